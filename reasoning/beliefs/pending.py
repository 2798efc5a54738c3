"""The frames a write-behind belief store has fused but its writer has not yet committed, as an overlay on what the
store's connection reads (issue 19).

A frame's candidate search reads the committed ``objects`` rows with their R*Tree entries;
:meth:`PendingFrames.overlaid` turns that into what the search would have read with every pending frame committed:
rows a pending frame wrote replace their stored versions (and count as found when they meet the search), and the
gone rule of each pending frame (``_MARK_GONE``) is applied. Applying it to a read that already holds some of those
frames gives the same rows (each pending row replaces itself; the gone rule is idempotent), so a frame may be
committed during the read.

R*Tree entries are kept as SQLite's R*Tree stores them: 32-bit floats, the lower bound rounded down and the upper one
up (:func:`rtree_bounds`), so an overlaid row equals the row SQLite would return.
"""

from __future__ import annotations

from array import array
from collections import deque
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

_TOWARDS = 1.0 - 1.0 / 8388608.0
_AWAY = 1.0 + 1.0 / 8388608.0

FRAME, STATUS, LAST_SEEN, MISSES, RECORDING = 2, 16, 18, 19, 23
"""Columns of an ``objects`` row the candidate search and the gone rule read."""
PRESENT = "present"
GONE = "gone"


def rtree_bounds(boxes: Sequence[Sequence[float]]) -> list[tuple[float, ...]]:
    """Rows ``(id, x0, x1, y0, y1, z0, z1)`` as a 32-bit SQLite R*Tree stores them and returns them: each bound cast
    to a float, lower bounds not above and upper bounds not below the given value (SQLite's ``rtreeValueDown`` and
    ``rtreeValueUp``: a cast that went the wrong way is redone on the value scaled by one float epsilon)."""
    stored = []
    for box in boxes:
        values = [float(v) for v in box[1:]]
        rounded = array("f", values).tolist()  # C's double -> float cast, as SQLite's
        for k, (value, bound) in enumerate(zip(values, rounded, strict=True)):
            lower = k % 2 == 0
            if bound > value if lower else bound < value:
                scale = _AWAY if lower == (value < 0) else _TOWARDS
                rounded[k] = array("f", [value * scale])[0]
        stored.append((int(box[0]), *rounded))
    return stored


@dataclass(slots=True)
class PendingFrame:
    """One fused frame not yet committed: the rows it wrote (columns, then the R*Tree entry), its gone rule's time
    bound, and ``meta.next_id`` after it."""

    seq: int
    rows: dict[int, tuple]
    gone_before: float
    next_id: int


class PendingFrames:
    """The pending frames of one store, oldest first, and their overlay."""

    def __init__(self) -> None:
        self.frames: deque[PendingFrame] = deque()
        self._view: tuple[dict[int, tuple], float] | None = None

    def __len__(self) -> int:
        return len(self.frames)

    def add(self, frame: PendingFrame) -> None:
        """A frame handed to the writer."""
        self.frames.append(frame)
        self._view = None

    def committed(self, seq: int) -> None:
        """Frame ``seq`` (the oldest) is committed: reads now see it."""
        oldest = self.frames.popleft()
        if oldest.seq != seq:
            raise RuntimeError(f"the writer committed frame {seq}, the oldest pending frame is {oldest.seq}")
        self._view = None

    def clear(self) -> None:
        """Forget every pending frame (their writes failed)."""
        self.frames.clear()
        self._view = None

    @property
    def next_id(self) -> int:
        """``meta.next_id`` after the newest pending frame (only when there is one)."""
        return self.frames[-1].next_id

    def view(self) -> tuple[dict[int, tuple], float]:
        """Every row a pending frame wrote, as of the newest one and with the later gone rules applied, and the
        latest time bound of the gone rules (for rows no pending frame wrote)."""
        if self._view is None:
            latest: dict[int, tuple] = {}
            bound = -np.inf
            for frame in reversed(self.frames):  # newest first: a row's last writer wins, later bounds apply to it
                bound = max(bound, frame.gone_before)
                for belief_id, row in frame.rows.items():
                    if belief_id not in latest:
                        latest[belief_id] = _after_gone_rule(row, bound)
            self._view = (latest, bound)
        return self._view

    def overlaid(
        self, found: Sequence[tuple], boxes: np.ndarray, frame: str, world: str, recording: str
    ) -> list[tuple]:
        """The rows the candidate search would have found with every pending frame committed (see the module
        docstring): ``found`` from the committed store, ``boxes`` the search boxes (x1, x0, y1, y0, z1, z0 each, as
        in the statement), present beliefs of ``frame`` whose frame is ``world`` or whose recording is
        ``recording``."""
        latest, bound = self.view()
        kept = [row for row in found if row[0] not in latest and not _gone(row, bound)]
        candidates = [
            row
            for row in latest.values()
            if row[STATUS] == PRESENT and row[FRAME] == frame and (row[FRAME] == world or row[RECORDING] == recording)
        ]
        if candidates:
            entry_start = len(candidates[0]) - 6  # the R*Tree entry follows the row's columns
            entries = np.array([row[entry_start:] for row in candidates], dtype=np.float64)
            search = np.asarray(boxes, dtype=np.float64).reshape(-1, 6)
            hit = (
                (entries[:, None, 0] <= search[None, :, 0])
                & (entries[:, None, 1] >= search[None, :, 1])
                & (entries[:, None, 2] <= search[None, :, 2])
                & (entries[:, None, 3] >= search[None, :, 3])
                & (entries[:, None, 4] <= search[None, :, 4])
                & (entries[:, None, 5] >= search[None, :, 5])
            ).any(axis=1)
            kept.extend(row for row, meets in zip(candidates, hit.tolist(), strict=True) if meets)
        return kept


def _gone(row: tuple, bound: float) -> bool:
    """Whether the gone rule with time bound ``bound`` marks ``row`` gone."""
    return row[MISSES] > 0 and row[STATUS] == PRESENT and row[LAST_SEEN] <= bound


def _after_gone_rule(row: tuple, bound: float) -> tuple:
    if _gone(row, bound):
        return (*row[:STATUS], GONE, *row[STATUS + 1 :])
    return row


def entries_of(rows: Iterable[tuple], moved: dict[int, tuple], loaded: dict[int, tuple], columns: int) -> dict:
    """Each written row followed by its R*Tree entry: the rewritten one (``moved``, as stored) or the one it had
    (``loaded``, after its ``columns`` columns)."""
    return {
        row[0]: (*row, *(moved[row[0]][1:] if row[0] in moved else loaded[row[0]][columns : columns + 6]))
        for row in rows
    }
