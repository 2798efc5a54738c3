"""The packed forms the belief store writes: attribute supports as binary records, rounded numbers, image boxes
and expert sets as text (shared by the store and its row-level update, :mod:`reasoning.beliefs.row_update`)."""

from __future__ import annotations

import functools
import json
import struct
from collections.abc import Sequence

import numpy as np

INDEX_SEPARATOR = "\x1f"
"""Between the entries of an ``objects`` row's ``indexed`` column (``name=value`` each, sorted)."""

SUPPORT = struct.Struct("<iidqidd")
"""One packed value support: attribute name code, value code, log-odds (rounded to 9 digits), count, expert-set
code, first seen, last seen (little-endian; the attribute column is these records one after another)."""
FIELDS = 7
"""Numbers in one packed support."""


@functools.lru_cache(maxsize=64)
def supports_packing(count: int) -> struct.Struct:
    """The packing of ``count`` supports."""
    return struct.Struct("<" + SUPPORT.format[1:] * count)


@functools.lru_cache(maxsize=4096, typed=True)
def rounded_cached(value: float, digits: int) -> float:
    return round(value, digits)


def rounded(value: float, digits: int) -> float:
    """``round(value, digits)``, remembered for the values that recur on every row (accumulated log-odds, the
    experts' confidences); zero is rounded afresh, as the cache would not tell -0.0 from 0.0."""
    return rounded_cached(value, digits) if value else round(value, digits)


def roi_text(roi: tuple[int, int, int, int] | None) -> str | None:
    if roi is None:
        return None
    x0, y0, x1, y1 = roi
    return "%d,%d,%d,%d" % (x0, y0, x1, y1)  # noqa: UP031 - int() of each, faster than an f-string of four int()


def roi_from_text(text: str | None) -> tuple[int, int, int, int] | None:
    if not text:
        return None
    x0, y0, x1, y1 = map(int, text.split(","))
    return x0, y0, x1, y1


def floats(values: np.ndarray | Sequence[float], count: int) -> list[float]:
    """The first ``count`` values as Python floats (one conversion of the array, not one per element)."""
    if type(values) is np.ndarray and values.dtype == np.float64 and values.shape == (count,):
        return values.tolist()  # the common case: already that array
    return np.asarray(values, dtype=np.float64)[:count].tolist()


@functools.lru_cache(maxsize=256)
def decoded_sources(text: str) -> tuple[str, ...]:
    """The experts of a ``sources`` column (few distinct texts recur on every row)."""
    return tuple(json.loads(text))
