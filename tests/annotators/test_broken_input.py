"""Every annotator of the annotators package on broken input: FAILURE with a reason, never an exception.

Annotators are discovered (subclasses of robokudo's Annotator defined in the package), so a new expert is
covered automatically - and this test fails until the tables below say how to break it. Each broken CAS is
seeded by a first leaf inside a Pipeline; every expert whose inputs are missing from it must fail too.
"""

from __future__ import annotations

import importlib
import inspect
import json
import pkgutil
import re
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest
from py_trees.common import Status

import annotators
from annotators.clusters import ClusterExtractor
from annotators.color import SemanticColorAnnotator
from annotators.filters import RangeFilter
from annotators.plane import SupportPlaneSegmenter
from annotators.point_cloud import PointCloudGenerator
from annotators.pose import PoseAnnotator
from annotators.readers import ColorDepthPairReader, KitchenSceneReader
from robokudo.annotator import Annotator
from robokudo.pipeline import Pipeline
from robokudo.types import (
    ANNOTATION_TYPES,
    VIEW_TYPES,
    Annotation,
    CameraInfo,
    CameraIntrinsics,
    ColorImage,
    DepthImage,
    ObjectHypothesis,
    Plane,
    PointCloud,
    View,
)

H, W = 48, 64
K = CameraIntrinsics(fx=60.0, fy=60.0, cx=32.0, cy=24.0, width=W, height=H)
CRASH = re.compile(r"^[A-Z]\w*(Error|Exception)\b")


def discovered_annotators() -> list[type[Annotator]]:
    """Every Annotator subclass defined in a module of the annotators package."""
    found = []
    for info in pkgutil.iter_modules(annotators.__path__):
        module = importlib.import_module(f"annotators.{info.name}")
        for _, value in inspect.getmembers(module, inspect.isclass):
            if issubclass(value, Annotator) and value.__module__ == module.__name__ and not inspect.isabstract(value):
                found.append(value)
    return sorted(found, key=lambda cls: cls.__name__)


# ------------------------------------------------------------------------------------------ broken CASes


def color(height: int = H, width: int = W) -> ColorImage:
    return ColorImage(np.full((height, width, 3), 120, dtype=np.uint8))


def flat_cloud(mask_value: bool = True) -> PointCloud:
    """A valid cloud: a wall 1 m ahead, every point of interest (or none)."""
    v, u = np.mgrid[0:H, 0:W].astype(np.float32)
    points = np.stack([(u - K.cx) / K.fx, (v - K.cy) / K.fy, np.ones_like(u)], axis=-1)
    return PointCloud(points=points, mask=np.full((H, W), mask_value), colors=color().image)


def wall_plane() -> Plane:
    return Plane(model=np.array([0.0, 0.0, -1.0, 1.0]), inlier_indices=np.arange(H * W))


def hypothesis(mask_shape: tuple[int, int] = (H, W)) -> ObjectHypothesis:
    mask = np.zeros(mask_shape, dtype=bool)
    mask[10:20, 10:20] = True
    return ObjectHypothesis(point_indices=np.flatnonzero(mask), mask=mask, roi=(10, 10, 20, 20))


def nan_cloud() -> PointCloud:
    return PointCloud(points=np.full((H, W, 3), np.nan, np.float32), mask=np.ones((H, W), bool), colors=color().image)


def line_cloud() -> PointCloud:
    cloud = flat_cloud()
    cloud.points[..., 0] = np.linspace(0, 1, W)[None, :]
    cloud.points[..., 1] = 0.0
    cloud.points[..., 2] = 1.0 + np.linspace(0, 1, W)[None, :]
    return cloud


Seeds = list[View | Annotation]

