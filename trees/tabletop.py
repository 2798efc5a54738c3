"""The seed's Fig. 2 tabletop tree: capture, cloud, filter, support plane, objects, then colour and pose in parallel.

Without an input path the capture is the built-in kitchen scene (view "table"); with one, the reader is chosen
from the path by :func:`annotators.readers.choice.reader_for` (TUM, uoc, PCL TIFF, PCD layouts; ValueError for others).
A reader that writes the point cloud itself (PcdReader) needs no PointCloudGenerator.
"""

from __future__ import annotations

from annotators.cloud.clutter import ClutterSegmenter
from annotators.cloud.filters import RangeFilter
from annotators.cloud.point_cloud import PointCloudGenerator
from annotators.cloud.pose import PoseAnnotator
from annotators.cloud.support_choice import SupportPlaneSegmenter
from annotators.image.color import SemanticColorAnnotator
from annotators.readers.choice import reader_for
from annotators.readers.frame_readers import KitchenSceneReader
from robokudo.core.annotator import Annotator
from robokudo.core.parallel import ThresholdParallel
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import CameraIntrinsics, PointCloud


def create_reader(
    input_path: str | None = None, frame: int = 0, intrinsics: CameraIntrinsics | None = None
) -> Annotator:
    """The capture node: the built-in kitchen scene, or the reader of ``input_path`` (ValueError when none fits)."""
    if input_path is None:
        reader: Annotator = KitchenSceneReader()
        reader.reason = "capture: renders the built-in kitchen scene (camera looking at the table)"
    else:
        reader = reader_for(input_path, frame, intrinsics)
        reader.reason = f"capture: reads frame {frame} of {input_path} ({type(reader).__name__})"
    return reader


def create_tree(input_path: str | None = None, frame: int = 0, intrinsics: CameraIntrinsics | None = None) -> Pipeline:
    """A fresh tabletop Pipeline (Fig. 2 of the seed) on the kitchen scene or on a recorded frame (``intrinsics``:
    the camera of a point-cloud input)."""
    return create_pipeline(create_reader(input_path, frame, intrinsics))


def create_pipeline(reader: Annotator, segmenter: Annotator | None = None) -> Pipeline:
    """The tabletop Pipeline behind any capture node that writes ColorImage, DepthImage and CameraInfo;
    ``segmenter`` (default: a ClutterSegmenter) turns the cloud and plane into object hypotheses."""
    front: list[Annotator] = [reader]
    if PointCloud not in reader.outputs:
        cloud = PointCloudGenerator()
        cloud.reason = "back-projects depth with the intrinsics into an organized, coloured point cloud"
        front.append(cloud)
    crop = RangeFilter(min_depth=0.2, max_depth=2.5)
    crop.reason = "drops points outside the sensor's useful range (0.2-2.5 m) before any geometry"
    plane = SupportPlaneSegmenter()
    plane.reason = "finds the table (the dominant, roughly horizontal plane) that objects stand on"
    clusters = segmenter or ClutterSegmenter()
    clusters.reason = "segments what stands on the table into object hypotheses"
    color = SemanticColorAnnotator()
    color.reason = "names each hypothesis' dominant colour"
    pose = PoseAnnotator()
    pose.reason = "gives each hypothesis the pose of its oriented bounding box"
    describe = ThresholdParallel(
        "describe", [color, pose], reason="colour and pose are independent given the hypotheses; both must succeed"
    )
    return Pipeline(
        "tabletop", [*front, crop, plane, clusters, describe], reason="the seed's Fig. 2 tabletop perception pipeline"
    )
