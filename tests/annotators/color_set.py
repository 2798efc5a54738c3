"""The hand-labelled colour test set (tests/data/colors/real_colors.json): objects on real frames of ../shared/data,
each with its pixels (a mask recipe) and the colour names a person gives it.

Mask recipes: ``{"label": k}`` is object ``k`` of an mOSD scene (labels ``10k..10k+9``); ``{"box": [x0, y0, x1,
y1]}`` is every pixel of the box that stands at least ``ABOVE_PLANE_M`` above the plane fitted (RANSAC, fixed seed)
to the depth of a ring around the box, its largest 8-connected part; ``"above_plane": false`` keeps every pixel of
the box (for a box drawn inside the object, e.g. an object standing on another one).

Scoring (:func:`is_named_as_labelled`): the names reported (dominant first, then a second one or none) must
include every labelled colour (``or`` lists names a person would accept instead of the first one), every
reported name must be labelled (``colors``, ``or``) or acceptable as a minor colour (``also``), and the dominant
one must not be an ``also`` name.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import cv2
import numpy as np

from annotators.readers.choice import reader_for
from annotators.readers.frame_io import Frame

REPO_ROOT = Path(__file__).resolve().parents[2]
SHARED_DATA = REPO_ROOT.parent / "shared" / "data"
LABELS = REPO_ROOT / "tests" / "data" / "colors" / "real_colors.json"

ABOVE_PLANE_M = 0.012
"""How far above the fitted support a pixel must be to belong to a box's object."""

RING_PX = 14
"""Width of the ring around a box whose depth gives the support plane."""

SPLITS = ("tune", "held_out", "fresh", "fresh2")
"""The labelled splits. Rounds 1-2 tuned the namer on "tune" only; "held_out" and "fresh" checked it. From the third
tuning round on (branch colour10) "held_out" keeps its name but is tuned on as well: "fresh" and "fresh2" (labelled
in round 3, before the namer was run on it) are the held-out checks. From the fourth round on (branch colour11)
"fresh2" is tuned on too: "fresh" (never tuned on) is the one held-out check."""

FIRST_ROUND = 1
"""The labelling round the issue's goals were measured on (its "tune" and "held_out" objects, 84)."""


@dataclass(frozen=True)
class ColorSample:
    """One labelled object: where it is and what a person calls its colour."""

    name: str
    input: str
    frame: int
    split: str
    colors: tuple[str, ...]
    alternatives: tuple[str, ...]
    also: tuple[str, ...]
    labelling_round: int = FIRST_ROUND
    label: int | None = None
    box: tuple[int, int, int, int] | None = None
    above_plane: bool = True

    @property
    def key(self) -> str:
        """A short unique name: input, frame and object."""
        return f"{Path(self.input).stem}#{self.frame}:{self.name}"


def load_samples(path: Path = LABELS) -> list[ColorSample]:
    """Every labelled object of the file, in file order."""
    data = json.loads(path.read_text())
    samples = []
    for frame in data["frames"]:
        for obj in frame["objects"]:
            mask = obj["mask"]
            samples.append(
                ColorSample(
                    name=obj["name"],
                    input=frame["input"],
                    frame=int(frame["frame"]),
                    split=frame["split"],
                    colors=tuple(obj["colors"]),
                    alternatives=tuple(obj.get("or", ())),
                    also=tuple(obj.get("also", ())),
                    labelling_round=int(frame.get("round", FIRST_ROUND)),
                    label=mask.get("label"),
                    box=tuple(mask["box"]) if "box" in mask else None,
                    above_plane=bool(mask.get("above_plane", True)),
                )
            )
    return samples


@cache
def load_frame(input_path: str, frame: int) -> Frame:
    """The decoded frame (colour, depth, intrinsics, labels) of an input under ../shared/data."""
    reader = reader_for(str(SHARED_DATA / input_path), frame)
    return reader.load()  # type: ignore[attr-defined]


def _points(frame: Frame) -> np.ndarray:
    if frame.points is not None:
        return frame.points
    k = frame.intrinsics
    height, width = frame.depth.shape
    u, v = np.meshgrid(np.arange(width, dtype=np.float32), np.arange(height, dtype=np.float32))
    z = np.where(frame.depth > 0, frame.depth, np.nan).astype(np.float32)
    return np.dstack([(u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z])


def _support_plane(points: np.ndarray) -> np.ndarray:
    """RANSAC plane (n, d) with n pointing to the camera side, from Nx3 points."""
    rng = np.random.default_rng(0)
    best, best_count = None, -1
    for _ in range(300):
        a, b, c = points[rng.choice(points.shape[0], 3, replace=False)]
        normal = np.cross(b - a, c - a)
        norm = np.linalg.norm(normal)
        if norm < 1e-9:
            continue
        normal /= norm
        d = -float(normal @ a)
        count = int(np.count_nonzero(np.abs(points @ normal + d) < 0.008))
        if count > best_count:
            best, best_count = np.append(normal, d), count
    assert best is not None, "no plane in the ring around the box"
    if best[3] < 0:  # the camera (origin) on the positive side
        best = -best
    return best


def sample_mask(sample: ColorSample, frame: Frame) -> np.ndarray:
    """The HxW bool mask of the sample's object."""
    height, width = frame.color.shape[:2]
    if sample.label is not None:
        assert frame.labels is not None, f"{sample.input} has no labels"
        labels = frame.labels
        return (labels >= 20) & (labels // 10 == sample.label)
    assert sample.box is not None
    x0, y0, x1, y1 = sample.box
    inside = np.zeros((height, width), dtype=bool)
    inside[y0:y1, x0:x1] = True
    if not sample.above_plane:
        return inside
    points = _points(frame)
    valid = np.isfinite(points[..., 2]) & (points[..., 2] > 0)
    ring = np.zeros_like(inside)
    ring[max(0, y0 - RING_PX) : y1 + RING_PX, max(0, x0 - RING_PX) : x1 + RING_PX] = True
    ring &= ~inside & valid
    plane = _support_plane(points[ring].astype(np.float64))
    height_above = np.where(valid, points @ plane[:3] + plane[3], -np.inf)
    mask = inside & (height_above > ABOVE_PLANE_M)
    count, parts, stats, _ = cv2.connectedComponentsWithStats(mask.view(np.uint8), connectivity=8)
    if count <= 1:
        return mask
    largest = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    return parts == largest


def is_named_as_labelled(sample: ColorSample, reported: Sequence[str]) -> bool:
    """Whether the reported names (dominant first) are what the label says (see the module docstring)."""
    if not reported:
        return False
    first_ok = sample.colors[0] in reported or any(name in reported for name in sample.alternatives)
    rest_ok = all(name in reported for name in sample.colors[1:])
    allowed = set(sample.colors) | set(sample.alternatives) | set(sample.also)
    dominant_ok = reported[0] in set(sample.colors) | set(sample.alternatives)
    return first_ok and rest_ok and dominant_ok and all(name in allowed for name in reported)
