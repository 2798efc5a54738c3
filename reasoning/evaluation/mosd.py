"""The labelling conventions of the modified Object Segmentation Database (mOSD, PCL data: ``segmentation/mOSD``).

Per-point labels: 0 = no measurement, 1-9 = (parts of) the supporting table, 20-29 = (parts of) the first object,
30-39 = the second, and so on; the object id is ``label // 10`` for labels >= 20 (disjoint parts of one object
carry different units digits). The scenes are files ``learnN.pcd`` and ``testN.pcd`` whose number gives the
category, as the database's README lists it.
"""

from __future__ import annotations

import re
from pathlib import PurePath

import numpy as np

FIRST_OBJECT_LABEL = 20

CATEGORY_RANGES: dict[str, tuple[tuple[int, int, str], ...]] = {
    "learn": ((0, 16, "boxes"), (17, 24, "stacked"), (25, 32, "occluded"), (33, 44, "cylindric")),
    "test": (
        (0, 15, "boxes"),
        (16, 23, "stacked"),
        (24, 30, "occluded"),
        (31, 42, "cylindric"),
        (43, 54, "mixed"),
        (55, 65, "complex"),
    ),
}
"""Inclusive scene-number ranges of each split's categories (mOSD README)."""

_SCENE_NAME = re.compile(r"^(learn|test)(\d+)$")


def object_labels(labels: np.ndarray) -> np.ndarray:
    """HxW int32 object ids: ``label // 10 - 1`` (1, 2, ...) for labels >= 20, 0 for the table and no data."""
    labels = np.asarray(labels).astype(np.int64)
    return np.where(labels >= FIRST_OBJECT_LABEL, labels // 10 - 1, 0).astype(np.int32)


def table_mask(labels: np.ndarray) -> np.ndarray:
    """HxW bool: the points labelled as the supporting table (1-9)."""
    labels = np.asarray(labels)
    return (labels >= 1) & (labels <= 9)


def scene_category(path: str | PurePath) -> str:
    """The mOSD category of a scene file (``learn17.pcd`` -> ``stacked``); other files: their folder's name."""
    path = PurePath(path)
    found = _SCENE_NAME.match(path.stem)
    if found:
        number = int(found.group(2))
        for first, last, category in CATEGORY_RANGES[found.group(1)]:
            if first <= number <= last:
                return category
    return path.parent.name or "scenes"
