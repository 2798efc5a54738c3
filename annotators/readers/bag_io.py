"""ROS 1 and ROS 2 bags (read with ``rosbags``, no ROS needed) as RGB-D frames.

A bag is a ``.bag`` file (ROS 1), or a ROS 2 recording: a folder with ``metadata.yaml``, or its ``.mcap`` / ``.db3``
file. Frames come from either

* ``sensor_msgs/Image`` colour (``rgb8``, ``bgr8``, ``rgba8``, ``bgra8``) and registered depth (``16UC1`` / ``mono16``
  in millimetres unless ``depth_scale`` says otherwise, ``32FC1`` in metres) with a ``sensor_msgs/CameraInfo``
  for the intrinsics; colour and depth are paired by header stamp (nearest within ``max_difference`` seconds,
  each message used once, unpaired ones dropped), or
* an organized ``sensor_msgs/PointCloud2`` (x, y, z float32 and an ``rgb``/``rgba`` field): colour, depth (z) and
  the cloud itself, with the intrinsics fitted to the grid as for PCD files.

Topics are picked by message type (colour and depth images told apart by their encoding; the camera info beside
the colour topic) unless named. :func:`bag_frames` yields the frames in recording order; every problem raises
:class:`~annotators.readers.frame_io.FrameError` with the reason.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import Any

import numpy as np
from rosbags.highlevel import AnyReader, AnyReaderError
from rosbags.interfaces import Connection

from annotators.readers.frame_io import Frame, FrameError, assemble_frame
from annotators.readers.pcd_io import fit_intrinsics
from robokudo.core.types import CameraIntrinsics

IMAGE = "sensor_msgs/msg/Image"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
POINT_CLOUD = "sensor_msgs/msg/PointCloud2"

COLOR_ENCODINGS = ("rgb8", "bgr8", "rgba8", "bgra8")
DEPTH_ENCODINGS = ("16UC1", "mono16", "32FC1")
MILLIMETRES = 1000.0
"""Depth units per metre of 16-bit depth images (the ROS convention: millimetres)."""
MAX_STAMP_DIFFERENCE = 0.02
"""Largest header stamp gap (seconds) between a colour image and the depth image paired with it."""

ROS2_STORAGE_SUFFIXES = (".mcap", ".db3")


def is_bag(path: Path) -> bool:
    """True for a ROS 1 ``.bag`` file, a ROS 2 bag folder (``metadata.yaml``) or a ``.mcap`` / ``.db3`` file."""
    if path.is_dir():
        return (path / "metadata.yaml").is_file()
    return path.is_file() and path.suffix.lower() in (".bag", *ROS2_STORAGE_SUFFIXES)


@dataclass(frozen=True)
class BagTopics:
    """The topics frames are read from: colour + depth (+ camera info), or a point cloud."""

    color: str | None = None
    depth: str | None = None
    info: str | None = None
    cloud: str | None = None

    @property
    def is_cloud(self) -> bool:
        """True when frames come from a PointCloud2 topic."""
        return self.cloud is not None


ANY_TOPICS = BagTopics()
"""No topic named: every topic is picked by message type."""


def open_bag(path: str | Path) -> AnyReader:
    """An opened reader of the bag at ``path`` (close it); FrameError when it is no bag rosbags can read."""
    path = Path(path)
    if not is_bag(path):
        raise FrameError(f"{path} is not a bag (.bag file, folder with metadata.yaml, .mcap or .db3 file)")
    try:
        reader = AnyReader([path])
        reader.open()
    except (AnyReaderError, OSError, ValueError, KeyError) as error:
        raise FrameError(f"cannot open the bag {path}: {type(error).__name__}: {error}") from None
    return reader


def _stamp(message: Any) -> float:
    stamp = message.header.stamp
    return float(stamp.sec) + float(getattr(stamp, "nanosec", getattr(stamp, "nsec", 0))) * 1e-9


def _topics_of(reader: AnyReader, msgtype: str) -> list[str]:
    return sorted({c.topic for c in reader.connections if c.msgtype == msgtype})


def _first_message(reader: AnyReader, topic: str) -> Any:
    connections = [c for c in reader.connections if c.topic == topic]
    for connection, _, raw in reader.messages(connections=connections):
        return reader.deserialize(raw, connection.msgtype)
    raise FrameError(f"topic {topic} holds no message")


def _require(reader: AnyReader, topic: str, msgtype: str) -> str:
    found = {c.msgtype for c in reader.connections if c.topic == topic}
    if not found:
        known = ", ".join(sorted({f"{c.topic} ({c.msgtype})" for c in reader.connections})) or "none"
        raise FrameError(f"the bag has no topic {topic}; its topics: {known}")
    if msgtype not in found:
        raise FrameError(f"topic {topic} carries {', '.join(sorted(found))}, expected {msgtype}")
    return topic


def _one(candidates: list[str], what: str, hint: str) -> str:
    if len(candidates) == 1:
        return candidates[0]
    if not candidates:
        raise FrameError(f"the bag has no {what}")
    raise FrameError(f"the bag has several {what}s ({', '.join(candidates)}); name one with {hint}")


def pick_topics(reader: AnyReader, requested: BagTopics = ANY_TOPICS) -> BagTopics:
    """The topics to read: those ``requested`` (checked), the others picked by message type and encoding."""
    if requested.cloud is not None:
        return BagTopics(cloud=_require(reader, requested.cloud, POINT_CLOUD))
    images = _topics_of(reader, IMAGE)
    if requested.color is None and requested.depth is None and not images:
        clouds = _topics_of(reader, POINT_CLOUD)
        if clouds:
            return BagTopics(cloud=_one(clouds, "PointCloud2 topic", "the cloud topic"))
        raise FrameError("the bag has neither sensor_msgs/Image nor sensor_msgs/PointCloud2 topics")
    encodings = {topic: _first_message(reader, topic).encoding for topic in images}
    color = requested.color or _one(
        [t for t in images if encodings[t] in COLOR_ENCODINGS], "colour image topic", "the colour topic"
    )
    depth = requested.depth or _one(
        [t for t in images if encodings[t] in DEPTH_ENCODINGS], "depth image topic", "the depth topic"
    )
    _require(reader, color, IMAGE)
    _require(reader, depth, IMAGE)
    if requested.info is not None:
        info = _require(reader, requested.info, CAMERA_INFO)
    else:
        infos = _topics_of(reader, CAMERA_INFO)
        beside = [t for t in infos if PurePosixPath(t).parent == PurePosixPath(color).parent]
        info = _one(beside or infos, "camera info topic", "the camera info topic")
    return BagTopics(color=color, depth=depth, info=info)


def named_topics(path: str | Path, names: list[str]) -> BagTopics:
    """The topics ``names`` (as given to ``--topic``) sorted into their roles by the bag's message types: a
    PointCloud2 topic, colour and depth Image topics (told apart by encoding) and a CameraInfo topic. FrameError
    names a topic the bag lacks, one of another type, or two topics for one role."""
    roles: dict[str, str] = {}
    reader = open_bag(path)
    try:
        for name in names:
            found = {c.msgtype for c in reader.connections if c.topic == name}
            if not found:
                known = ", ".join(sorted({f"{c.topic} ({c.msgtype})" for c in reader.connections})) or "none"
                raise FrameError(f"the bag has no topic {name}; its topics: {known}")
            if POINT_CLOUD in found:
                role = "cloud"
            elif CAMERA_INFO in found:
                role = "info"
            elif IMAGE in found:
                encoding = _first_message(reader, name).encoding
                if encoding in COLOR_ENCODINGS:
                    role = "color"
                elif encoding in DEPTH_ENCODINGS:
                    role = "depth"
                else:
                    raise FrameError(f"topic {name} carries images of encoding {encoding!r}, neither colour nor depth")
            else:
                carried = ", ".join(sorted(found))
                raise FrameError(f"topic {name} carries {carried}: no Image, CameraInfo or PointCloud2")
            if role in roles and roles[role] != name:
                raise FrameError(f"two {role} topics named: {roles[role]} and {name}")
            roles[role] = name
    finally:
        reader.close()
    if "cloud" in roles and len(roles) > 1:
        raise FrameError("name either a PointCloud2 topic or image topics, not both")
    return BagTopics(**roles)


def _rows(message: Any, channels: int, itemsize: int) -> np.ndarray:
    """The image's bytes as a (height, width * channels * itemsize) array, honouring the row step."""
    row = message.width * channels * itemsize
    data = np.asarray(message.data, dtype=np.uint8)
    if message.step < row or data.size < message.step * message.height:
        raise FrameError(
            f"image data is {data.size} bytes with step {message.step}, too short for "
            f"{message.width}x{message.height} {message.encoding}"
        )
    return data[: message.step * message.height].reshape(message.height, message.step)[:, :row]


