"""The Fig. 2 tabletop tree on the built-in kitchen scene: every visible object found, placed and named."""

from __future__ import annotations

import numpy as np
import pytest
from py_trees.common import Status

import trees
from annotators.readers.frame_readers import KitchenSceneReader
from annotators.simulation.kitchen_scene import RenderedScene
from robokudo.application.annotated_image import draw_answer, write_annotated_image
from robokudo.application.report import describe_hypotheses
from robokudo.core.engine import Engine
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import ColorImage, ObjectHypothesis, Plane, Pose, SemanticColor
from trees.tabletop import create_pipeline, create_tree

MIN_VISIBLE_PIXELS = 200


def run_view(view: str) -> tuple[Pipeline, RenderedScene]:
    """Tick the tabletop tree once on a kitchen view; returns the pipeline and the rendered ground truth."""
    reader = KitchenSceneReader(view=view)
    root = create_pipeline(reader)
    status = Engine(root).tick()
    assert status is Status.SUCCESS, root.tip().feedback_message if root.tip() else "no tip"
    assert reader.last_scene is not None
    return root, reader.last_scene


@pytest.fixture(scope="module")
def table() -> tuple[Pipeline, RenderedScene]:
    return run_view("table")


def matched(root: Pipeline, scene: RenderedScene) -> dict[str, ObjectHypothesis]:
    """Each visible ground-truth object with the hypothesis whose world pose is nearest to it."""
    hypotheses = root.cas.annotations(ObjectHypothesis)
    found = {}
    for obj in scene.visible_objects(MIN_VISIBLE_PIXELS):
        distances = [np.linalg.norm(h.first(Pose).position - obj.position) for h in hypotheses]
        found[obj.name] = hypotheses[int(np.argmin(distances))]
    return found


def test_every_visible_object_is_one_hypothesis(table: tuple[Pipeline, RenderedScene]) -> None:
    root, scene = table
    visible = scene.visible_objects(MIN_VISIBLE_PIXELS)
    hypotheses = root.cas.annotations(ObjectHypothesis)
    assert {o.name for o in visible} == {"cereal_box", "red_cup", "bowl"}
    assert len(hypotheses) == len(visible)
    assert len({id(h) for h in matched(root, scene).values()}) == len(visible)


def test_centroids_are_within_2_cm_in_the_world_frame(table: tuple[Pipeline, RenderedScene]) -> None:
    root, scene = table
    for name, hypothesis in matched(root, scene).items():
        pose = hypothesis.first(Pose)
        assert pose is not None and pose.frame == "world"
        error = np.linalg.norm(pose.position - scene.object(name).position)
        assert error < 0.02, f"{name}: centroid off by {100 * error:.1f} cm"


def test_colours_are_named_right(table: tuple[Pipeline, RenderedScene]) -> None:
    root, scene = table
    for name, hypothesis in matched(root, scene).items():
        color = hypothesis.first(SemanticColor)
        assert color is not None and color.color == scene.object(name).color, name
        assert 0.5 < color.confidence <= 1.0


def test_hypotheses_have_consistent_indices_masks_and_rois(table: tuple[Pipeline, RenderedScene]) -> None:
    root, scene = table
    height, width = scene.depth.shape
    for hypothesis in root.cas.annotations(ObjectHypothesis):
        rows, cols = np.nonzero(hypothesis.mask)
        assert hypothesis.mask.reshape(-1)[hypothesis.point_indices].all()  # every measured point is in the mask
        assert hypothesis.point_indices.size >= 0.8 * rows.size  # the border adds an outline, not another object
        assert hypothesis.roi == (cols.min(), rows.min(), cols.max() + 1, rows.max() + 1)
        assert hypothesis.mask.shape == (height, width)
        ids = scene.object_ids.reshape(-1)[hypothesis.point_indices]
        assert np.bincount(ids).argmax() > 0  # mostly on one object, not on furniture


def test_the_support_is_the_table_top(table: tuple[Pipeline, RenderedScene]) -> None:
    root, scene = table
    (plane,) = root.cas.annotations(Plane)
    up = scene.cam_to_world[:3, :3].T @ np.array([0.0, 0.0, 1.0])
    assert plane.model[:3] @ up > 0.99
    camera_height = scene.cam_to_world[2, 3]
    assert abs(plane.model[3] - (camera_height - 0.75)) < 0.01  # table top at 0.75 m


def test_the_fridge_view_finds_the_milk() -> None:
    root, scene = run_view("fridge")
    (hypothesis,) = root.cas.annotations(ObjectHypothesis)
    assert np.linalg.norm(hypothesis.first(Pose).position - scene.object("milk").position) < 0.02
    assert hypothesis.first(SemanticColor).color == "white"


def test_report_lists_every_hypothesis_in_the_world_frame(table: tuple[Pipeline, RenderedScene]) -> None:
    root, _ = table
    text = describe_hypotheses(root.cas)
    lines = text.splitlines()
    assert len(lines) == 1 + len(root.cas.annotations(ObjectHypothesis))
    assert "colour" in lines[0] and "size" in lines[0]
    for color in ("yellow", "red", "blue"):
        assert color in text
    assert all(" world " in line for line in lines[1:])


def test_annotated_image_is_drawn_on_a_copy(table: tuple[Pipeline, RenderedScene], tmp_path) -> None:
    root, _ = table
    original = root.cas.view(ColorImage).image
    before = original.copy()
    drawn = draw_answer(root.cas)
    assert drawn.shape == original.shape and drawn.dtype == np.uint8
    assert np.array_equal(original, before)
    assert np.count_nonzero(np.any(drawn != original, axis=2)) > 500
    path = write_annotated_image(root.cas, tmp_path / "out" / "demo.png")
    assert path.is_file() and path.stat().st_size > 1000


def test_tree_module_is_listed_explained_and_valid() -> None:
    spec = trees.load_tree("tabletop")
    assert spec.summary.startswith("The seed's Fig. 2 tabletop tree: ")
    root = create_tree()
    Engine(root)  # checks structure and data flow
    assert [type(c).__name__ for c in root.children][:5] == [
        "KitchenSceneReader",
        "PointCloudGenerator",
        "RangeFilter",
        "SupportPlaneSegmenter",
        "ClutterSegmenter",
    ]
    describe = root.children[5]
    assert [type(c).__name__ for c in describe.children] == ["SemanticColorAnnotator", "PoseAnnotator"]
    assert all(getattr(node, "reason", "") for node in root.iterate())
    with pytest.raises(ValueError, match="supported inputs"):
        create_tree("/some/folder", 2)
