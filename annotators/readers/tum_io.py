"""The TUM RGB-D layouts: a sequence folder (``rgb.txt`` / ``depth.txt``) and a single colour/depth pair.

A sequence folder lists its images in ``rgb.txt`` and ``depth.txt``, one ``timestamp path`` per line (``#`` starts
a comment, paths are relative to the folder). Frame ``n`` is the ``n``-th colour image, in time order, that has a
depth image within ``max_time_difference`` seconds (the nearest one; each depth image is used once).

Depth PNGs hold 16-bit values of 1/5000 m (``TUM_DEPTH_SCALE``). TUM ships no intrinsics with the images; the
default is the PrimeSense default TUM documents for its registered images (fx = fy = 525, cx = 319.5, cy = 239.5,
640x480). A ``camera_params.json`` (uoc format) in the sequence folder overrides it; an explicit argument wins.
A ``groundtruth.txt`` in the folder (``timestamp tx ty tz qx qy qz qw`` per line: the colour camera's optical centre
in the motion-capture world) gives a frame the pose nearest its colour image's time, when one lies within
``max_time_difference``; a frame without one has no camera pose.

A single pair is a colour file whose name contains ``color`` or ``rgb`` with the depth file beside it, named the
same with the last ``color``/``rgb`` replaced by ``depth`` (``TUM_color.png`` -> ``TUM_depth.png``); the depth
file may be given instead of the colour file. A folder holding such pairs (and no other layout) is read pair by
pair: :func:`pair_color_files` lists their colour files.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from annotators.readers.frame_io import (
    CAMERA_PARAMS_FILE,
    Frame,
    FrameError,
    decode_rgbd,
    frame_of,
    read_camera_params,
)
from robokudo.core.geometry import rotation_matrices
from robokudo.core.types import CameraIntrinsics

TUM_DEPTH_SCALE = 5000.0
"""Sensor units per metre of TUM depth images."""

PRIMESENSE_INTRINSICS = CameraIntrinsics(fx=525.0, fy=525.0, cx=319.5, cy=239.5, width=640, height=480)
"""The PrimeSense default intrinsics TUM documents for its registered 640x480 images."""

MAX_TIME_DIFFERENCE = 0.02
"""Largest time gap (seconds) between a colour image and the depth image (or ground-truth pose) associated with it."""

GROUND_TRUTH_FILE = "groundtruth.txt"

_COLOR_WORD = re.compile(r"(color|colour|rgb)", re.IGNORECASE)
_DEPTH_WORD = re.compile(r"depth", re.IGNORECASE)


@dataclass(frozen=True)
class TimedImage:
    """One line of rgb.txt or depth.txt: a timestamp (seconds) and the image path."""

    timestamp: float
    path: Path


def read_image_list(path: Path) -> list[TimedImage]:
    """The entries of an rgb.txt / depth.txt file, in time order; FrameError on a malformed line."""
    if not path.is_file():
        raise FrameError(f"missing {path}")
    entries = []
    for number, line in enumerate(path.read_text(errors="replace").splitlines(), start=1):
        text = line.strip()
        if not text or text.startswith("#"):
            continue
        fields = text.split()
        try:
            timestamp = float(fields[0])
            entries.append(TimedImage(timestamp, path.parent / fields[1]))
        except (ValueError, IndexError):
            raise FrameError(f"{path}:{number}: expected 'timestamp path', got {text!r}") from None
    return sorted(entries, key=lambda entry: entry.timestamp)


def associate(
    colors: list[TimedImage], depths: list[TimedImage], max_difference: float = MAX_TIME_DIFFERENCE
) -> list[tuple[TimedImage, TimedImage]]:
    """Colour/depth pairs: each colour image with a near unused depth image within ``max_difference`` s.

    Each colour image considers the depth images just before and after it in time; the closest pairs are
    taken first, so the association does not depend on the order of the lists.
    """
    depth_times = np.array([d.timestamp for d in depths], dtype=np.float64)
    candidates = []
    for i, color in enumerate(colors):
        after = int(np.searchsorted(depth_times, color.timestamp))
        for j in (after - 1, after):
            if 0 <= j < len(depths) and abs(depth_times[j] - color.timestamp) <= max_difference:
                candidates.append((abs(depth_times[j] - color.timestamp), i, j))
    used_colors: set[int] = set()
    used_depths: set[int] = set()
    pairs = []
    for _, i, j in sorted(candidates):
        if i in used_colors or j in used_depths:
            continue
        used_colors.add(i)
        used_depths.add(j)
        pairs.append((colors[i], depths[j]))
    return sorted(pairs, key=lambda pair: pair[0].timestamp)


def is_tum_sequence(folder: Path) -> bool:
    """True when ``folder`` holds rgb.txt and depth.txt."""
    return (folder / "rgb.txt").is_file() and (folder / "depth.txt").is_file()


def sequence_intrinsics(folder: Path, intrinsics: CameraIntrinsics | None) -> CameraIntrinsics:
    """The explicit intrinsics, else those of the folder's camera_params.json, else the PrimeSense default."""
    if intrinsics is not None:
        return intrinsics
    if (folder / CAMERA_PARAMS_FILE).is_file():
        return read_camera_params(folder / CAMERA_PARAMS_FILE)[0]
    return PRIMESENSE_INTRINSICS


