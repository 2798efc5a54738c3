"""Reading one RGB-D frame from files: the shared decoding and checks, and the uoc colour/depth pair layout.

Every file layout (see also :mod:`annotators.readers.tum_io`, :mod:`annotators.readers.pcd_io`,
:mod:`annotators.readers.tiff_io`) ends in :func:`decode_rgbd` or :func:`assemble_frame`, which check what all
frames must satisfy: the colour and depth images have the same size, the intrinsics are valid and made for that
size, the depth scale is a positive finite number.

The uoc layout is ``NNNNNN-color.png`` (8-bit RGB), ``NNNNNN-depth.png`` (16-bit depth in sensor units) and
``camera_params.json`` with ``fx``, ``fy``, ``x_offset`` (cx), ``y_offset`` (cy), ``img_width``, ``img_height``
and optionally ``depth_scale``. Problems raise :class:`FrameError` with a reason.

A PNG file's chunk structure and checksums are checked (:func:`png_problem`) before OpenCV decodes it: libpng
reports a broken file by printing to the process's stderr, so a truncated or damaged PNG is refused here, with
the reason in the FrameError, and never reaches the decoder.
"""

from __future__ import annotations

import json
import math
import re
import time
import zlib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TypeVar

import cv2
import numpy as np

from robokudo.core.types import CameraInfo, CameraIntrinsics

DEFAULT_DEPTH_SCALE = 1000.0
"""Sensor units per metre when camera_params.json does not say (millimetres)."""

CAMERA_PARAMS_FILE = "camera_params.json"

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tif", ".tiff")
"""File suffixes (lower case) of the colour and depth images the readers decode."""


def natural_order_key(path: Path) -> list[object]:
    """Sort key of a file name in natural order: ``frame2`` before ``frame10``."""
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", path.name)]


class FrameError(Exception):
    """A frame could not be read or is inconsistent; the message says why."""


@dataclass(frozen=True, eq=False)
class Frame:
    """One decoded RGB-D frame: RGB uint8 HxWx3, depth float32 metres HxW (0 = no data), intrinsics.

    ``points`` is the organized HxWx3 float32 cloud when the file holds one (NaN where invalid), ``labels`` HxW
    ground-truth labels when the file has them, ``timestamp`` the recording time in seconds when known,
    ``cam_to_world`` the 4x4 camera pose in the recording's world when the recording gives one.
    """

    color: np.ndarray
    depth: np.ndarray
    intrinsics: CameraIntrinsics
    source: str = ""
    points: np.ndarray | None = None
    labels: np.ndarray | None = None
    timestamp: float | None = None
    cam_to_world: np.ndarray | None = None


def frame_camera(frame: Frame, recording: str) -> CameraInfo:
    """The camera info of a recorded frame: its intrinsics and camera pose, frame id ``camera``, its recording time
    (now when the file has none) and ``recording``."""
    stamp = frame.timestamp if frame.timestamp is not None else time.time()
    return CameraInfo(
        intrinsics=frame.intrinsics,
        cam_to_world=frame.cam_to_world,
        frame_id="camera",
        timestamp=stamp,
        recording=recording,
    )


def check_intrinsics(intrinsics: CameraIntrinsics, where: str) -> CameraIntrinsics:
    """``intrinsics`` when the focal lengths are positive and every value finite; else FrameError naming ``where``."""
    values = (intrinsics.fx, intrinsics.fy, intrinsics.cx, intrinsics.cy)
    if not intrinsics.is_valid() or not all(math.isfinite(v) for v in values):
        raise FrameError(f"invalid intrinsics in {where}: {intrinsics}")
    return intrinsics


def check_depth_scale(scale: float) -> float:
    """``scale`` (sensor units per metre) when it is positive and finite; else FrameError."""
    try:
        value = float(scale)
    except (TypeError, ValueError):
        raise FrameError(f"depth scale must be a number, got {scale!r}") from None
    if not math.isfinite(value) or value <= 0:
        raise FrameError(f"depth scale must be positive, got {scale}")
    return value


