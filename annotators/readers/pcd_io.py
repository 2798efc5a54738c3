"""Reading a PCD file (x y z with rgb/rgba, an optional ``label`` field) into a Frame.

The header is checked here (``WIDTH * HEIGHT`` points, with x, y, z and a colour field); the data is decoded by
Open3D's tensor reader, which keeps extra fields such as ``label``. The depth image is the z channel.

* An organized cloud (``HEIGHT`` > 1) is the image grid itself. PCD files carry no intrinsics: unless given, they
  are fitted to the grid by least squares (``u = fx * x / z + cx``, ``v = fy * y / z + cy``) and rejected when the
  grid is not a pinhole projection (a residual above ``MAX_FIT_RESIDUAL_PX``).
* An unorganized cloud (``HEIGHT`` 1: filtered, merged or stereo clouds), given in the camera frame (z forward),
  is projected onto a virtual image with intrinsics: those given, else a ``camera_params.json`` beside the file
  (the uoc layout: ``fx``, ``fy``, ``x_offset``, ``y_offset``, ``img_width``, ``img_height``), else
  :data:`DEFAULT_INTRINSICS` (the 640x480 PrimeSense/Kinect model PCL assumes). Each pixel keeps the nearest point
  that projects into it (with its colour and label); pixels no point falls in have none.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import open3d as o3d

from annotators.readers.frame_io import (
    CAMERA_PARAMS_FILE,
    Frame,
    FrameError,
    assemble_frame,
    check_intrinsics,
    read_camera_params,
)
from robokudo.core.types import CameraIntrinsics

MAX_FIT_RESIDUAL_PX = 0.5
"""Largest pixel residual of the fitted pinhole model that still counts as an organized camera grid."""

DEFAULT_INTRINSICS = CameraIntrinsics(fx=525.0, fy=525.0, cx=319.5, cy=239.5, width=640, height=480)
"""The virtual camera of an unorganized cloud without intrinsics: the 640x480 PrimeSense model (PCL's default)."""

_MAX_HEADER_LINES = 64


@dataclass(frozen=True)
class PcdHeader:
    """The parts of a PCD header the reader needs."""

    fields: tuple[str, ...]
    width: int
    height: int
    points: int
    data: str
    point_bytes: int = 0
    data_offset: int = 0


def read_pcd_header(path: Path) -> PcdHeader:
    """Parse and check the header of a PCD file; FrameError with the reason when it is not a readable cloud."""
    if not path.is_file():
        raise FrameError(f"missing {path}")
    values: dict[str, list[str]] = {}
    with path.open("rb") as stream:
        for _ in range(_MAX_HEADER_LINES):
            line = stream.readline()
            if not line:
                break
            text = line.decode("ascii", errors="replace").strip()
            if not text or text.startswith("#"):
                continue
            key, *rest = text.split()
            values[key.upper()] = rest
            if key.upper() == "DATA":
                break
        offset = stream.tell()
    try:
        header = PcdHeader(
            fields=tuple(values["FIELDS"]),
            width=int(values["WIDTH"][0]),
            height=int(values["HEIGHT"][0]),
            points=int(values.get("POINTS", [values["WIDTH"][0]])[0]),
            data=values["DATA"][0].lower(),
            point_bytes=sum(
                int(size) * int(count)
                for size, count in zip(values.get("SIZE", []), values.get("COUNT", ["1"] * 64), strict=False)
            ),
            data_offset=offset,
        )
    except (KeyError, IndexError, ValueError):
        raise FrameError(f"{path} is not a PCD file (header lacks FIELDS, WIDTH, HEIGHT or DATA)") from None
    missing = {"x", "y", "z"} - set(header.fields)
    if missing:
        raise FrameError(f"{path} has no {', '.join(sorted(missing))} field (fields: {' '.join(header.fields)})")
    if not {"rgb", "rgba"} & set(header.fields):
        raise FrameError(f"{path} has no rgb/rgba colour field (fields: {' '.join(header.fields)})")
    if header.height < 1 or header.width < 1 or header.points != header.width * header.height:
        raise FrameError(f"{path} has {header.points} points, not WIDTH {header.width} x HEIGHT {header.height}")
    check_data_length(path, header)
    return header


def check_data_length(path: Path, header: PcdHeader) -> None:
    """FrameError when the data section is shorter than the header promises (a truncated file).

    ASCII data must have a line per point, binary data ``POINTS x`` the point size in bytes; compressed data is
    checked by its decoder.
    """
    if header.data == "ascii":
        with path.open("rb") as stream:
            stream.seek(header.data_offset)
            lines = sum(1 for line in stream if line.strip())
        if lines < header.points:
            raise FrameError(f"{path} is truncated: {lines} of {header.points} points")
    elif header.data == "binary" and header.point_bytes > 0:
        available = path.stat().st_size - header.data_offset
        if available < header.points * header.point_bytes:
            raise FrameError(f"{path} is truncated: {available} of {header.points * header.point_bytes} data bytes")


def fit_intrinsics(points: np.ndarray) -> CameraIntrinsics:
    """Pinhole intrinsics that project the organized HxWx3 cloud's finite points onto their own pixels."""
    height, width = points.shape[:2]
    flat = points.reshape(-1, 3)
    with np.errstate(invalid="ignore"):
        valid = np.flatnonzero(np.isfinite(flat).all(axis=1) & (flat[:, 2] > 0))
    if valid.size < 3:
        raise FrameError("too few finite points to fit intrinsics to the organized cloud")
    sample = valid[:: max(1, valid.size // 20000)]
    xyz = flat[sample].astype(np.float64)
    rows, cols = np.divmod(sample, width)
    fitted = []
    for pixels, ratio in ((cols, xyz[:, 0] / xyz[:, 2]), (rows, xyz[:, 1] / xyz[:, 2])):
        design = np.column_stack([ratio, np.ones_like(ratio)])
        (focal, centre), *_ = np.linalg.lstsq(design, pixels.astype(np.float64), rcond=None)
        residual = np.abs(design @ (focal, centre) - pixels).max()
        if not np.isfinite(residual) or residual > MAX_FIT_RESIDUAL_PX:
            raise FrameError(
                f"the organized cloud is not a pinhole grid (fit residual {residual:.2f} px); give the intrinsics"
            )
        fitted.append((float(focal), float(centre)))
    (fx, cx), (fy, cy) = fitted
    fx, fy, cx, cy = (round(v, 4) for v in (fx, fy, cx, cy))
    return CameraIntrinsics(fx=fx, fy=fy, cx=cx, cy=cy, width=width, height=height)


def read_pcd(path: str | Path, intrinsics: CameraIntrinsics | None = None) -> Frame:
    """Decode a PCD file: colour, depth (z), the organized cloud, labels when present, intrinsics.

    An unorganized cloud is first projected onto a virtual image (see the module docstring).
    """
    path = Path(path)
    header = read_pcd_header(path)
    with o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error):
        cloud = o3d.t.io.read_point_cloud(str(path))
    count = header.width * header.height
    attributes = cloud.point
    if "positions" not in attributes or attributes.positions.shape[0] != count:
        raise FrameError(f"cannot read the {count} points of {path} (truncated or corrupt data)")
    if "colors" not in attributes:
        raise FrameError(f"cannot read the colours of {path}")
    points = attributes.positions.numpy().astype(np.float32, copy=False).reshape(-1, 3)
    colors = attributes.colors.numpy()
    if colors.dtype != np.uint8:
        colors = np.clip(np.rint(colors * (255.0 if colors.max(initial=0) <= 1.0 else 1.0)), 0, 255).astype(np.uint8)
    colors = colors.reshape(-1, 3)
    labels = attributes.label.numpy().reshape(-1) if "label" in attributes else None
    if header.height == 1:
        intrinsics = intrinsics or intrinsics_beside(path) or DEFAULT_INTRINSICS
        check_intrinsics(intrinsics, str(path))
        points, colors, labels = organize(points, colors, labels, intrinsics)
    else:
        shape = (header.height, header.width)
        points = points.reshape(*shape, 3)
        colors = np.ascontiguousarray(colors.reshape(*shape, 3))
        labels = labels.reshape(shape) if labels is not None else None
    z = points[..., 2]
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(points).all(axis=2) & (z > 0)
    if not valid.any():
        raise FrameError(f"{path} has no finite point in front of the camera")
    points[~valid] = np.nan
    depth = np.where(valid, z, np.float32(0.0)).astype(np.float32)
    if intrinsics is None:
        intrinsics = fit_intrinsics(points)
    check_intrinsics(intrinsics, str(path))
    return assemble_frame(colors, depth, intrinsics, str(path), points=points, labels=labels)


def intrinsics_beside(path: Path) -> CameraIntrinsics | None:
    """The intrinsics of a ``camera_params.json`` in the file's folder, or None when there is none."""
    params = path.parent / CAMERA_PARAMS_FILE
    return read_camera_params(params)[0] if params.is_file() else None


def organize(
    points: np.ndarray, colors: np.ndarray, labels: np.ndarray | None, intrinsics: CameraIntrinsics
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """Nx3 camera-frame points (with Nx3 colours and N labels) as an organized HxWx3 cloud of the pinhole camera
    ``intrinsics``: each pixel holds the nearest point projecting into it, NaN (colour 0, label 0) where none does."""
    k = intrinsics
    with np.errstate(invalid="ignore", divide="ignore"):
        z = points[:, 2]
        u = np.rint(k.fx * points[:, 0] / z + k.cx)
        v = np.rint(k.fy * points[:, 1] / z + k.cy)
        inside = np.isfinite(points).all(axis=1) & (z > 0) & (u >= 0) & (u < k.width) & (v >= 0) & (v < k.height)
    index = np.flatnonzero(inside)
    pixel = v[index].astype(np.int64) * k.width + u[index].astype(np.int64)
    order = np.lexsort((z[index], pixel))  # by pixel, nearest first
    first = order[np.flatnonzero(np.diff(pixel[order], prepend=-1) != 0)]
    chosen, at = index[first], pixel[first]
    grid = np.full((k.height * k.width, 3), np.nan, dtype=np.float32)
    grid[at] = points[chosen]
    image = np.zeros((k.height * k.width, 3), dtype=np.uint8)
    image[at] = colors[chosen]
    label_image = None
    if labels is not None:
        label_image = np.zeros(k.height * k.width, dtype=labels.dtype)
        label_image[at] = labels[chosen]
        label_image = label_image.reshape(k.height, k.width)
    return grid.reshape(k.height, k.width, 3), image.reshape(k.height, k.width, 3), label_image
