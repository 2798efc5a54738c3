"""Reading one RGB-D frame from files: a colour/depth PNG pair with a camera_params.json (the uoc layout).

The layout is ``NNNNNN-color.png`` (8-bit RGB), ``NNNNNN-depth.png`` (16-bit depth in sensor units) and
``camera_params.json`` with ``fx``, ``fy``, ``x_offset`` (cx), ``y_offset`` (cy), ``img_width``, ``img_height``
and optionally ``depth_scale``. Everything is checked; problems raise :class:`FrameError` with a reason.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from robokudo.types import CameraIntrinsics

DEFAULT_DEPTH_SCALE = 1000.0
"""Sensor units per metre when camera_params.json does not say (millimetres)."""

CAMERA_PARAMS_FILE = "camera_params.json"


class FrameError(Exception):
    """A frame could not be read or is inconsistent; the message says why."""


@dataclass(frozen=True, eq=False)
class Frame:
    """One decoded RGB-D frame: RGB uint8 HxWx3, depth float32 metres HxW (0 = no data), intrinsics."""

    color: np.ndarray
    depth: np.ndarray
    intrinsics: CameraIntrinsics
    source: str = ""


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
    values = (intrinsics.fx, intrinsics.fy, intrinsics.cx, intrinsics.cy)
    if not intrinsics.is_valid() or not all(math.isfinite(v) for v in values):
        raise FrameError(f"invalid intrinsics in {path}: {intrinsics}")
    scale = params.get("depth_scale")
    if scale is None:
        return intrinsics, None
    scale = float(scale)
    if not math.isfinite(scale) or scale <= 0:
        raise FrameError(f"invalid depth_scale {scale} in {path}")
    return intrinsics, (1.0 / scale if scale < 1.0 else scale)


def read_color_depth_pair(folder: str | Path, frame: int = 0, depth_scale: float | None = None) -> Frame:
    """Decode frame ``frame`` of a uoc-layout folder; ``depth_scale`` (units per metre) overrides the file's."""
    folder = Path(folder)
    if not folder.is_dir():
        raise FrameError(f"no such folder {folder}")
    if frame < 0:
        raise FrameError(f"frame number must be >= 0, got {frame}")
    color_path, depth_path = frame_paths(folder, frame)
    for path in (color_path, depth_path):
        if not path.is_file():
            raise FrameError(f"missing {path}")
    intrinsics, file_scale = read_camera_params(folder / CAMERA_PARAMS_FILE)
    scale = depth_scale if depth_scale is not None else (file_scale or DEFAULT_DEPTH_SCALE)
    if not math.isfinite(scale) or scale <= 0:
        raise FrameError(f"depth scale must be positive, got {scale}")

    bgr = cv2.imread(str(color_path), cv2.IMREAD_COLOR)
    if bgr is None:
        raise FrameError(f"cannot decode {color_path}")
    raw = cv2.imread(str(depth_path), cv2.IMREAD_UNCHANGED)
    if raw is None:
        raise FrameError(f"cannot decode {depth_path}")
    if raw.ndim != 2:
        raise FrameError(f"depth image {depth_path} has {raw.shape[2]} channels, expected one")
    if raw.shape != bgr.shape[:2]:
        raise FrameError(f"colour {bgr.shape[1]}x{bgr.shape[0]} and depth {raw.shape[1]}x{raw.shape[0]} sizes differ")
    if raw.shape != (intrinsics.height, intrinsics.width):
        raise FrameError(
            f"images are {raw.shape[1]}x{raw.shape[0]} but the intrinsics say {intrinsics.width}x{intrinsics.height}"
        )
    depth = raw.astype(np.float32)
    depth *= np.float32(1.0 / scale)
    color = cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)
    return Frame(color=color, depth=depth, intrinsics=intrinsics, source=str(color_path))
