"""The support plane is the surface the objects stand on: the table, also where the floor below it fills the view.

Rendered kitchen views (our own generator) seen from a mobile robot's head 2.4 m in front of the table, where the
floor is the dominant plane: the tabletop tree takes the table top as the support and finds the objects on it,
with and without the camera pose. With the objects put on the floor and no table in view the floor stays the
support and they are found there; a box top with a cup on it, lower above the table than a tall object, is not a
table.
"""

from __future__ import annotations

import time
from collections.abc import Mapping

import numpy as np
import pytest
from py_trees.common import Status

from annotators.cloud.filters import range_mask
from annotators.cloud.plane import ransac_support_plane
from annotators.cloud.point_cloud import back_project, pixel_rays
from annotators.cloud.support_choice import (
    SupportChoiceRules,
    choose_support,
    find_support_plane,
    grid_points,
    raised_peaks,
    standing_clusters,
    surface_area,
)
from annotators.simulation import kitchen_scene
from annotators.simulation.kitchen_scene import RenderedScene, SceneObject
from robokudo.core.annotator import Annotator
from robokudo.core.engine import Engine
from robokudo.core.types import CameraInfo, ColorImage, DepthImage, ObjectHypothesis, Plane
from trees.tabletop import create_pipeline

TABLE_OBJECTS = ("cereal_box", "red_cup", "bowl")
HEAD_EYE = (0.0, -2.4, 1.35)
"""A mobile robot's head camera 2.4 m in front of the table's centre, 1.35 m above the floor."""


class PosedKitchenReader(Annotator):
    """Writes one kitchen frame rendered from a given camera pose (test helper); ``posed``: with the camera pose."""

    outputs = (ColorImage, DepthImage, CameraInfo)

    def __init__(self, scene: RenderedScene, posed: bool) -> None:
        super().__init__(name="posed kitchen")
        self.scene = scene
        self.posed = posed

    def analyse(self) -> None:
        self.write(ColorImage(self.scene.color))
        self.write(DepthImage(self.scene.depth))
        pose = self.scene.cam_to_world if self.posed else None
        self.write(CameraInfo(intrinsics=self.scene.intrinsics, cam_to_world=pose, frame_id="k", timestamp=time.time()))


def run_tree(scene: RenderedScene, posed: bool) -> tuple[Plane, list[ObjectHypothesis]]:
    """The tabletop tree on the scene: its support plane and hypotheses."""
    root = create_pipeline(PosedKitchenReader(scene, posed))
    assert Engine(root).tick() is Status.SUCCESS, [(c.name, c.feedback_message) for c in root.children]
    (plane,) = root.cas.annotations(Plane)
    return plane, root.cas.annotations(ObjectHypothesis)


def height_of_plane(scene: RenderedScene, plane: Plane) -> float:
    """The world height (z, metres) of the plane below the camera: camera height minus its distance."""
    return float(scene.cam_to_world[2, 3] - plane.model[3])


def found_share(scene: RenderedScene, hypotheses: list[ObjectHypothesis], name: str) -> float:
    """The largest share of the object's visible pixels one hypothesis covers."""
    truth = scene.object_ids == scene.object(name).object_id
    return max((np.count_nonzero(h.mask & truth) / np.count_nonzero(truth) for h in hypotheses), default=0.0)


def render(target: tuple[float, float, float], moved: Mapping[str, np.ndarray] | None = None) -> RenderedScene:
    """The kitchen seen from :data:`HEAD_EYE` looking at ``target``."""
    return kitchen_scene.render_kitchen(kitchen_scene.look_at(HEAD_EYE, target), moved=moved)


@pytest.mark.parametrize("posed", [True, False])
def test_the_table_above_a_dominant_floor_is_the_support(posed: bool) -> None:
    scene = render((0.0, -0.6, 0.35))
    plane, hypotheses = run_tree(scene, posed)
    floor = np.zeros(scene.depth.shape, dtype=bool).reshape(-1)
    floor[plane.inlier_indices] = True
    table_pixels = np.count_nonzero(floor.reshape(scene.depth.shape) & (scene.object_ids == 0))
    assert height_of_plane(scene, plane) == pytest.approx(kitchen_scene.TABLE_TOP_HEIGHT, abs=0.03)
    assert table_pixels >= 1000
    for name in TABLE_OBJECTS:
        assert found_share(scene, hypotheses, name) >= 0.5, name


def test_objects_on_the_floor_are_found_when_only_the_floor_is_in_view() -> None:
    down = -kitchen_scene.TABLE_TOP_HEIGHT
    moved = {
        "cereal_box": np.array([0.0, -1.1, down]),
        "red_cup": np.array([0.1, -1.0, down]),
        "bowl": np.array([0.0, -1.1, down]),
    }
    scene = render((0.0, -1.2, 0.0), moved)
    plane, hypotheses = run_tree(scene, posed=False)
    assert height_of_plane(scene, plane) == pytest.approx(0.0, abs=0.03)
    for name in TABLE_OBJECTS:
        assert found_share(scene, hypotheses, name) >= 0.5, name


