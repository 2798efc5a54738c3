"""Object-by-object verdicts of a segmentation against sparse labels: per object a pixel well inside it and the box
of all of it in view (cheaper to draw than pixel masks, and enough to tell a cut or merged object from a whole one).

An object's segment is the one at its pixel (the commonest segment in the 5x5 pixels round it). The object is

* ``missed``: no segment there;
* ``merged``: its segment also holds another labelled object's pixel;
* ``cut``: a segment holding no labelled pixel, of at least ``PIECE_PX`` pixels, lies with at least
  ``PIECE_INSIDE`` of its pixels in this object's box and in no other, or its segment's box overlaps the labelled
  box with IoU below 0.5 (the match rule of the eval command) and is the smaller box;
* ``spills over``: its segment's box is larger than the labelled one, with IoU below 0.5 (it holds unlabelled
  surface: table, or part of another object);
* ``whole`` otherwise.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

PIECE_PX = 200
"""Fewest pixels of a segment counted as a piece of an object (a piece a person sees on a 640x480 frame)."""
PIECE_INSIDE = 0.8
"""Share of a piece's pixels that lie in its object's box."""
MIN_IOU = 0.5
"""Box IoU an object's segment needs, as in the eval command."""

Box = tuple[int, int, int, int]


@dataclass(frozen=True)
class LabelledObject:
    """One labelled object: its name, a pixel (x, y) well inside it, the box (x0, y0, x1, y1; ends exclusive)."""

    name: str
    pixel: tuple[int, int]
    box: Box


@dataclass(frozen=True)
class Verdict:
    """How a segmentation treats one object: ``kind`` is whole, missed, merged, cut or spills over."""

    kind: str
    detail: str = ""

    def __str__(self) -> str:
        return f"{self.kind} ({self.detail})" if self.detail else self.kind


def load_labelled_objects(path: Path) -> dict[tuple[str, int], list[LabelledObject]]:
    """The labelled objects per (input, frame) of a labels file (``frames`` of ``input``, ``frame``, ``objects``)."""
    data = json.loads(path.read_text())
    return {
        (frame["input"], int(frame["frame"])): [
            LabelledObject(o["name"], (int(o["pixel"][0]), int(o["pixel"][1])), tuple(o["box"]))  # type: ignore[arg-type]
            for o in frame["objects"]
        ]
        for frame in data["frames"]
    }


def _segment_at(labels: np.ndarray, pixel: tuple[int, int]) -> int:
    x, y = pixel
    window = labels[max(0, y - 2) : y + 3, max(0, x - 2) : x + 3].ravel()
    window = window[window > 0]
    return int(np.bincount(window).argmax()) if window.size else 0


def _box_of(mask: np.ndarray) -> Box:
    rows, cols = np.nonzero(mask)
    return int(cols.min()), int(rows.min()), int(cols.max()) + 1, int(rows.max()) + 1


def _area(box: Box) -> int:
    return (box[2] - box[0]) * (box[3] - box[1])


def _iou(a: Box, b: Box) -> float:
    w = max(0, min(a[2], b[2]) - max(a[0], b[0]))
    h = max(0, min(a[3], b[3]) - max(a[1], b[1]))
    union = _area(a) + _area(b) - w * h
    return w * h / union if union else 0.0


def _pieces(labels: np.ndarray, objects: list[LabelledObject], labelled: set[int]) -> dict[str, list[int]]:
    """Per object, the sizes of the unlabelled segments that lie in its box and in no other."""
    in_box = {}
    for o in objects:
        inside = np.zeros(labels.shape, dtype=bool)
        x0, y0, x1, y1 = o.box
        inside[y0:y1, x0:x1] = True
        in_box[o.name] = inside
    pieces: dict[str, list[int]] = {o.name: [] for o in objects}
    sizes = np.bincount(labels.ravel())
    for segment in range(1, sizes.size):
        if segment in labelled or sizes[segment] < PIECE_PX:
            continue
        mask = labels == segment
        shares = {name: np.count_nonzero(mask & box) / sizes[segment] for name, box in in_box.items()}
        owners = [name for name, share in shares.items() if share >= PIECE_INSIDE]
        if len(owners) == 1 and sum(share > 1 - PIECE_INSIDE for share in shares.values()) == 1:
            pieces[owners[0]].append(int(sizes[segment]))
    return pieces


def object_verdicts(labels: np.ndarray, objects: list[LabelledObject]) -> dict[str, Verdict]:
    """Each object's verdict for an HxW segmentation (0 = no segment), by object name."""
    at = {o.name: _segment_at(labels, o.pixel) for o in objects}
    pieces = _pieces(labels, objects, {s for s in at.values() if s})
    verdicts = {}
    for o in objects:
        segment = at[o.name]
        if not segment:
            verdicts[o.name] = Verdict("missed")
            continue
        others = [p.name for p in objects if p.name != o.name and at[p.name] == segment]
        if others:
            verdicts[o.name] = Verdict("merged", "with " + ", ".join(others))
            continue
        mask = labels == segment
        found = _box_of(mask)
        iou = _iou(found, o.box)
        size = int(np.count_nonzero(mask))
        detail = f"{' + '.join(map(str, [size, *pieces[o.name]]))} px, box IoU {iou:.2f}"
        if pieces[o.name] or (iou < MIN_IOU and _area(found) <= _area(o.box)):
            verdicts[o.name] = Verdict("cut", detail)
        elif iou < MIN_IOU:
            verdicts[o.name] = Verdict("spills over", detail)
        else:
            verdicts[o.name] = Verdict("whole")
    return verdicts
