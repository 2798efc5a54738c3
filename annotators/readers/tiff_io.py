"""The PCL ImageGrabber TIFF layout: ``tiff/frame_<time>_rgb.tiff`` and ``_depth.tiff`` with ``pclzf/frame_<time>.xml``.

The colour TIFF is 8-bit RGB, the depth TIFF 16-bit. Each frame's XML file holds the intrinsics of the ``<rgb>``
and ``<depth>`` cameras (``focal_length_x``, ``focal_length_y``, ``principal_point_x``, ``principal_point_y``) and the
depth unit (``z_multiplication_factor``, metres per unit; its inverse is the depth scale). The XML has two root
elements, so it is parsed wrapped in one. The depth camera's intrinsics are used (the images are registered);
the image size comes from the images. Frame ``n`` is the ``n``-th time stamp, in time order, that has both images.
The path may be the layout's folder or its ``tiff`` folder (the XML then lives in ``../pclzf`` or beside).
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ElementTree
from datetime import UTC, datetime
from pathlib import Path

from annotators.readers.frame_io import (
    Frame,
    FrameError,
    assemble_frame,
    check_depth_scale,
    decode_color,
    decode_depth,
    require_frame_folder,
)
from robokudo.core.types import CameraIntrinsics

_RGB_NAME = re.compile(r"^frame_(?P<stamp>.+)_rgb\.tiff?$", re.IGNORECASE)
_XML_DECLARATION = re.compile(r"^\s*<\?xml[^>]*\?>")


def tiff_folder(path: Path) -> Path:
    """The folder holding the TIFF images: ``path/tiff`` when it exists, else ``path`` itself."""
    return path / "tiff" if (path / "tiff").is_dir() else path


def frame_stamps(folder: Path) -> list[str]:
    """The time stamps (as in the file names) of the frames with both a colour and a depth TIFF, in time order."""
    stamps = []
    for rgb in folder.iterdir():
        match = _RGB_NAME.match(rgb.name)
        if match and rgb.with_name(rgb.name.replace("_rgb", "_depth")).is_file():
            stamps.append(match.group("stamp"))
    return sorted(stamps)


def is_tiff_sequence(path: Path) -> bool:
    """True when ``path`` (or its ``tiff`` sub-folder) holds at least one colour/depth TIFF frame."""
    return path.is_dir() and bool(frame_stamps(tiff_folder(path)))


def xml_path(folder: Path, stamp: str) -> Path:
    """The frame's XML file: in ``../pclzf``, ``pclzf`` or beside the TIFFs."""
    name = f"frame_{stamp}.xml"
    for candidate in (folder.parent / "pclzf" / name, folder / "pclzf" / name, folder / name):
        if candidate.is_file():
            return candidate
    raise FrameError(f"missing intrinsics file {name} (looked in ../pclzf, pclzf and beside the TIFFs)")


def read_grabber_xml(path: Path) -> tuple[tuple[float, float, float, float], float | None]:
    """``(fx, fy, cx, cy)`` of the depth camera and its depth scale (units per metre, None when absent)."""
    text = _XML_DECLARATION.sub("", path.read_text(errors="replace"))
    try:
        root = ElementTree.fromstring(f"<grabber>{text}</grabber>")
    except ElementTree.ParseError as error:
        raise FrameError(f"cannot parse {path}: {error}") from None
    camera = root.find("depth")
    if camera is None:
        camera = root.find("rgb")
    if camera is None:
        raise FrameError(f"{path} has neither a <depth> nor an <rgb> element")
    try:
        values = tuple(
            float(camera.findtext(tag, default="nan"))
            for tag in ("focal_length_x", "focal_length_y", "principal_point_x", "principal_point_y")
        )
        factor_text = camera.findtext("z_multiplication_factor")
        factor = float(factor_text) if factor_text is not None else None
    except ValueError as error:
        raise FrameError(f"bad number in {path}: {error}") from None
    if not all(math.isfinite(v) for v in values):
        raise FrameError(f"{path} lacks the focal lengths or the principal point")
    if factor is not None and (not math.isfinite(factor) or factor <= 0):
        raise FrameError(f"invalid z_multiplication_factor {factor} in {path}")
    return values, (1.0 / factor if factor is not None else None)  # type: ignore[return-value]


def stamp_seconds(stamp: str) -> float | None:
    """Seconds since the epoch (UTC) of a ``20121214T142255.814212`` stamp, None when it has another form."""
    try:
        return datetime.strptime(stamp, "%Y%m%dT%H%M%S.%f").replace(tzinfo=UTC).timestamp()
    except ValueError:
        return None


def read_tiff_frame(
    path: str | Path,
    frame: int = 0,
    depth_scale: float | None = None,
    intrinsics: CameraIntrinsics | None = None,
) -> Frame:
    """Decode frame ``frame`` of a TIFF sequence; explicit ``depth_scale`` / ``intrinsics`` override the XML."""
    path = require_frame_folder(path, frame)
    folder = tiff_folder(path)
    stamps = frame_stamps(folder)
    if frame >= len(stamps):
        raise FrameError(f"{folder} has {len(stamps)} colour/depth TIFF frames, no frame {frame}")
    stamp = stamps[frame]
    file_scale = None
    if intrinsics is None or depth_scale is None:
        (fx, fy, cx, cy), file_scale = read_grabber_xml(xml_path(folder, stamp))
    scale = check_depth_scale(depth_scale if depth_scale is not None else (file_scale or 1000.0))
    color = decode_color(folder / f"frame_{stamp}_rgb.tiff")
    depth = decode_depth(folder / f"frame_{stamp}_depth.tiff", scale)
    if intrinsics is None:
        height, width = depth.shape
        intrinsics = CameraIntrinsics(fx=fx, fy=fy, cx=cx, cy=cy, width=width, height=height)
    source = str(folder / f"frame_{stamp}_rgb.tiff")
    return assemble_frame(color, depth, intrinsics, source, timestamp=stamp_seconds(stamp))