FrameItem = TypeVar("FrameItem")
"""What a recording lists per frame (a colour/depth pair of paths or of timed images)."""


def require_frame_folder(folder: str | Path, frame: int) -> Path:
    """``folder`` as a Path when it is a folder and ``frame`` a frame number (>= 0); else FrameError."""
    folder = Path(folder)
    if not folder.is_dir():
        raise FrameError(f"no such folder {folder}")
    if frame < 0:
        raise FrameError(f"frame number must be >= 0, got {frame}")
    return folder


def frame_of(frames: Sequence[FrameItem], frame: int, folder: Path, what: str) -> FrameItem:
    """Item ``frame`` of a recording's ``frames`` (its ``what``, e.g. "colour/depth frames"); FrameError naming the
    folder and how many it has when there is no such frame."""
    if not 0 <= frame < len(frames):
        raise FrameError(f"{folder} has {len(frames)} {what}, no frame {frame}")
    return frames[frame]


def require_file(path: Path) -> Path:
    """``path`` when it is a file; else FrameError."""
    if not path.is_file():
        raise FrameError(f"missing {path}")
    return path


def png_problem(data: bytes) -> str | None:
    """Why ``data`` (a file starting with the PNG signature) is not a complete, intact PNG; None when it is.

    Checks the chunk layout (IHDR first, image data present, IEND last, no chunk past the end of the file) and
    every chunk's CRC; the compressed image data itself is left to the decoder.
    """
    view = memoryview(data)
    position = len(PNG_SIGNATURE)
    kinds: list[bytes] = []
    while position < len(data):
        if position + 12 > len(data):
            return f"truncated: the file ends inside a chunk header at byte {position}"
        length = int.from_bytes(view[position : position + 4], "big")
        kind = bytes(view[position + 4 : position + 8])
        name = kind.decode("latin-1")
        if not kind.isalpha():
            return f"damaged: no valid chunk at byte {position}"
        if not kinds and kind != b"IHDR":
            return "damaged: the first chunk is not IHDR"
        end = position + 12 + length
        if end > len(data):
            return f"truncated: chunk {name} at byte {position} needs {length} bytes, the file ends first"
        stored = int.from_bytes(view[end - 4 : end], "big")
        if zlib.crc32(view[position + 4 : end - 4]) != stored:
            return f"damaged: checksum mismatch in chunk {name} at byte {position}"
        kinds.append(kind)
        position = end
        if kind == b"IEND":
            break
    if not kinds:
        return "truncated: the file ends after its signature"
    if b"IDAT" not in kinds:
        return "no image data (IDAT chunk)"
    if kinds[-1] != b"IEND":
        return "truncated: the file ends before its IEND chunk"
    return None


def _decode_image(path: Path, flags: int) -> np.ndarray:
    """The image of ``path`` decoded by OpenCV with ``flags``; FrameError with the reason when it cannot be."""
    data = require_file(path).read_bytes()
    if data.startswith(PNG_SIGNATURE):
        problem = png_problem(data)
        if problem is not None:
            raise FrameError(f"cannot decode {path}: {problem}")
    image = cv2.imdecode(np.frombuffer(data, dtype=np.uint8), flags)
    if image is None or image.size == 0:
        raise FrameError(f"cannot decode {path}: not an image OpenCV can read")
    return image


