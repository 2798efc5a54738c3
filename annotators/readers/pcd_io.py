"""Reading an organized PCD file (x y z with rgb/rgba, an optional ``label`` field) into a Frame.

The header is checked here (an organized cloud has ``HEIGHT`` > 1 and ``WIDTH * HEIGHT`` points, with x, y, z
and a colour field); the data is decoded by Open3D's tensor reader, which keeps extra fields such as ``label``.
The depth image is the z channel. PCD files carry no intrinsics: unless given, they are fitted to the organized
grid by least squares (``u = fx * x / z + cx``, ``v = fy * y / z + cy``) and rejected when the grid is not a
pinhole projection (a residual above ``MAX_FIT_RESIDUAL_PX``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import open3d as o3d

from annotators.readers.frame_io import Frame, FrameError, assemble_frame, check_intrinsics
from robokudo.core.types import CameraIntrinsics

MAX_FIT_RESIDUAL_PX = 0.5
"""Largest pixel residual of the fitted pinhole model that still counts as an organized camera grid."""

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
    """Parse and check the header of a PCD file; FrameError with the reason when it is not an organized cloud."""
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
    if header.height <= 1 or header.width <= 1 or header.points != header.width * header.height:
        raise FrameError(f"{path} is not an organized cloud (WIDTH {header.width}, HEIGHT {header.height})")
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
    """Decode an organized PCD file: colour, depth (z), the cloud itself, labels when present, intrinsics."""
    path = Path(path)
    header = read_pcd_header(path)
    with o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error):
        cloud = o3d.t.io.read_point_cloud(str(path))
    count = header.width * header.height
    attributes = cloud.point
    if "positions" not in attributes or attributes.positions.shape[0] != count:
        raise FrameError(f"cannot read the {count} points of {path} (truncated or corrupt data)")
    shape = (header.height, header.width)
    points = attributes.positions.numpy().astype(np.float32, copy=False).reshape(*shape, 3)
    if "colors" not in attributes:
        raise FrameError(f"cannot read the colours of {path}")
    colors = attributes.colors.numpy()
    if colors.dtype != np.uint8:
        colors = np.clip(np.rint(colors * (255.0 if colors.max(initial=0) <= 1.0 else 1.0)), 0, 255).astype(np.uint8)
    colors = np.ascontiguousarray(colors.reshape(*shape, 3))
    labels = attributes.label.numpy().reshape(shape) if "label" in attributes else None
    z = points[..., 2]
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(points).all(axis=2) & (z > 0)
    if not valid.any():
        raise FrameError(f"{path} has no finite point")
    points[~valid] = np.nan
    depth = np.where(valid, z, np.float32(0.0)).astype(np.float32)
    if intrinsics is None:
        intrinsics = fit_intrinsics(points)
    check_intrinsics(intrinsics, str(path))
    return assemble_frame(colors, depth, intrinsics, str(path), points=points, labels=labels)