# name -> (what the CAS holds, the experts this case is meant to break while their inputs are present)
BROKEN_CASES: dict[str, tuple[Callable[[], Seeds], tuple[type[Annotator], ...]]] = {
    "empty CAS": (lambda: [], ()),
    "all-zero depth": (
        lambda: [color(), DepthImage(np.zeros((H, W), np.float32)), CameraInfo(K)],
        (PointCloudGenerator,),
    ),
    "all-NaN depth": (
        lambda: [color(), DepthImage(np.full((H, W), np.nan, np.float32)), CameraInfo(K)],
        (PointCloudGenerator,),
    ),
    "colour and depth sizes differ": (
        lambda: [color(H // 2, W // 2), DepthImage(np.ones((H, W), np.float32)), CameraInfo(K)],
        (PointCloudGenerator,),
    ),
    "zero intrinsics": (
        lambda: [color(), DepthImage(np.ones((H, W), np.float32)), CameraInfo(CameraIntrinsics(0, 0, 0, 0, 0, 0))],
        (PointCloudGenerator,),
    ),
    "intrinsics for another image size": (
        lambda: [DepthImage(np.ones((H, W), np.float32)), CameraInfo(CameraIntrinsics(60, 60, 32, 24, 2 * W, H))],
        (PointCloudGenerator,),
    ),
    "empty cloud": (
        lambda: [
            PointCloud(points=np.zeros((0, 0, 3), np.float32), mask=np.zeros((0, 0), bool)),
            ColorImage(np.zeros((0, 0, 3), np.uint8)),
            wall_plane(),
            ObjectHypothesis(point_indices=np.zeros(0, np.int64), mask=np.zeros((0, 0), bool), roi=(0, 0, 0, 0)),
        ],
        (RangeFilter, SupportPlaneSegmenter, ClusterExtractor, SemanticColorAnnotator, PoseAnnotator),
    ),
    "all-NaN cloud": (
        lambda: [nan_cloud(), wall_plane(), hypothesis()],
        (RangeFilter, SupportPlaneSegmenter, ClusterExtractor, PoseAnnotator),
    ),
    "cloud without points of interest": (
        lambda: [flat_cloud(mask_value=False), wall_plane(), hypothesis()],
        (RangeFilter, SupportPlaneSegmenter, ClusterExtractor, PoseAnnotator),
    ),
    "collinear cloud": (lambda: [line_cloud()], (SupportPlaneSegmenter,)),
    "cloud out of range": (
        lambda: [PointCloud(points=flat_cloud().points * 10, mask=np.ones((H, W), bool))],
        (RangeFilter,),
    ),
    "degenerate plane": (
        lambda: [flat_cloud(), Plane(model=np.array([0.0, 0.0, 0.0, np.nan]), inlier_indices=np.arange(10))],
        (ClusterExtractor,),
    ),
    "plane indices outside the grid": (
        lambda: [flat_cloud(), Plane(model=np.array([0.0, 0.0, -1.0, 1.0]), inlier_indices=np.array([0, H * W]))],
        (ClusterExtractor,),
    ),
    "nothing stands on the plane": (lambda: [flat_cloud(), wall_plane()], (ClusterExtractor,)),
    "no hypotheses": (lambda: [color(), flat_cloud(), CameraInfo(K)], (SemanticColorAnnotator, PoseAnnotator)),
    "hypothesis and image sizes differ": (
        lambda: [color(H // 2, W // 2), hypothesis((H, W))],
        (SemanticColorAnnotator,),
    ),
    "hypothesis without valid points": (
        lambda: [nan_cloud(), hypothesis(), CameraInfo(K)],
        (PoseAnnotator,),
    ),
    "camera pose not a transform": (
        lambda: [flat_cloud(), hypothesis(), CameraInfo(K, cam_to_world=np.full((3, 3), np.nan))],
        (PoseAnnotator,),
    ),
}


def write_uoc(folder: Path, color_size: tuple[int, int] = (H, W), params: dict | None = None) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(folder / "000000-color.png"), np.zeros((*color_size, 3), np.uint8))
    cv2.imwrite(str(folder / "000000-depth.png"), np.full((H, W), 900, np.uint16))
    default = {"img_width": W, "img_height": H, "fx": 60.0, "fy": 60.0, "x_offset": 32.0, "y_offset": 24.0}
    (folder / "camera_params.json").write_text(json.dumps(params if params is not None else default))
    return folder


def zero_intrinsics_params() -> dict:
    return {"img_width": W, "img_height": H, "fx": 0.0, "fy": 0.0, "x_offset": 0.0, "y_offset": 0.0}


# readers read no CAS input; they are broken through their configuration: name -> factory(tmp_path)
BROKEN_READERS: dict[type[Annotator], dict[str, Callable[[Path], Annotator]]] = {
    KitchenSceneReader: {
        "unknown view": lambda tmp: KitchenSceneReader(view="attic"),
        "unknown moved object": lambda tmp: KitchenSceneReader(moved={"unicorn": np.zeros(3)}),
    },
    ColorDepthPairReader: {
        "missing folder": lambda tmp: ColorDepthPairReader(tmp / "nowhere"),
        "missing frame": lambda tmp: ColorDepthPairReader(write_uoc(tmp / "a"), frame=5),
        "image sizes differ": lambda tmp: ColorDepthPairReader(write_uoc(tmp / "b", color_size=(H // 2, W))),
        "zero intrinsics": lambda tmp: ColorDepthPairReader(write_uoc(tmp / "c", params=zero_intrinsics_params())),
        "negative depth scale": lambda tmp: ColorDepthPairReader(write_uoc(tmp / "d"), depth_scale=-1.0),
    },
}


class Seed(Annotator):
    """Writes the broken CAS content (test helper); it may write any CAS type."""

    outputs = VIEW_TYPES + ANNOTATION_TYPES

    def __init__(self, seeds: Seeds) -> None:
        super().__init__(name="seed")
        self.seeds = seeds

    def analyse(self) -> None:
        for item in self.seeds:
            self.write(item)


def assert_fails_with_a_reason(annotator: Annotator, seeds: Seeds) -> None:
    Pipeline("broken", [Seed(seeds), annotator]).tick_once()  # must not raise
    assert annotator.status is Status.FAILURE, f"{type(annotator).__name__} did not fail"
    message = annotator.feedback_message
    assert message.strip(), f"{type(annotator).__name__} failed without a reason"
    assert not CRASH.match(message), f"{type(annotator).__name__} crashed instead of failing: {message}"


EXPERTS = [cls for cls in discovered_annotators() if cls.inputs]
READERS = [cls for cls in discovered_annotators() if not cls.inputs]


def test_the_tables_cover_every_discovered_annotator() -> None:
    assert {c.__name__ for c in discovered_annotators()} >= {
        "KitchenSceneReader", "ColorDepthPairReader", "PointCloudGenerator", "RangeFilter",
        "SupportPlaneSegmenter", "ClusterExtractor", "SemanticColorAnnotator", "PoseAnnotator",
    }  # fmt: skip
    targeted = {cls for _, targets in BROKEN_CASES.values() for cls in targets}
    assert set(EXPERTS) <= targeted, f"no broken case targets {set(EXPERTS) - targeted}"
    assert set(READERS) <= set(BROKEN_READERS), f"no broken configuration for {set(READERS) - set(BROKEN_READERS)}"


def expert_cases() -> list[tuple[type[Annotator], str]]:
    """(expert, case) pairs where the case breaks the expert: it is a target, or its inputs are missing."""
    pairs = []
    for case, (make_seeds, targets) in sorted(BROKEN_CASES.items()):
        present = {type(item) for item in make_seeds()}
        for expert in EXPERTS:
            missing = any(not any(issubclass(t, need) for t in present) for need in expert.inputs)
            if expert in targets or missing:
                pairs.append((expert, case))
    return pairs


@pytest.mark.parametrize(
    ("expert", "case"), expert_cases(), ids=lambda value: value.__name__ if isinstance(value, type) else value
)
def test_experts_fail_with_a_reason_on_broken_input(expert: type[Annotator], case: str) -> None:
    make_seeds, _ = BROKEN_CASES[case]
    assert_fails_with_a_reason(expert(), make_seeds())


@pytest.mark.parametrize(
    ("reader", "case"),
    [(reader, case) for reader in READERS for case in sorted(BROKEN_READERS.get(reader, {}))],
    ids=lambda value: value.__name__ if isinstance(value, type) else value,
)
def test_readers_fail_with_a_reason_on_broken_configuration(reader: type[Annotator], case: str, tmp_path) -> None:
    assert_fails_with_a_reason(BROKEN_READERS[reader][case](tmp_path), [])
