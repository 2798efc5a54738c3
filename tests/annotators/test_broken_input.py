"""Every annotator of the annotators package on broken input: FAILURE with a reason, never an exception.

Annotators are discovered (subclasses of robokudo's Annotator defined in the package), so a new expert is
covered automatically - and this test fails until the tables below say how to break it. Each broken CAS is
seeded by a first leaf inside a Pipeline; every expert whose inputs are missing from it must fail too.
"""

from __future__ import annotations

import json
import re
import time
from collections.abc import Callable
from pathlib import Path

import cv2
import numpy as np
import pytest
from py_trees.common import Status

from annotators.catalog import discover_annotators
from annotators.classification.knowledge_classifier import KnowledgeClassifier
from annotators.cloud.clusters import ClusterExtractor
from annotators.cloud.clutter import ClutterSegmenter
from annotators.cloud.filters import CropBoxFilter, RangeFilter, RegionFilter
from annotators.cloud.form import FormAnnotator
from annotators.cloud.free_space import FreeSpaceEstimator
from annotators.cloud.normals import NormalEstimator
from annotators.cloud.people import DepthPeopleDetector
from annotators.cloud.point_cloud import PointCloudGenerator
from annotators.cloud.pose import PoseAnnotator
from annotators.cloud.shape import ShapeAnnotator
from annotators.cloud.size import SizeAnnotator
from annotators.cloud.support_choice import SupportPlaneSegmenter
from annotators.image.color import SemanticColorAnnotator
from annotators.image.histogram import ColorHistogramAnnotator
from annotators.image.human_pose import LANDMARKS, HumanPoseDetector
from annotators.image.image_regions import ImageRegionSegmenter
from annotators.image.onnx_detector import OnnxDetector
from annotators.people.activity import ActivityRecognizer
from annotators.people.pointing import PointingEstimator
from annotators.readers.frame_io import Frame
from annotators.readers.frame_readers import (
    BagCloudReader,
    BagReader,
    ColorDepthPairReader,
    KitchenSceneReader,
    Open3dFolderReader,
    PcdReader,
    TiffSequenceReader,
    TumPairReader,
    TumSequenceReader,
)
from annotators.readers.streams import FrameStream, PerceivedFrameReader, StreamReader, recorded_stream
from annotators.text.reader import TextReader
from annotators.tracking.human_tracker import HumanTracker
from annotators.tracking.object_tracker import ObjectTracker
from robokudo.core.annotator import Annotator
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import (
    ANNOTATION_TYPES,
    VIEW_TYPES,
    Activity,
    Annotation,
    BodyKeypoints,
    CameraInfo,
    CameraIntrinsics,
    ColorImage,
    DepthImage,
    Normals,
    ObjectHypothesis,
    PersonHypothesis,
    Plane,
    PointCloud,
    SemanticColor,
    Shape,
    Size,
    View,
)
from tests.annotators.bag_writing import INFO_TOPIC, write_bag
from tests.annotators.onnx_models import detection_model, one_box_model

H, W = 48, 64
K = CameraIntrinsics(fx=60.0, fy=60.0, cx=32.0, cy=24.0, width=W, height=H)
CRASH = re.compile(r"^[A-Z]\w*(Error|Exception)\b")


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


def nan_normals() -> Normals:
    return Normals(np.full((H, W, 3), np.nan, np.float32))


def up_normals() -> Normals:
    normals = np.zeros((H, W, 3), np.float32)
    normals[..., 2] = -1.0
    return Normals(normals)


def posed_camera(x: float = 0.0) -> CameraInfo:
    """A camera 1 m above the world origin looking down (shifted ``x`` m along world x)."""
    pose = np.array([[1.0, 0, 0, x], [0, -1, 0, 0], [0, 0, -1, 1.0], [0, 0, 0, 1]])
    return CameraInfo(K, cam_to_world=pose)


def evidence_types() -> Seeds:
    """Scene-level colour, shape and size: the classifier's inputs are present, yet no hypothesis carries them."""
    return [SemanticColor(color="red"), Shape(shape="box"), Size(dimensions=(0.1, 0.1, 0.1), size_class="small")]


