"""Writing small ROS 1 / ROS 2 bags with rosbags' own writers and typestores (test helper).

Frames are written as a robot records them: ``sensor_msgs/Image`` colour (``rgb8``) and depth (``16UC1``, mm)
on ``/camera/color/image_raw`` and ``/camera/depth/image_raw`` with ``/camera/color/camera_info``, or organized
``sensor_msgs/PointCloud2`` on ``/camera/points``.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.rosbag1 import Writer as Writer1
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Writer2
from rosbags.typesys import Stores, get_typestore

from annotators.readers.frame_io import Frame

COLOR_TOPIC = "/camera/color/image_raw"
DEPTH_TOPIC = "/camera/depth/image_raw"
INFO_TOPIC = "/camera/color/camera_info"
CLOUD_TOPIC = "/camera/points"


def _typestore(ros1: bool) -> Any:
    return get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)


def _header(store: Any, ros1: bool, stamp_ns: int, frame_id: str) -> Any:
    types = store.types
    stamp = types["builtin_interfaces/msg/Time"](sec=stamp_ns // 10**9, nanosec=stamp_ns % 10**9)
    if ros1:
        return types["std_msgs/msg/Header"](seq=0, stamp=stamp, frame_id=frame_id)
    return types["std_msgs/msg/Header"](stamp=stamp, frame_id=frame_id)


def _image(store: Any, ros1: bool, stamp_ns: int, pixels: np.ndarray, encoding: str) -> Any:
    height, width = pixels.shape[:2]
    data = np.ascontiguousarray(pixels).view(np.uint8).reshape(-1)
    return store.types["sensor_msgs/msg/Image"](
        header=_header(store, ros1, stamp_ns, "camera_color_optical_frame"),
        height=height,
        width=width,
        encoding=encoding,
        is_bigendian=0,
        step=data.size // height,
        data=data,
    )


def _camera_info(store: Any, ros1: bool, stamp_ns: int, frame: Frame) -> Any:
    k = frame.intrinsics
    types = store.types
    roi = types["sensor_msgs/msg/RegionOfInterest"](x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)
    matrices = {
        "d": np.zeros(5),
        "k": np.array([k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1], dtype=np.float64),
        "r": np.eye(3).reshape(-1),
        "p": np.array([k.fx, 0, k.cx, 0, 0, k.fy, k.cy, 0, 0, 0, 1, 0], dtype=np.float64),
    }
    if ros1:
        matrices = {name.upper(): value for name, value in matrices.items()}
    return types["sensor_msgs/msg/CameraInfo"](
        header=_header(store, ros1, stamp_ns, "camera_color_optical_frame"),
        height=k.height,
        width=k.width,
        distortion_model="plumb_bob",
        binning_x=0,
        binning_y=0,
        roi=roi,
        **matrices,
    )


def _cloud(store: Any, ros1: bool, stamp_ns: int, frame: Frame) -> Any:
    assert frame.points is not None
    height, width = frame.depth.shape
    types = store.types
    field = types["sensor_msgs/msg/PointField"]
    rgb = (frame.color[..., 0].astype(np.uint32) << 16) | (frame.color[..., 1].astype(np.uint32) << 8)
    rgb |= frame.color[..., 2].astype(np.uint32)
    grid = np.zeros((height, width), dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("pad", "<f4"), ("rgb", "<u4")])
    grid["x"], grid["y"], grid["z"], grid["rgb"] = (*np.moveaxis(frame.points, -1, 0), rgb)
    fields = [
        field(name=name, offset=offset, datatype=datatype, count=1)
        for name, offset, datatype in (("x", 0, 7), ("y", 4, 7), ("z", 8, 7), ("rgb", 16, 7))
    ]
    return types["sensor_msgs/msg/PointCloud2"](
        header=_header(store, ros1, stamp_ns, "camera"),
        height=height,
        width=width,
        fields=fields,
        is_bigendian=False,
        point_step=20,
        row_step=20 * width,
        data=grid.view(np.uint8).reshape(-1),
        is_dense=False,
    )


def _depth_pixels(frame: Frame, encoding: str) -> np.ndarray:
    if encoding == "32FC1":
        return frame.depth.astype("<f4")
    return np.rint(frame.depth * 1000.0).astype("<u2")


def write_bag(
    path: Path,
    frames: Sequence[Frame],
    *,
    ros1: bool,
    period_ns: int = 100_000_000,
    cloud: bool = False,
    color_encoding: str = "rgb8",
    depth_encoding: str = "16UC1",
    depth_offset_ns: int = 3_000_000,
    info_offset_ns: int = 0,
    mcap: bool = False,
) -> Path:
    """Write ``frames`` (colour + depth + camera info, or organized clouds) to a new bag at ``path``; ``path``.

    Frame ``i`` is stamped at ``1.7e9 s + i * period_ns``; depth ``depth_offset_ns`` later (real cameras are a few
    ms apart), camera info ``info_offset_ns`` later. Colour is ``rgb8`` or ``bgr8``, depth ``16UC1``/``mono16``
    (mm) or ``32FC1`` (m). A ROS 2 bag is stored in SQLite, or in MCAP when ``mcap``.
    """
    store = _typestore(ros1)
    serialize = store.serialize_ros1 if ros1 else store.serialize_cdr
    plugin = StoragePlugin.MCAP if mcap else StoragePlugin.SQLITE3
    writer = Writer1(path) if ros1 else Writer2(path, version=9, storage_plugin=plugin)
    start = 1_700_000_000 * 10**9
    with writer:
        if cloud:
            topics = {CLOUD_TOPIC: "sensor_msgs/msg/PointCloud2"}
        else:
            topics = {
                INFO_TOPIC: "sensor_msgs/msg/CameraInfo",
                COLOR_TOPIC: "sensor_msgs/msg/Image",
                DEPTH_TOPIC: "sensor_msgs/msg/Image",
            }
        connections = {topic: writer.add_connection(topic, kind, typestore=store) for topic, kind in topics.items()}
        for index, frame in enumerate(frames):
            stamp = start + index * period_ns
            if cloud:
                messages = [(CLOUD_TOPIC, stamp, _cloud(store, ros1, stamp, frame))]
            else:
                color = frame.color[..., ::-1] if color_encoding == "bgr8" else frame.color
                depth_stamp, info_stamp = stamp + depth_offset_ns, stamp + info_offset_ns
                depth = _depth_pixels(frame, depth_encoding)
                messages = [
                    (INFO_TOPIC, info_stamp, _camera_info(store, ros1, info_stamp, frame)),
                    (COLOR_TOPIC, stamp, _image(store, ros1, stamp, color, color_encoding)),
                    (DEPTH_TOPIC, depth_stamp, _image(store, ros1, depth_stamp, depth, depth_encoding)),
                ]
            for topic, time_ns, message in sorted(messages, key=lambda item: item[1]):
                connection = connections[topic]
                writer.write(connection, time_ns, serialize(message, connection.msgtype))
    return path
