"""The Open3D RGB-D folder layout: ``color/`` (or ``image/``) and ``depth/`` image folders, a camera JSON, poses.

Open3D's RealSense recorder and its reconstruction system write a recording as a folder holding ``color/`` (the
reconstruction system: ``image/``) and ``depth/``, one image per frame, and a camera intrinsic JSON beside them;
Open3D's sample RGB-D data (the "Redwood" frames) has the same shape. Frame ``n`` is the ``n``-th pair: the pairs
listed in ``rgbd.match`` (``depth/X.png color/Y.jpg`` per line) when the folder has one, else the two folders'
images in natural order, which must then be as many.

Depth images hold 16-bit millimetres (Open3D's default depth scale, 1000 units per metre). The intrinsics are those
of the folder's Open3D camera JSON (``width``, ``height`` and a column-major ``intrinsic_matrix``):
``camera_intrinsic.json`` first, else any ``*.json`` in the folder holding an ``intrinsic_matrix``; without one,
the PrimeSense default. A ``trajectory.log`` (Open3D's log format: per frame a line of three integers, then the
4x4 camera-to-world pose, row by row) gives every frame its camera pose in the world.
"""

from __future__ import annotations

import functools
import json
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from annotators.readers.frame_io import (
    IMAGE_SUFFIXES,
    Frame,
    FrameError,
    decode_rgbd,
    frame_of,
    natural_order_key,
    require_frame_folder,
)
from annotators.readers.tum_io import PRIMESENSE_INTRINSICS
from robokudo.core.types import CameraIntrinsics

OPEN3D_DEPTH_SCALE = 1000.0
"""Sensor units per metre of Open3D's depth images (its ``depth_scale`` default)."""

COLOR_FOLDERS = ("color", "image")
"""Names of the colour image folder: the RealSense recorder's, the reconstruction system's."""

MATCH_FILE = "rgbd.match"
TRAJECTORY_FILE = "trajectory.log"
INTRINSIC_FILE = "camera_intrinsic.json"


def _images(folder: Path) -> list[Path]:
    return sorted((p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES), key=natural_order_key)


def color_folder(folder: Path) -> Path | None:
    """The colour image folder of an Open3D RGB-D folder, None when ``folder`` is not one (see the module)."""
    if not (folder / "depth").is_dir():
        return None
    for name in COLOR_FOLDERS:
        candidate = folder / name
        if candidate.is_dir() and _images(candidate):
            return candidate
    return None


def is_open3d_folder(folder: Path) -> bool:
    """Does ``folder`` hold ``depth/`` and ``color/`` (or ``image/``) with images?"""
    return folder.is_dir() and color_folder(folder) is not None


def frame_pairs(folder: Path) -> list[tuple[Path, Path]]:
    """The (colour, depth) files of every frame, in order; FrameError when they cannot be paired."""
    colors = color_folder(folder)
    if colors is None:
        raise FrameError(f"{folder} has no depth/ and color/ (or image/) folders of images")
    match = folder / MATCH_FILE
    if match.is_file():
        return _matched_pairs(folder, match)
    color_files, depth_files = _images(colors), _images(folder / "depth")
    if len(color_files) != len(depth_files):
        raise FrameError(
            f"{folder} has {len(color_files)} colour images in {colors.name}/ but {len(depth_files)} depth images "
            f"in depth/ (and no {MATCH_FILE} to pair them)"
        )
    return list(zip(color_files, depth_files, strict=True))


def _matched_pairs(folder: Path, match: Path) -> list[tuple[Path, Path]]:
    pairs = []
    for number, line in enumerate(match.read_text().splitlines(), start=1):
        fields = line.split()
        if not fields or fields[0].startswith("#"):
            continue
        if len(fields) != 2:
            raise FrameError(f"{match}, line {number}: expected 'depth-file colour-file', got {line.strip()!r}")
        depth, color = folder / fields[0], folder / fields[1]
        pairs.append((color, depth))
    return pairs


def open3d_intrinsics(folder: Path, given: CameraIntrinsics | None = None) -> tuple[CameraIntrinsics, str]:
    """``given``, else the intrinsics of the folder's Open3D camera JSON, else the PrimeSense default; with where
    they come from."""
    if given is not None:
        return given, "given"
    named = folder / INTRINSIC_FILE
    candidates = [named] if named.is_file() else []
    candidates += sorted(p for p in folder.glob("*.json") if p != named)
    for path in candidates:
        try:
            document = json.loads(path.read_text())
        except (OSError, json.JSONDecodeError) as error:
            if path == named:
                raise FrameError(f"cannot read the camera intrinsics {path}: {error}") from None
            continue
        if isinstance(document, dict) and "intrinsic_matrix" in document:
            return _intrinsics_of(document, path), str(path)
    return PRIMESENSE_INTRINSICS, f"the PrimeSense default: no camera JSON with an intrinsic_matrix in {folder}"