def decode_color(path: Path) -> np.ndarray:
    """An RGB uint8 image from an 8-bit colour file (PNG, JPEG, TIFF); FrameError when it cannot be decoded."""
    return cv2.cvtColor(_decode_image(path, cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB)


def decode_depth(path: Path, depth_scale: float) -> np.ndarray:
    """Depth in metres (float32, 0 = no data) from a one-channel 16-bit file in units of 1/``depth_scale`` m."""
    scale = check_depth_scale(depth_scale)
    raw = _decode_image(path, cv2.IMREAD_UNCHANGED)
    if raw.ndim != 2:
        raise FrameError(f"depth image {path} has {raw.shape[2]} channels, expected one")
    if raw.dtype != np.uint16:
        raise FrameError(f"depth image {path} is {raw.dtype}, expected 16-bit")
    depth = raw.astype(np.float32)
    depth *= np.float32(1.0 / scale)
    return depth


def assemble_frame(
    color: np.ndarray,
    depth: np.ndarray,
    intrinsics: CameraIntrinsics,
    source: str,
    points: np.ndarray | None = None,
    labels: np.ndarray | None = None,
    timestamp: float | None = None,
) -> Frame:
    """A checked Frame: same image sizes, valid intrinsics made for that size (FrameError otherwise)."""
    check_intrinsics(intrinsics, source)
    if depth.shape != color.shape[:2]:
        raise FrameError(
            f"colour {color.shape[1]}x{color.shape[0]} and depth {depth.shape[1]}x{depth.shape[0]} sizes differ"
        )
    if depth.shape != (intrinsics.height, intrinsics.width):
        k = intrinsics
        raise FrameError(f"images are {depth.shape[1]}x{depth.shape[0]} but the intrinsics say {k.width}x{k.height}")
    return Frame(color, depth, intrinsics, source, points, labels, timestamp)


def decode_rgbd(
    color_path: Path,
    depth_path: Path,
    intrinsics: CameraIntrinsics,
    depth_scale: float,
    timestamp: float | None = None,
) -> Frame:
    """Decode and check a registered colour/depth file pair (depth in units of 1/``depth_scale`` m)."""
    check_intrinsics(intrinsics, str(color_path))
    check_depth_scale(depth_scale)
    for path in (color_path, depth_path):
        require_file(path)
    color = decode_color(color_path)
    depth = decode_depth(depth_path, depth_scale)
    return assemble_frame(color, depth, intrinsics, str(color_path), timestamp=timestamp)


# ------------------------------------------------------------------------------------------ uoc layout


def frame_paths(folder: str | Path, frame: int) -> tuple[Path, Path]:
    """The colour and depth file paths of frame number ``frame`` in ``folder``."""
    base = Path(folder)
    return base / f"{frame:06d}-color.png", base / f"{frame:06d}-depth.png"


def read_camera_params(path: str | Path) -> tuple[CameraIntrinsics, float | None]:
    """Intrinsics and the depth scale (units per metre, None when absent) from a camera_params.json.

    A ``depth_scale`` below 1 is read as metres per unit (the RealSense convention) and inverted.
    """
    path = Path(path)
    if not path.is_file():
        raise FrameError(f"missing camera parameters {path}")
    try:
        params = json.loads(path.read_text())
        intrinsics = CameraIntrinsics(
            fx=float(params["fx"]),
            fy=float(params["fy"]),
            cx=float(params["x_offset"]),
            cy=float(params["y_offset"]),
            width=int(params["img_width"]),
            height=int(params["img_height"]),
        )
    except (ValueError, KeyError, TypeError) as error:
        raise FrameError(f"bad camera parameters in {path}: {type(error).__name__} {error}") from None
    check_intrinsics(intrinsics, str(path))
    scale = params.get("depth_scale")
    if scale is None:
        return intrinsics, None
    scale = float(scale)
    if not math.isfinite(scale) or scale <= 0:
        raise FrameError(f"invalid depth_scale {scale} in {path}")
    return intrinsics, (1.0 / scale if scale < 1.0 else scale)


def read_color_depth_pair(folder: str | Path, frame: int = 0, depth_scale: float | None = None) -> Frame:
    """Decode frame ``frame`` of a uoc-layout folder; ``depth_scale`` (units per metre) overrides the file's."""
    folder = require_frame_folder(folder, frame)
    color_path, depth_path = frame_paths(folder, frame)
    for path in (color_path, depth_path):
        require_file(path)
    intrinsics, file_scale = read_camera_params(folder / CAMERA_PARAMS_FILE)
    scale = depth_scale if depth_scale is not None else (file_scale or DEFAULT_DEPTH_SCALE)
    return decode_rgbd(color_path, depth_path, intrinsics, scale)