def decode_color_image(message: Any) -> np.ndarray:
    """RGB uint8 HxWx3 from a colour sensor_msgs/Image."""
    encoding = message.encoding
    if encoding not in COLOR_ENCODINGS:
        raise FrameError(f"colour image encoding {encoding!r} is not supported ({', '.join(COLOR_ENCODINGS)})")
    channels = 4 if encoding.endswith("a8") else 3
    pixels = _rows(message, channels, 1).reshape(message.height, message.width, channels)
    if encoding.startswith("bgr"):
        return np.ascontiguousarray(pixels[..., 2::-1])
    return np.ascontiguousarray(pixels[..., :3]) if channels == 4 else pixels


def decode_depth_image(message: Any, depth_scale: float = MILLIMETRES) -> np.ndarray:
    """Depth in metres (float32 HxW, 0 = no data) from a 16UC1/mono16 (1/``depth_scale`` m) or 32FC1 (m) image."""
    encoding = message.encoding
    big = bool(message.is_bigendian)
    if encoding in ("16UC1", "mono16"):
        raw = _rows(message, 1, 2).copy().view(">u2" if big else "<u2").reshape(message.height, message.width)
        depth = raw.astype(np.float32)
        depth *= np.float32(1.0 / depth_scale)
        return depth
    if encoding == "32FC1":
        raw = _rows(message, 1, 4).copy().view(">f4" if big else "<f4").reshape(message.height, message.width)
        depth = raw.astype(np.float32)
        depth[~np.isfinite(depth) | (depth < 0)] = 0.0
        return depth
    raise FrameError(f"depth image encoding {encoding!r} is not supported ({', '.join(DEPTH_ENCODINGS)})")