def read_ground_truth(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The times (N) and 4x4 camera-to-world poses (Nx4x4) of a TUM ``groundtruth.txt``, in time order; FrameError
    naming the line of a malformed entry."""
    numbers, rows = [], []
    for number, line in enumerate(path.read_text(errors="replace").splitlines(), start=1):
        fields = line.split()
        if fields and not fields[0].startswith("#"):
            numbers.append(number)
            rows.append(fields)
    try:
        values = np.array(rows, dtype=np.float64).reshape(len(rows), 8)
        bad = ~np.isfinite(values).all(axis=1)
    except ValueError:  # a line of another length or a word: find it
        bad = np.array([len(r) != 8 or not all(_is_number(v) for v in r) for r in rows])
        values = np.zeros((len(rows), 8))
    if bad.any():
        first = int(np.argmax(bad))
        text = " ".join(rows[first])
        raise FrameError(f"{path}:{numbers[first]}: expected 'timestamp tx ty tz qx qy qz qw', got {text!r}")
    norms = np.linalg.norm(values[:, 4:], axis=1)
    if (norms < 1e-6).any():
        raise FrameError(f"{path}:{numbers[int(np.argmax(norms < 1e-6))]}: the orientation quaternion is zero")
    poses = np.tile(np.eye(4), (len(rows), 1, 1))
    poses[:, :3, :3] = rotation_matrices(values[:, 4:] / norms[:, None])
    poses[:, :3, 3] = values[:, 1:4]
    order = np.argsort(values[:, 0], kind="stable")
    return values[order, 0], poses[order]


def _is_number(text: str) -> bool:
    try:
        return np.isfinite(float(text))
    except ValueError:
        return False


def pose_at(
    times: np.ndarray, poses: np.ndarray, timestamp: float, max_difference: float = MAX_TIME_DIFFERENCE
) -> np.ndarray | None:
    """The pose nearest ``timestamp`` among ``times`` (sorted), None when none lies within ``max_difference``."""
    after = int(np.searchsorted(times, timestamp))
    near = [j for j in (after - 1, after) if 0 <= j < times.size]
    if not near:
        return None
    best = min(near, key=lambda j: abs(times[j] - timestamp))
    return poses[best] if abs(times[best] - timestamp) <= max_difference else None


@dataclass(frozen=True, eq=False)
class TumSequence:
    """A TUM sequence folder's lists, read once: its colour/depth pairs in time order and, with a
    ``groundtruth.txt``, the times and camera-to-world poses of its ground truth. A reader of every frame (a playback
    stream) shares one; reading a frame decodes that frame's two images only."""

    folder: Path
    pairs: tuple[tuple[TimedImage, TimedImage], ...]
    ground_truth: tuple[np.ndarray, np.ndarray] | None

    @classmethod
    def open(cls, folder: str | Path) -> TumSequence:
        """Read the folder's ``rgb.txt``, ``depth.txt`` and ``groundtruth.txt`` (when there is one); FrameError
        names a line that is not ``timestamp path`` or a ground-truth pose."""
        folder = Path(folder)
        pairs = tuple(associate(read_image_list(folder / "rgb.txt"), read_image_list(folder / "depth.txt")))
        truth = folder / GROUND_TRUTH_FILE
        return cls(folder, pairs, read_ground_truth(truth) if truth.is_file() else None)

    @functools.cached_property
    def folder_intrinsics(self) -> CameraIntrinsics:
        """Those of the folder's camera_params.json, else the PrimeSense default (read on the first frame)."""
        return sequence_intrinsics(self.folder, None)

    def read(
        self, frame: int = 0, depth_scale: float = TUM_DEPTH_SCALE, intrinsics: CameraIntrinsics | None = None
    ) -> Frame:
        """Decode frame ``frame`` (0-based, in time order), with its pose when the ground truth has one near it."""
        color, depth = frame_of(self.pairs, frame, self.folder, "associated colour/depth frames")
        camera = intrinsics if intrinsics is not None else self.folder_intrinsics
        decoded = decode_rgbd(color.path, depth.path, camera, depth_scale, color.timestamp)
        if self.ground_truth is None:
            return decoded
        return replace(decoded, cam_to_world=pose_at(*self.ground_truth, color.timestamp))


def pair_paths(path: str | Path) -> tuple[Path, Path]:
    """The colour and depth files of a TUM-style pair from either file's path (see the module docstring)."""
    path = Path(path)
    name = path.name
    if _COLOR_WORD.search(name):
        start, end = list(_COLOR_WORD.finditer(name))[-1].span()
        return path, path.with_name(name[:start] + "depth" + name[end:])
    if _DEPTH_WORD.search(name):
        start, end = list(_DEPTH_WORD.finditer(name))[-1].span()
        for word in ("color", "rgb", "colour"):
            candidate = path.with_name(name[:start] + word + name[end:])
            if candidate.is_file():
                return candidate, path
        return path.with_name(name[:start] + "color" + name[end:]), path
    raise FrameError(f"{path}: a colour/depth pair file name must contain 'color', 'rgb' or 'depth'")


def is_tum_pair(path: Path) -> bool:
    """True when ``path`` is a file of a pair whose other file exists beside it."""
    if not path.is_file():
        return False
    try:
        color, depth = pair_paths(path)
    except FrameError:
        return False
    return color.is_file() and depth.is_file() and color != depth


def pair_color_files(folder: Path, suffixes: tuple[str, ...]) -> list[Path]:
    """The colour files in ``folder`` (with one of ``suffixes``) whose depth file is beside them, unsorted."""
    return [
        path
        for path in folder.iterdir()
        if path.suffix.lower() in suffixes and _COLOR_WORD.search(path.name) and is_tum_pair(path)
    ]


def read_tum_pair(
    path: str | Path,
    depth_scale: float = TUM_DEPTH_SCALE,
    intrinsics: CameraIntrinsics | None = None,
) -> Frame:
    """Decode a TUM-style colour/depth pair (PrimeSense default intrinsics unless given)."""
    color, depth = pair_paths(path)
    return decode_rgbd(color, depth, intrinsics or PRIMESENSE_INTRINSICS, depth_scale)
