"""The Fig. 2 tabletop tree on a real RealSense frame (uoc_tabletop_realsense, frame 000003)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from py_trees.common import Status

from annotators.geometry.boxes import object_box
from robokudo.core.engine import Engine
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import ObjectHypothesis, Plane, PointCloud, Pose, SemanticColor
from trees.tabletop import create_tree

pytestmark = pytest.mark.real_data

# A pixel (x, y) well inside each object of frame 000003 (looked up on the colour image).
OBJECT_PIXELS = {
    "cheez-it box": (260, 70),
    "water bottle": (560, 150),
    "teal bowl": (340, 185),
    "white bowl": (410, 250),
    "blue mug": (490, 130),
    "mustard bottle": (190, 160),
    "soup can": (150, 170),
}
TABLE_PIXELS = ((320, 420), (80, 400), (600, 330), (320, 320), (50, 120))


@pytest.fixture(scope="module")
def frame3(uoc_folder: Path) -> Pipeline:
    root = create_tree(str(uoc_folder), 3)
    assert Engine(root).tick() is Status.SUCCESS
    return root


def label_image(root: Pipeline) -> tuple[np.ndarray, list[ObjectHypothesis]]:
    hypotheses = root.cas.annotations(ObjectHypothesis)
    labels = np.zeros(hypotheses[0].mask.shape, dtype=int)
    for number, hypothesis in enumerate(hypotheses, start=1):
        labels[hypothesis.mask] = number
    return labels, hypotheses


def hypothesis_at(labels: np.ndarray, x: int, y: int) -> int:
    """The label most of the 5x5 pixels around (x, y) carry (0: none)."""
    window = labels[y - 2 : y + 3, x - 2 : x + 3].ravel()
    return int(np.bincount(window).argmax())


def test_the_table_plane_is_found(frame3: Pipeline) -> None:
    (plane,) = frame3.cas.annotations(Plane)
    inliers = np.zeros(640 * 480, dtype=bool)
    inliers[plane.inlier_indices] = True
    inliers = inliers.reshape(480, 640)
    assert all(inliers[y, x] for x, y in TABLE_PIXELS)
    assert not any(inliers[y, x] for x, y in OBJECT_PIXELS.values())
    normal, distance = plane.model[:3], plane.model[3]
    assert normal[1] < -0.5 and 0.4 < distance < 0.8  # faces up toward a camera ~0.6 m above it


def test_objects_standing_on_the_table_are_separate_hypotheses(frame3: Pipeline) -> None:
    labels, _ = label_image(frame3)
    found = {name: hypothesis_at(labels, x, y) for name, (x, y) in OBJECT_PIXELS.items()}
    assert all(found.values()), f"objects without a hypothesis: {[n for n, k in found.items() if not k]}"
    assert len(set(found.values())) == len(found), f"objects sharing a hypothesis: {found}"


def test_the_cheez_it_box_is_red(frame3: Pipeline) -> None:
    labels, hypotheses = label_image(frame3)
    box = hypotheses[hypothesis_at(labels, *OBJECT_PIXELS["cheez-it box"]) - 1]
    color = box.first(SemanticColor)
    assert color is not None and color.color == "red"


def test_every_hypothesis_has_a_colour_and_a_camera_frame_pose(frame3: Pipeline) -> None:
    for hypothesis in frame3.cas.annotations(ObjectHypothesis):
        assert hypothesis.first(SemanticColor) is not None
        pose = hypothesis.first(Pose)
        assert pose is not None and pose.frame == "camera"
        assert np.all(np.isfinite(pose.position)) and 0.4 < pose.position[2] < 1.5
        assert abs(np.linalg.norm(pose.orientation) - 1.0) < 1e-6


def test_a_milk_carton_measures_its_size_and_pose_despite_flying_pixels(shared_data: Path) -> None:
    """PCL's milk-carton scene: the carton (about 25 cm tall) has a few flying pixels 0.8 m behind it at its edges;
    they must not stretch its box (it measured 89 cm) nor drag its pose away from its surface."""
    root = create_tree(str(shared_data / "pcl_tabletop_pcd" / "milk_cartoon_all_small_clorox.pcd"), 0)
    assert Engine(root).tick() is Status.SUCCESS
    (carton,) = [h for h in root.cas.annotations(ObjectHypothesis) if h.mask[150, 280]]
    cloud = root.cas.view(PointCloud)
    points = cloud.points.reshape(-1, 3)[carton.point_indices]
    extents = sorted(object_box(points, None)[0].extents, reverse=True)
    assert 0.20 <= extents[0] <= 0.30 and extents[1] <= 0.15
    (pose,) = [a for a in carton.annotations if isinstance(a, Pose)]
    median = np.nanmedian(points, axis=0)
    assert np.linalg.norm(pose.position - median) < 0.08  # the box centre stays on the carton
