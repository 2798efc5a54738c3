"""The seed's Fig. 2 tabletop tree: capture, cloud, filter, support plane, clusters, then colour and pose in parallel.

Without an input path the capture is the built-in kitchen scene (view "table"); with one it reads frame
``frame`` of a colour/depth folder in the uoc layout (NNNNNN-color.png, NNNNNN-depth.png, camera_params.json).
"""

from __future__ import annotations

from annotators.clusters import ClusterExtractor
from annotators.color import SemanticColorAnnotator
from annotators.filters import RangeFilter
from annotators.plane import SupportPlaneSegmenter
from annotators.point_cloud import PointCloudGenerator
from annotators.pose import PoseAnnotator
from annotators.readers import ColorDepthPairReader, KitchenSceneReader
from robokudo.annotator import Annotator
from robokudo.parallel import ThresholdParallel
from robokudo.pipeline import Pipeline


def create_reader(input_path: str | None = None, frame: int = 0) -> Annotator:
    """The capture node: the built-in kitchen scene, or frame ``frame`` of a colour/depth pair folder."""
    if input_path is None:
        reader: Annotator = KitchenSceneReader()
        reader.reason = "capture: renders the built-in kitchen scene (camera looking at the table)"
    else:
        reader = ColorDepthPairReader(input_path, frame=frame)
        reader.reason = f"capture: reads frame {frame} of the colour/depth pairs in {input_path}"
    return reader


def create_tree(input_path: str | None = None, frame: int = 0) -> Pipeline:
    """A fresh tabletop Pipeline (Fig. 2 of the seed) on the kitchen scene or on a recorded frame."""
    return create_pipeline(create_reader(input_path, frame))


def create_pipeline(reader: Annotator) -> Pipeline:
    """The tabletop Pipeline behind any capture node that writes ColorImage, DepthImage and CameraInfo."""
    cloud = PointCloudGenerator()
    cloud.reason = "back-projects depth with the intrinsics into an organized, coloured point cloud"
    crop = RangeFilter(min_depth=0.2, max_depth=2.5)
    crop.reason = "drops points outside the sensor's useful range (0.2-2.5 m) before any geometry"
    plane = SupportPlaneSegmenter()
    plane.reason = "finds the table (the dominant, roughly horizontal plane) that objects stand on"
    clusters = ClusterExtractor()
    clusters.reason = "segments what stands on the table into object hypotheses"
    color = SemanticColorAnnotator()
    color.reason = "names each hypothesis' dominant colour"
    pose = PoseAnnotator()
    pose.reason = "gives each hypothesis the pose of its oriented bounding box"
    describe = ThresholdParallel("describe", [color, pose])
    describe.reason = "colour and pose are independent given the hypotheses; both must succeed"
    root = Pipeline("tabletop", [reader, cloud, crop, plane, clusters, describe])
    root.reason = "the seed's Fig. 2 tabletop perception pipeline"
    return root