def camera_intrinsics(message: Any) -> CameraIntrinsics:
    """Pinhole intrinsics from a sensor_msgs/CameraInfo (ROS 2 ``k`` or ROS 1 ``K``)."""
    k = np.asarray(message.k if hasattr(message, "k") else message.K, dtype=np.float64)
    if k.size != 9:
        raise FrameError(f"camera info has a K matrix of {k.size} values, expected 9")
    return CameraIntrinsics(
        fx=float(k[0]), fy=float(k[4]), cx=float(k[2]), cy=float(k[5]), width=message.width, height=message.height
    )


_FIELD_TYPES = {1: "i1", 2: "u1", 3: "i2", 4: "u2", 5: "i4", 6: "u4", 7: "f4", 8: "f8"}


def decode_point_cloud(message: Any, source: str, intrinsics: CameraIntrinsics | None = None) -> Frame:
    """A Frame (colour, depth = z, the organized cloud) from an organized sensor_msgs/PointCloud2."""
    if message.height <= 1:
        raise FrameError(f"{source}: the point cloud is not organized (height {message.height})")
    order = ">" if message.is_bigendian else "<"
    fields = {f.name: f for f in message.fields}
    missing = {"x", "y", "z"} - set(fields)
    if missing:
        raise FrameError(f"{source}: the point cloud has no {', '.join(sorted(missing))} field")
    color_name = "rgb" if "rgb" in fields else "rgba" if "rgba" in fields else None
    if color_name is None:
        raise FrameError(f"{source}: the point cloud has no rgb/rgba field (fields: {', '.join(fields)})")
    names = ["x", "y", "z", color_name]
    try:
        dtype = np.dtype(
            {
                "names": names,
                "formats": [order + _FIELD_TYPES[fields[n].datatype] for n in names],
                "offsets": [fields[n].offset for n in names],
                "itemsize": message.point_step,
            }
        )
    except KeyError:
        raise FrameError(f"{source}: unknown PointField datatype") from None
    count = message.width * message.height
    data = np.asarray(message.data, dtype=np.uint8)
    if message.row_step * message.height > data.size or message.row_step < message.point_step * message.width:
        raise FrameError(f"{source}: the point cloud data is shorter than its {message.width}x{message.height} grid")
    rows = data[: message.row_step * message.height].reshape(message.height, message.row_step)
    grid = np.ascontiguousarray(rows[:, : message.point_step * message.width]).view(dtype).reshape(count)
    points = np.stack([grid["x"], grid["y"], grid["z"]], axis=-1).astype(np.float32)
    points = points.reshape(message.height, message.width, 3)
    packed = grid[color_name].astype(dtype[color_name].newbyteorder("=")).view(np.uint32)
    colors = np.stack([(packed >> 16) & 255, (packed >> 8) & 255, packed & 255], axis=-1).astype(np.uint8)
    colors = colors.reshape(message.height, message.width, 3)
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(points).all(axis=2) & (points[..., 2] > 0)
    if not valid.any():
        raise FrameError(f"{source}: the point cloud has no finite point")
    points[~valid] = np.nan
    depth = np.where(valid, points[..., 2], np.float32(0.0)).astype(np.float32)
    return assemble_frame(
        colors, depth, intrinsics or fit_intrinsics(points), source, points=points, timestamp=_stamp(message)
    )