def test_a_box_top_carrying_a_cup_is_not_the_table() -> None:
    top = kitchen_scene.TABLE_TOP_HEIGHT + 0.3
    box_pose = np.eye(4)
    box_pose[:3, 3] = (0.3, -0.05, top - 0.15)
    box = SceneObject(
        object_id=50, name="big_box", object_class="Box", color="green", shape="box", size=(0.4, 0.3, 0.3),
        size_class="large", pose=box_pose, text="", region="table",
    )  # fmt: skip
    moved = {"red_cup": np.array([0.3, 0.07, 0.3])}  # onto the box
    scene = kitchen_scene.render_kitchen("table", moved=moved, extra=[(box, (40, 160, 60))])
    plane, _ = run_tree(scene, posed=False)
    assert height_of_plane(scene, plane) == pytest.approx(kitchen_scene.TABLE_TOP_HEIGHT, abs=0.03)


def test_the_table_legs_are_no_objects_on_the_floor_and_each_table_object_stands_on_the_table() -> None:
    scene = render((0.0, -0.6, 0.35))
    points = np.ascontiguousarray(back_project(scene.depth, pixel_rays(scene.intrinsics)), dtype=np.float32)
    mask = range_mask(points, np.isfinite(points[..., 2]), 0.2, 2.5)
    floor = ransac_support_plane(points, mask)
    assert floor is not None
    table = choose_support(points, mask, floor)
    rules = SupportChoiceRules()
    coarse = np.ascontiguousarray(points[:: rules.step, :: rules.step])
    valid = mask[:: rules.step, :: rules.step] & np.isfinite(coarse[..., 2])
    ids = scene.object_ids[:: rules.step, :: rules.step]
    owners = {}
    for name, fit in (("floor", floor), ("table", table)):
        surface = grid_points(coarse, fit.inlier_indices, mask.shape, rules.step)
        labels, kept = standing_clusters(coarse, valid, fit.model, surface, rules)
        owners[name] = [set(np.unique(ids[labels == label]).tolist()) for label in kept]
    assert owners["floor"] == []  # the legs go on up to the table top: part of something larger
    assert all(len(owner) == 1 for owner in owners["table"]), owners
    assert set().union(*owners["table"]) == {scene.object(name).object_id for name in TABLE_OBJECTS}


def test_raised_peaks_are_the_full_height_bins_above_the_tallest_object() -> None:
    rules = SupportChoiceRules()
    rng = np.random.default_rng(0)
    heights = np.concatenate(
        [rng.uniform(0.0, 0.4, 5000), np.full(300, 0.731), np.full(20, 1.2), rng.uniform(0.5, 1.5, 200)]
    )
    (peak,) = raised_peaks(heights, rules)
    assert abs(peak - 0.73) <= rules.bin
    assert raised_peaks(heights[heights < 0.5], rules) == []


def test_surface_area_counts_the_covered_cells() -> None:
    u, v = np.meshgrid(np.arange(0.0, 0.5, 0.005), np.arange(0.0, 0.4, 0.005))
    square = np.column_stack([u.ravel(), np.full(u.size, 0.7), v.ravel()])  # a 0.5 x 0.4 m patch, y = 0.7
    assert surface_area(square, np.array([0.0, -1.0, 0.0]), 0.02) == pytest.approx(0.2, rel=0.1)


def test_no_plane_without_points() -> None:
    points = np.full((48, 64, 3), np.nan, dtype=np.float32)
    assert find_support_plane(points, np.ones((48, 64), dtype=bool)) is None


def test_a_stray_surface_point_far_away_does_not_blow_up_the_footprint() -> None:
    """The footprint raster covers only where standing points can fall: one surface inlier 100 km off (a bad
    depth reading on the plane) leaves the box standing on the patch found, instead of a raster of the whole span."""
    rules = SupportChoiceRules()
    v, u = np.mgrid[0:40, 0:40] * 0.02  # a 0.8 m square patch, the plane z = 0 (height along z)
    heights = np.zeros_like(u)
    heights[15:25, 15:25] = 0.1  # a 0.2 m box standing on it
    points = np.stack([u, v, heights], axis=-1).astype(np.float32)
    valid = np.ones(u.shape, dtype=bool)
    patch = points[heights == 0]
    model = np.array([0.0, 0.0, 1.0, 0.0])
    labels, kept = standing_clusters(points, valid, model, patch, rules)
    (box,) = kept
    for far in (1e5, -1e5):
        stray = np.concatenate([patch, [[far, far, 0.0]]]).astype(np.float32)
        labels_stray, kept_stray = standing_clusters(points, valid, model, stray, rules)
        assert len(kept_stray) == 1
        assert np.array_equal(labels_stray == kept_stray[0], labels == box)