def _intrinsics_of(document: dict, path: Path) -> CameraIntrinsics:
    """Intrinsics from an Open3D PinholeCameraIntrinsic JSON (``intrinsic_matrix`` column-major)."""
    matrix = document.get("intrinsic_matrix")
    try:
        values = [float(v) for v in matrix]
        width, height = int(document["width"]), int(document["height"])
    except (KeyError, TypeError, ValueError):
        raise FrameError(f"{path}: expected width, height and a 9-number intrinsic_matrix") from None
    if len(values) != 9:
        raise FrameError(f"{path}: intrinsic_matrix has {len(values)} numbers, expected 9")
    return CameraIntrinsics(fx=values[0], fy=values[4], cx=values[6], cy=values[7], width=width, height=height)


def read_trajectory(path: Path) -> list[np.ndarray]:
    """The 4x4 camera-to-world poses of an Open3D ``trajectory.log``, in order; FrameError naming the line."""
    lines = [(number, line.split()) for number, line in enumerate(path.read_text().splitlines(), start=1)]
    lines = [(number, fields) for number, fields in lines if fields]
    if len(lines) % 5:
        raise FrameError(f"{path}: {len(lines)} lines, expected 5 per pose (three integers, then 4 rows of 4)")
    poses = []
    for start in range(0, len(lines), 5):
        rows = []
        for number, fields in lines[start + 1 : start + 5]:
            try:
                row = [float(v) for v in fields]
            except ValueError:
                row = []
            if len(row) != 4:
                raise FrameError(f"{path}, line {number}: expected 4 numbers of a pose row, got {' '.join(fields)!r}")
            rows.append(row)
        pose = np.array(rows)
        if not np.all(np.isfinite(pose)) or not np.allclose(pose[3], (0.0, 0.0, 0.0, 1.0)):
            raise FrameError(f"{path}, line {lines[start + 4][0]}: a pose's last row must be 0 0 0 1")
        poses.append(pose)
    return poses


@dataclass(frozen=True, eq=False)
class Open3dRecording:
    """An Open3D RGB-D folder's lists, read once: its colour/depth image pairs in order and, with a
    ``trajectory.log``, each frame's camera-to-world pose. A reader of every frame (a playback stream) shares one;
    reading a frame decodes that frame's two images only."""

    folder: Path
    pairs: tuple[tuple[Path, Path], ...]
    poses: tuple[np.ndarray, ...] | None

    @classmethod
    def open(cls, folder: str | Path) -> Open3dRecording:
        """Pair the folder's images and read its trajectory (when there is one); FrameError when the folders or the
        trajectory do not agree (the counts, a line of the trajectory by number)."""
        folder = Path(folder)
        pairs = tuple(frame_pairs(folder))
        trajectory = folder / TRAJECTORY_FILE
        if not trajectory.is_file():
            return cls(folder, pairs, None)
        poses = read_trajectory(trajectory)
        if len(poses) != len(pairs):
            raise FrameError(f"{trajectory} holds {len(poses)} poses for {len(pairs)} frames")
        return cls(folder, pairs, tuple(poses))

    @functools.cached_property
    def folder_intrinsics(self) -> tuple[CameraIntrinsics, str]:
        """Those of the folder's camera JSON, else the PrimeSense default, with where they come from (read on the
        first frame)."""
        return open3d_intrinsics(self.folder)

    def read(
        self, frame: int = 0, depth_scale: float = OPEN3D_DEPTH_SCALE, intrinsics: CameraIntrinsics | None = None
    ) -> Frame:
        """Decode frame ``frame``, with its camera pose when the folder has a trajectory."""
        color, depth = frame_of(self.pairs, frame, self.folder, "colour/depth frames")
        camera, where = (intrinsics, "given") if intrinsics is not None else self.folder_intrinsics
        try:
            decoded = decode_rgbd(color, depth, camera, depth_scale)
        except FrameError as error:
            if "the intrinsics say" in str(error):
                raise FrameError(f"{error} (intrinsics: {where})") from None
            raise
        return replace(decoded, cam_to_world=self.poses[frame] if self.poses is not None else None)


def read_open3d_frame(
    folder: str | Path,
    frame: int = 0,
    depth_scale: float = OPEN3D_DEPTH_SCALE,
    intrinsics: CameraIntrinsics | None = None,
) -> Frame:
    """Decode frame ``frame`` of an Open3D RGB-D folder, with its camera pose when the folder has a trajectory."""
    return Open3dRecording.open(require_frame_folder(folder, frame)).read(frame, depth_scale, intrinsics)