def _rgbd_frames(
    reader: AnyReader, topics: BagTopics, source: str, depth_scale: float, max_difference: float
) -> Iterator[Frame]:
    wanted = {topics.color, topics.depth, topics.info}
    connections: list[Connection] = [c for c in reader.connections if c.topic in wanted]
    intrinsics: CameraIntrinsics | None = None
    colors: deque[Any] = deque()
    depths: deque[Any] = deque()
    paired: deque[tuple[Any, Any]] = deque()  # pairs waiting for the first camera info
    for connection, _, raw in reader.messages(connections=connections):
        message = reader.deserialize(raw, connection.msgtype)
        if connection.topic == topics.info:
            intrinsics = camera_intrinsics(message)
        else:
            (colors if connection.topic == topics.color else depths).append(message)
        while colors and depths:
            gap = _stamp(colors[0]) - _stamp(depths[0])
            if abs(gap) > max_difference:
                (depths if gap > 0 else colors).popleft()  # the older one has no partner any more
                continue
            paired.append((colors.popleft(), depths.popleft()))
        while paired and intrinsics is not None:
            color, depth = paired.popleft()
            yield assemble_frame(
                decode_color_image(color),
                decode_depth_image(depth, depth_scale),
                intrinsics,
                f"{source}#{topics.color}@{_stamp(color):.6f}",
                timestamp=_stamp(color),
            )
    if paired:
        raise FrameError(f"{source}: no camera info on {topics.info}, so the images have no intrinsics")


def _cloud_frames(reader: AnyReader, topics: BagTopics, source: str) -> Iterator[Frame]:
    connections = [c for c in reader.connections if c.topic == topics.cloud]
    for connection, _, raw in reader.messages(connections=connections):
        message = reader.deserialize(raw, connection.msgtype)
        yield decode_point_cloud(message, f"{source}#{topics.cloud}@{_stamp(message):.6f}")


def bag_frames(
    path: str | Path,
    topics: BagTopics = ANY_TOPICS,
    depth_scale: float = MILLIMETRES,
    max_difference: float = MAX_STAMP_DIFFERENCE,
) -> Iterator[Frame]:
    """The bag's frames in recording order (see the module docstring); the bag is closed when the iterator is."""
    reader = open_bag(path)
    try:
        chosen = pick_topics(reader, topics)
        if chosen.is_cloud:
            yield from _cloud_frames(reader, chosen, str(path))
        else:
            yield from _rgbd_frames(reader, chosen, str(path), depth_scale, max_difference)
    except (AnyReaderError, KeyError, ValueError) as error:
        raise FrameError(f"cannot read the bag {path}: {type(error).__name__}: {error}") from None
    finally:
        reader.close()


def read_bag_frame(
    path: str | Path, frame: int = 0, topics: BagTopics = ANY_TOPICS, depth_scale: float = MILLIMETRES
) -> Frame:
    """Frame number ``frame`` (0-based, recording order) of the bag; FrameError when the bag has fewer."""
    if frame < 0:
        raise FrameError(f"frame number must be >= 0, got {frame}")
    frames = bag_frames(path, topics, depth_scale)
    count = 0
    try:
        for decoded in frames:
            if count == frame:
                return decoded
            count += 1
    finally:
        frames.close()
    raise FrameError(f"{path} holds {count} frame(s), no frame {frame}")


def bag_message_types(path: str | Path) -> frozenset[str]:
    """The message types of the bag's topics (from its index; no message is read); FrameError when unreadable."""
    reader = open_bag(path)
    try:
        return frozenset(c.msgtype for c in reader.connections)
    finally:
        reader.close()