def line_cloud() -> PointCloud:
    cloud = flat_cloud()
    cloud.points[..., 0] = np.linspace(0, 1, W)[None, :]
    cloud.points[..., 1] = 0.0
    cloud.points[..., 2] = 1.0 + np.linspace(0, 1, W)[None, :]
    return cloud


def keypoints(depth: float = np.nan) -> BodyKeypoints:
    """33 keypoints in the image middle, all at ``depth`` (NaN: no depth)."""
    return BodyKeypoints(
        names=LANDMARKS,
        pixels=np.full((len(LANDMARKS), 2), 20.0),
        points=np.full((len(LANDMARKS), 3), depth),
        visibility=np.ones(len(LANDMARKS)),
    )


def person(*attached: Annotation) -> PersonHypothesis:
    mask = np.zeros((H, W), dtype=bool)
    mask[5:40, 20:30] = True
    return PersonHypothesis(point_indices=np.flatnonzero(mask), mask=mask, roi=(20, 5, 30, 40), annotations=[*attached])


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
            Normals(np.zeros((0, 0, 3), np.float32)),
            posed_camera(),
            wall_plane(),
            ObjectHypothesis(point_indices=np.zeros(0, np.int64), mask=np.zeros((0, 0), bool), roi=(0, 0, 0, 0)),
        ],
        (
            RangeFilter,
            CropBoxFilter,
            RegionFilter,
            NormalEstimator,
            SupportPlaneSegmenter,
            ClusterExtractor,
            ClutterSegmenter,
            FreeSpaceEstimator,
            SemanticColorAnnotator,
            ColorHistogramAnnotator,
            PoseAnnotator,
            ShapeAnnotator,
            SizeAnnotator,
            FormAnnotator,
            TextReader,
            OnnxDetector,
            ImageRegionSegmenter,
            DepthPeopleDetector,
            HumanPoseDetector,
        ),
    ),
    "all-NaN cloud": (
        lambda: [nan_cloud(), nan_normals(), posed_camera(), wall_plane(), hypothesis()],
        (
            RangeFilter,
            CropBoxFilter,
            RegionFilter,
            NormalEstimator,
            SupportPlaneSegmenter,
            ClusterExtractor,
            ClutterSegmenter,
            FreeSpaceEstimator,
            PoseAnnotator,
            ShapeAnnotator,
            SizeAnnotator,
            DepthPeopleDetector,
        ),
    ),
    "cloud without points of interest": (
        lambda: [flat_cloud(mask_value=False), up_normals(), posed_camera(), wall_plane(), hypothesis()],
        (
            RangeFilter,
            CropBoxFilter,
            RegionFilter,
            NormalEstimator,
            SupportPlaneSegmenter,
            ClusterExtractor,
            ClutterSegmenter,
            FreeSpaceEstimator,
            PoseAnnotator,
            ShapeAnnotator,
            SizeAnnotator,
            DepthPeopleDetector,
        ),
    ),
    "cloud too small for normals": (
        lambda: [PointCloud(points=np.ones((2, 2, 3), np.float32), mask=np.ones((2, 2), bool))],
        (NormalEstimator,),
    ),
    "collinear cloud": (lambda: [line_cloud()], (SupportPlaneSegmenter, DepthPeopleDetector)),
    "hypotheses beyond the cloud": (
        lambda: [
            flat_cloud(),
            PersonHypothesis(point_indices=np.array([H * W + 5]), mask=np.zeros((H, W), bool), roi=(0, 0, 1, 1)),
        ],
        (HumanTracker, ObjectTracker),
    ),
    "a wall, no ground": (lambda: [flat_cloud()], (DepthPeopleDetector,)),
    "cloud out of range": (
        lambda: [PointCloud(points=flat_cloud().points * 10, mask=np.ones((H, W), bool))],
        (RangeFilter, CropBoxFilter),
    ),
    "camera pose unknown": (lambda: [flat_cloud(), CameraInfo(K)], (RegionFilter,)),
    "no point inside the region": (lambda: [flat_cloud(), posed_camera(x=50.0)], (RegionFilter,)),
    "degenerate plane": (
        lambda: [flat_cloud(), Plane(model=np.array([0.0, 0.0, 0.0, np.nan]), inlier_indices=np.arange(10))],
        (ClusterExtractor, ClutterSegmenter, FreeSpaceEstimator),
    ),
    "plane indices outside the grid": (
        lambda: [flat_cloud(), Plane(model=np.array([0.0, 0.0, -1.0, 1.0]), inlier_indices=np.array([0, H * W]))],
        (ClusterExtractor, ClutterSegmenter, FreeSpaceEstimator),
    ),
    "nothing stands on the plane": (lambda: [flat_cloud(), wall_plane()], (ClusterExtractor, ClutterSegmenter)),
    "no hypotheses": (
        lambda: [color(), flat_cloud(), up_normals(), CameraInfo(K), *evidence_types()],
        (
            SemanticColorAnnotator,
            ColorHistogramAnnotator,
            PoseAnnotator,
            ShapeAnnotator,
            SizeAnnotator,
            KnowledgeClassifier,
            TextReader,
            OnnxDetector,
        ),
    ),
    "hypothesis and image sizes differ": (
        lambda: [color(H // 2, W // 2), hypothesis((H, W))],
        (SemanticColorAnnotator, ColorHistogramAnnotator, TextReader),
    ),
    "hypothesis box outside the image": (
        lambda: [
            color(),
            ObjectHypothesis(point_indices=np.arange(3), mask=np.zeros((H, W), bool), roi=(90, 70, 99, 80)),
        ],
        (TextReader, OnnxDetector),
    ),
    "hypothesis without valid points": (
        lambda: [nan_cloud(), nan_normals(), hypothesis(), CameraInfo(K)],
        (PoseAnnotator, ShapeAnnotator, SizeAnnotator, FormAnnotator),
    ),
    "normals and cloud sizes differ": (
        lambda: [flat_cloud(), Normals(np.zeros((H // 2, W, 3), np.float32)), hypothesis()],
        (ShapeAnnotator,),
    ),
    "camera pose not a transform": (
        lambda: [flat_cloud(), hypothesis(), CameraInfo(K, cam_to_world=np.full((3, 3), np.nan))],
        (PoseAnnotator, RegionFilter),
    ),
    "uniform colour image": (lambda: [color()], (ImageRegionSegmenter, HumanPoseDetector)),
    "tiny colour image": (lambda: [color(4, 4)], (ImageRegionSegmenter, HumanPoseDetector)),
    "hypothesis without evidence": (lambda: [hypothesis(), *evidence_types()], (KnowledgeClassifier,)),
    "a person without keypoints": (
        lambda: [person(), keypoints(), Activity(activity="pointing"), flat_cloud(), posed_camera()],
        (ActivityRecognizer, PointingEstimator),
    ),
    "a pointing person's arm without depth": (
        lambda: [
            person(keypoints(), Activity(activity="pointing", arm="right")),
            keypoints(),
            Activity(activity="pointing"),
            flat_cloud(),
            posed_camera(),
        ],
        (PointingEstimator,),
    ),
}

PROFILES = ({"class": "Milk", "colors": ("white",), "shape": "box", "size": "medium", "texts": ("milk",)},)

# experts that need constructor arguments: class -> factory(tmp_path); the others are built with no arguments
FACTORIES: dict[type[Annotator], Callable[[Path], Annotator]] = {
    RegionFilter: lambda tmp: RegionFilter("table", np.eye(4).ravel(), (4.0, 4.0, 4.0)),
    KnowledgeClassifier: lambda tmp: KnowledgeClassifier(PROFILES),
    OnnxDetector: lambda tmp: OnnxDetector(str(one_box_model(tmp / "model.onnx"))),
    FreeSpaceEstimator: lambda tmp: FreeSpaceEstimator((0.1, 0.1)),
}

# experts broken through their configuration: class -> {case: factory(tmp_path)}
BROKEN_CONFIGURATIONS: dict[type[Annotator], dict[str, Callable[[Path], Annotator]]] = {
    KnowledgeClassifier: {"no profiles": lambda tmp: KnowledgeClassifier([])},
    ActivityRecognizer: {
        "missing image-text model": lambda tmp: ActivityRecognizer(model_path=tmp / "nowhere.onnx"),
        "malformed image-text model": lambda tmp: ActivityRecognizer(model_path=junk_file(tmp / "junk.onnx")),
    },
    OnnxDetector: {
        "missing model file": lambda tmp: OnnxDetector(str(tmp / "nowhere.onnx")),
        "malformed model file": lambda tmp: OnnxDetector(str(junk_file(tmp / "junk.onnx"))),
        "truncated model file": lambda tmp: OnnxDetector(str(truncated(one_box_model(tmp / "cut.onnx")))),
        "no class names": lambda tmp: OnnxDetector(str(detection_model(tmp / "m.onnx", np.zeros((1, 6, 3))))),
        "missing class name file": lambda tmp: OnnxDetector(str(one_box_model(tmp / "m.onnx")), str(tmp / "x.txt")),
        "output it cannot decode": lambda tmp: OnnxDetector(
            str(detection_model(tmp / "m.onnx", np.zeros((2, 2, 2)))), ["a"]
        ),
    },
}


def junk_file(path: Path) -> Path:
    path.write_bytes(b"this is not an ONNX model")
    return path


def truncated(path: Path) -> Path:
    path.write_bytes(path.read_bytes()[:40])
    return path


def write_uoc(folder: Path, color_size: tuple[int, int] = (H, W), params: dict | None = None) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(folder / "000000-color.png"), np.zeros((*color_size, 3), np.uint8))
    cv2.imwrite(str(folder / "000000-depth.png"), np.full((H, W), 900, np.uint16))
    default = {"img_width": W, "img_height": H, "fx": 60.0, "fy": 60.0, "x_offset": 32.0, "y_offset": 24.0}
    (folder / "camera_params.json").write_text(json.dumps(params if params is not None else default))
    return folder


ZERO_FOCAL_XML = (
    "<depth><focal_length_x>0</focal_length_x><focal_length_y>0</focal_length_y>"
    "<principal_point_x>32</principal_point_x><principal_point_y>24</principal_point_y></depth>"
)


def truncated_uoc(folder: Path) -> Path:
    write_uoc(folder)
    color = folder / "000000-color.png"
    color.write_bytes(color.read_bytes()[:60])
    return folder


def zero_intrinsics_params() -> dict:
    return {"img_width": W, "img_height": H, "fx": 0.0, "fy": 0.0, "x_offset": 0.0, "y_offset": 0.0}


def write_tum_pair(folder: Path, truncate: str | None = None) -> Path:
    """A TUM-style pair at the PrimeSense size (the default intrinsics fit it); ``truncate`` cuts one file short."""
    folder.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(folder / "a_color.png"), np.zeros((480, 640, 3), np.uint8))
    cv2.imwrite(str(folder / "a_depth.png"), np.full((480, 640), 5000, np.uint16))
    if truncate is not None:
        path = folder / f"a_{truncate}.png"
        path.write_bytes(path.read_bytes()[:200])
    return folder / "a_color.png"


def write_tum_sequence(folder: Path, depth_list: str = "1.0 a_depth.png\n", truncate: str | None = None) -> Path:
    write_tum_pair(folder, truncate)
    (folder / "rgb.txt").write_text("# colour\n1.0 a_color.png\n")
    (folder / "depth.txt").write_text(depth_list)
    return folder


def write_open3d(
    folder: Path,
    camera: str | None = '{"width": 64, "height": 48, "intrinsic_matrix": [60, 0, 0, 0, 60, 0, 32, 24, 1]}',
    trajectory: str | None = None,
    truncate: bool = False,
) -> Path:
    """An Open3D RGB-D folder with one frame (color/, depth/, camera_intrinsic.json, optional trajectory.log)."""
    (folder / "color").mkdir(parents=True, exist_ok=True)
    (folder / "depth").mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(folder / "color" / "000000.jpg"), np.zeros((H, W, 3), np.uint8))
    depth = folder / "depth" / "000000.png"
    cv2.imwrite(str(depth), np.full((H, W), 1000, np.uint16))
    if truncate:
        depth.write_bytes(depth.read_bytes()[: depth.stat().st_size // 2])
    if camera is not None:
        (folder / "camera_intrinsic.json").write_text(camera)
    if trajectory is not None:
        (folder / "trajectory.log").write_text(trajectory)
    return folder


def write_pcd(path: Path, organized: bool = True, truncate: bool = False, depth: float = 1.0) -> Path:
    """A small ASCII PCD (x y z rgb), organized 4x3 or a single row, ``depth`` m ahead; optionally cut short."""
    width, height = (4, 3) if organized else (12, 1)
    header = (
        "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
        f"WIDTH {width}\nHEIGHT {height}\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {width * height}\nDATA ascii\n"
    )
    rows = [f"{(c - 1.5) / 10} {(r - 1) / 10} {depth} 0" for r in range(height) for c in range(width)]
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(header + "\n".join(rows[: 5 if truncate else None]) + "\n")
    return path


def write_tiff(folder: Path, xml: str | None = None, truncate: bool = False) -> Path:
    """A PCL ImageGrabber layout with one frame (tiff/ and pclzf/)."""
    (folder / "tiff").mkdir(parents=True, exist_ok=True)
    (folder / "pclzf").mkdir(parents=True, exist_ok=True)
    stamp = "20121214T142255.814212"
    cv2.imwrite(str(folder / "tiff" / f"frame_{stamp}_rgb.tiff"), np.zeros((H, W, 3), np.uint8))
    cv2.imwrite(str(folder / "tiff" / f"frame_{stamp}_depth.tiff"), np.full((H, W), 900, np.uint16))
    if truncate:
        depth = folder / "tiff" / f"frame_{stamp}_depth.tiff"
        depth.write_bytes(depth.read_bytes()[:100])
    camera = "<focal_length_x>60</focal_length_x><focal_length_y>60</focal_length_y>"
    camera += "<principal_point_x>32</principal_point_x><principal_point_y>24</principal_point_y>"
    default = f'<?xml version="1.0"?>\n<rgb>{camera}</rgb>\n<depth>{camera}'
    default += "<z_multiplication_factor>0.001</z_multiplication_factor></depth>\n"
    if xml != "missing":
        (folder / "pclzf" / f"frame_{stamp}.xml").write_text(default if xml is None else xml)
    return folder


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
        "truncated colour file": lambda tmp: ColorDepthPairReader(truncated_uoc(tmp / "e")),
    },
    TumSequenceReader: {
        "missing folder": lambda tmp: TumSequenceReader(tmp / "nowhere"),
        "no depth within the time tolerance": lambda tmp: TumSequenceReader(write_tum_sequence(tmp, "9.0 a.png\n")),
        "malformed list line": lambda tmp: TumSequenceReader(write_tum_sequence(tmp, "not-a-time\n")),
        "missing frame": lambda tmp: TumSequenceReader(write_tum_sequence(tmp), frame=3),
        "malformed ground-truth line": lambda tmp: TumSequenceReader(
            (write_tum_sequence(tmp), (tmp / "groundtruth.txt").write_text("1.0 0 0 0 0 0 1\n"))[0]
        ),
        "truncated depth file": lambda tmp: TumSequenceReader(write_tum_sequence(tmp, truncate="depth")),
        "zero intrinsics": lambda tmp: TumSequenceReader(
            write_tum_sequence(tmp), intrinsics=CameraIntrinsics(0, 0, 0, 0, 0, 0)
        ),
        "intrinsics for another image size": lambda tmp: TumSequenceReader(write_tum_sequence(tmp), intrinsics=K),
    },
    Open3dFolderReader: {
        "missing folder": lambda tmp: Open3dFolderReader(tmp / "nowhere"),
        "missing frame": lambda tmp: Open3dFolderReader(write_open3d(tmp / "a"), frame=1),
        "truncated depth file": lambda tmp: Open3dFolderReader(write_open3d(tmp / "b", truncate=True)),
        "camera JSON that is not JSON": lambda tmp: Open3dFolderReader(write_open3d(tmp / "c", camera="{fx: 60")),
        "camera for the default size": lambda tmp: Open3dFolderReader(write_open3d(tmp / "d", camera=None)),
        "pose row of three numbers": lambda tmp: Open3dFolderReader(
            write_open3d(tmp / "e", trajectory="0 0 1\n1 0 0 0\n0 1 0 0\n0 0 1\n0 0 0 1\n")
        ),
    },
    TumPairReader: {
        "missing depth file": lambda tmp: TumPairReader((write_tum_pair(tmp), (tmp / "a_depth.png").unlink())[0]),
        "truncated colour file": lambda tmp: TumPairReader(write_tum_pair(tmp, truncate="color")),
        "zero depth scale": lambda tmp: TumPairReader(write_tum_pair(tmp), depth_scale=0.0),
        "zero intrinsics": lambda tmp: TumPairReader(
            write_tum_pair(tmp), intrinsics=CameraIntrinsics(0, 0, 0, 0, 0, 0)
        ),
        "name without colour or depth": lambda tmp: TumPairReader(tmp / "picture.png"),
    },
    PcdReader: {
        "missing file": lambda tmp: PcdReader(tmp / "nowhere.pcd"),
        "truncated file": lambda tmp: PcdReader(write_pcd(tmp / "cut.pcd", truncate=True)),
        "unorganized cloud behind the camera": lambda tmp: PcdReader(
            write_pcd(tmp / "row.pcd", organized=False, depth=-1.0)
        ),
        "not a PCD file": lambda tmp: PcdReader((tmp / "junk.pcd", (tmp / "junk.pcd").write_text("hello"))[0]),
        "zero intrinsics": lambda tmp: PcdReader(
            write_pcd(tmp / "a.pcd"), intrinsics=CameraIntrinsics(0, 0, 0, 0, 0, 0)
        ),
    },
    BagReader: {
        "missing bag": lambda tmp: BagReader(tmp / "nowhere.bag"),
        "not a bag file": lambda tmp: BagReader((tmp / "junk.bag", (tmp / "junk.bag").write_text("hello"))[0]),
        "missing frame": lambda tmp: BagReader(write_small_bag(tmp / "a.bag"), frame=1),
        "named topic of another type": lambda tmp: BagReader(write_small_bag(tmp / "b"), color_topic=INFO_TOPIC),
    },
    BagCloudReader: {
        "missing bag": lambda tmp: BagCloudReader(tmp / "nowhere"),
        "image bag": lambda tmp: BagCloudReader(write_small_bag(tmp / "c.bag")),
    },
    StreamReader: {
        "source ended": lambda tmp: StreamReader(played_once(recorded_stream(str(write_uoc(tmp / "a")), loop=False))),
        "unreadable frame": lambda tmp: StreamReader(recorded_stream(str(truncated_uoc(tmp / "b")))),
        "closed stream": lambda tmp: StreamReader(closed(recorded_stream(str(write_uoc(tmp / "c"))))),
    },
    PerceivedFrameReader: {
        "no perception pipeline in the tree": lambda tmp: PerceivedFrameReader(),
        "a perception pipeline without a frame": lambda tmp: PerceivedFrameReader(pipeline="broken"),
    },
    TiffSequenceReader: {
        "missing folder": lambda tmp: TiffSequenceReader(tmp / "nowhere"),
        "missing frame": lambda tmp: TiffSequenceReader(write_tiff(tmp), frame=1),
        "missing intrinsics file": lambda tmp: TiffSequenceReader(write_tiff(tmp, xml="missing")),
        "malformed intrinsics file": lambda tmp: TiffSequenceReader(write_tiff(tmp, xml="<rgb><focal")),
        "zero focal length": lambda tmp: TiffSequenceReader(write_tiff(tmp, xml=ZERO_FOCAL_XML)),
        "truncated depth file": lambda tmp: TiffSequenceReader(write_tiff(tmp, truncate=True)),
    },
}


def write_small_bag(path: Path) -> Path:
    """A bag (ROS 1 for a .bag path, else ROS 2) of one small colour + depth frame."""
    frame = Frame(np.full((H, W, 3), 90, np.uint8), np.full((H, W), 0.8, np.float32), K)
    return write_bag(path, [frame], ros1=path.suffix == ".bag")


def played_once(stream: FrameStream) -> FrameStream:
    """``stream`` after its first frame was taken (a one-frame recording played once has then ended)."""
    stream.next_frame()
    return stream


def closed(stream: FrameStream) -> FrameStream:
    stream.close()
    return stream


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
    pipeline = Pipeline("broken", [Seed(seeds), annotator])
    pipeline.tick_once()  # must not raise
    deadline = time.monotonic() + 20.0
    while annotator.status is Status.RUNNING and time.monotonic() < deadline:  # threaded annotators
        time.sleep(0.005)
        pipeline.tick_once()
    assert annotator.status is Status.FAILURE, f"{type(annotator).__name__} did not fail"
    message = annotator.feedback_message
    assert message.strip(), f"{type(annotator).__name__} failed without a reason"
    assert not CRASH.match(message), f"{type(annotator).__name__} crashed instead of failing: {message}"


EXPERTS = [cls for cls in discover_annotators() if cls.inputs]
READERS = [cls for cls in discover_annotators() if not cls.inputs]


def test_the_tables_cover_every_discovered_annotator() -> None:
    assert {c.__name__ for c in discover_annotators()} >= {
        "KitchenSceneReader", "ColorDepthPairReader", "TumSequenceReader", "TumPairReader", "PcdReader",
        "TiffSequenceReader", "PointCloudGenerator", "RangeFilter", "RegionFilter", "CropBoxFilter",
        "NormalEstimator", "SupportPlaneSegmenter", "ClusterExtractor", "ClutterSegmenter", "SemanticColorAnnotator",
        "ColorHistogramAnnotator", "PoseAnnotator", "ShapeAnnotator", "SizeAnnotator", "KnowledgeClassifier",
        "TextReader", "OnnxDetector", "ImageRegionSegmenter",
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
def test_experts_fail_with_a_reason_on_broken_input(expert: type[Annotator], case: str, tmp_path: Path) -> None:
    make_seeds, _ = BROKEN_CASES[case]
    factory = FACTORIES.get(expert, lambda tmp: expert())
    assert_fails_with_a_reason(factory(tmp_path), make_seeds())


@pytest.mark.parametrize(
    ("expert", "case"),
    [(expert, case) for expert, cases in BROKEN_CONFIGURATIONS.items() for case in sorted(cases)],
    ids=lambda value: value.__name__ if isinstance(value, type) else value,
)
def test_experts_fail_with_a_reason_on_broken_configuration(expert: type[Annotator], case: str, tmp_path) -> None:
    seeds = [
        color(),
        flat_cloud(),
        up_normals(),
        CameraInfo(K),
        hypothesis(),
        *evidence_types(),
        person(keypoints(1.0)),
    ]
    assert_fails_with_a_reason(BROKEN_CONFIGURATIONS[expert][case](tmp_path), seeds)


@pytest.mark.parametrize(
    ("reader", "case"),
    [(reader, case) for reader in READERS for case in sorted(BROKEN_READERS.get(reader, {}))],
    ids=lambda value: value.__name__ if isinstance(value, type) else value,
)
def test_readers_fail_with_a_reason_on_broken_configuration(reader: type[Annotator], case: str, tmp_path) -> None:
    assert_fails_with_a_reason(BROKEN_READERS[reader][case](tmp_path), [])
