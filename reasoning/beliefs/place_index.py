"""An in-memory copy of the belief store's R*Tree (``objects_place``), for the candidate search of
``BeliefStore.integrate``: which beliefs may lie near a frame's observations, without an SQL query.

It holds numpy arrays only (ids, R*Tree entry centres, world codes, grid keys), never per-belief Python objects, so
it adds nothing for Python's cyclic garbage collector to walk (about 50 bytes per belief). Entries are found by a
uniform grid: a sorted array of the cells' hashed keys, plus the short list of entries written since it was sorted
(checked one by one; sorted in when that list grows long). Like the R*Tree, it answers a superset: every entry
whose centre lies within ``reach`` (per axis) of an observation; the store fetches those rows and keeps the ones
within the gate, as it did with the R*Tree's answer.

The store keeps it exact: it is built from the tables, follows the store's own R*Tree writes after they commit,
and is dropped when another connection has written (``PRAGMA data_version``) or the store wrote in a way it does
not follow (``put``, ``forget``, ``clear``, ``allocate_ids``).
"""

from __future__ import annotations

import sqlite3
from collections.abc import Sequence

import numpy as np

from reasoning.fusion.frame import WORLD_FRAME

RESORT_AFTER = 512
"""Entries written since the grid was sorted beyond which it is sorted again."""
PAD = 1e-6
"""Metres by which a search widens its boxes before picking grid cells (float rounding)."""
_BUILD_CHUNK = 20_000
"""Rows read per step while building (bounds the transient Python rows)."""
_CORNERS = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], dtype=np.float64)
_HASH = np.array([73856093, 19349663, 83492791], dtype=np.int64)
_WORLD_HASH = 2654435761
"""Multipliers of the cell hash (int64 arithmetic wraps; a collision only adds hits the store's check drops)."""


def _filed(keys: np.ndarray, slots: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """The slots filed under any of the ``wanted`` keys in sorted ``keys`` (``slots`` in the same order)."""
    begin = np.searchsorted(keys, wanted)
    counts = np.searchsorted(keys, wanted, side="right") - begin
    return slots[np.repeat(begin - np.cumsum(counts) + counts, counts) + np.arange(int(counts.sum()))]


def world_key(frame: str, recording: str) -> tuple[str, str]:
    """The world a belief or an observation lives in: its frame, and its recording unless the frame is the world's
    (camera-frame beliefs of different recordings are never the same object)."""
    return frame, "" if frame == WORLD_FRAME else recording


class PlaceIndex:
    """R*Tree entry centres of the stored beliefs by id, searchable by box (see the module docstring)."""

    def __init__(self, reach: float, version: int) -> None:
        self.reach = float(reach)
        """Largest half-width (metres) of a search box; grid cells are twice that wide."""
        self.cell = 2.0 * (self.reach + 2.0 * PAD)
        self.version = version
        """``PRAGMA data_version`` of the connection when built (another connection's commit changes it)."""
        self.next_id: int | None = None
        """The store's next id as last read or written (None: read it)."""
        self._worlds: dict[tuple[str, str], int] = {}
        self._size = 0
        self._ids = np.empty(0, dtype=np.int64)
        self._place = np.empty((0, 3), dtype=np.float64)
        self._world = np.empty(0, dtype=np.int64)
        self._present = np.empty(0, dtype=bool)
        self._keys = np.empty(0, dtype=np.int64)
        self._slots = np.empty(0, dtype=np.int64)
        self._recent: list[int] = []
        """Slots written since the grid was sorted (their sorted key may be stale)."""
        self._recent_slots = np.empty(0, dtype=np.int64)
        """``_recent`` (once each) sorted by their current keys, which are ``_recent_keys``."""
        self._recent_keys = np.empty(0, dtype=np.int64)

    # ------------------------------------------------------------------ building

    @classmethod
    def build(cls, conn: sqlite3.Connection, reach: float) -> PlaceIndex:
        """The index of every R*Tree entry of a present belief (read inside the caller's transaction)."""
        version = int(conn.execute("PRAGMA data_version").fetchone()[0])
        index = cls(reach, version)
        cursor = conn.execute(
            "SELECT o.id, o.frame, o.recording, (p.x0 + p.x1) / 2, (p.y0 + p.y1) / 2, (p.z0 + p.z1) / 2 "
            "FROM objects o JOIN objects_place p ON p.id = o.id WHERE o.status = 'present' ORDER BY o.id"
        )
        ids: list[np.ndarray] = []
        worlds: list[np.ndarray] = []
        places: list[np.ndarray] = []
        while rows := cursor.fetchmany(_BUILD_CHUNK):
            ids.append(np.array([row[0] for row in rows], dtype=np.int64))
            worlds.append(np.array([index._code(row[1], row[2]) for row in rows], dtype=np.int64))
            places.append(np.array([row[3:6] for row in rows], dtype=np.float64))
            del rows
        if ids:
            index._ids = np.concatenate(ids)
            index._world = np.concatenate(worlds)
            index._place = np.concatenate(places)
            index._size = len(index._ids)
            index._present = np.ones(index._size, dtype=bool)
        index._sort()
        return index

    def _code(self, frame: str, recording: str) -> int:
        key = world_key(frame, recording)
        code = self._worlds.get(key)
        if code is None:
            code = self._worlds[key] = len(self._worlds)
        return code

    def _keys_of(self, places: np.ndarray, worlds: np.ndarray) -> np.ndarray:
        return (np.floor(places / self.cell).astype(np.int64) @ _HASH) ^ (worlds * _WORLD_HASH)

    def _sort(self) -> None:
        n = self._size
        keys = self._keys_of(self._place[:n], self._world[:n])
        order = np.argsort(keys, kind="stable")
        self._keys = keys[order]
        self._slots = order.astype(np.int64)
        self._recent = []
        self._recent_slots = np.empty(0, dtype=np.int64)
        self._recent_keys = np.empty(0, dtype=np.int64)

    # ------------------------------------------------------------------ searching

    def near(self, centres: np.ndarray, frame: str, recording: str, reach: float) -> np.ndarray:
        """Ids (in no order, maybe repeated) of the entries of present beliefs of the world of ``frame`` and
        ``recording`` whose centre lies within ``reach`` (per axis, at most :attr:`reach`) of one of ``centres``
        (n x 3), and maybe of some more."""
        code = self._worlds.get(world_key(frame, recording))
        if code is None or not len(centres) or not self._size:
            return np.empty(0, dtype=np.int64)
        if reach > self.reach:
            raise ValueError(f"reach {reach} is wider than the index's {self.reach}")
        low = np.floor((centres - (reach + PAD)) / self.cell)  # the box spans at most two cells per axis
        cells = (low[:, None, :] + _CORNERS).reshape(-1, 3).astype(np.int64)
        wanted = (cells @ _HASH) ^ (code * _WORLD_HASH)
        slots = _filed(self._keys, self._slots, wanted)
        if len(self._recent_slots):
            slots = np.concatenate([slots, _filed(self._recent_keys, self._recent_slots, wanted)])
        if not len(slots):
            return slots
        places = self._place[slots]
        limit = reach + PAD
        inside = np.abs(places[:, 0, None] - centres[:, 0]) <= limit  # per axis (a reduction over 3 is slow)
        inside &= np.abs(places[:, 1, None] - centres[:, 1]) <= limit
        inside &= np.abs(places[:, 2, None] - centres[:, 2]) <= limit
        keep = inside.any(axis=1) & self._present[slots] & (self._world[slots] == code)
        return self._ids[slots[keep]]

    def places(self, ids: Sequence[int]) -> list[tuple[float, float, float]]:
        """The R*Tree entry centres of beliefs (NaN for one the index does not hold)."""
        n = self._size
        if not n:
            return [(np.nan, np.nan, np.nan)] * len(ids)
        wanted = np.asarray(ids, dtype=np.int64)
        slots = np.minimum(np.searchsorted(self._ids[:n], wanted), max(n - 1, 0))
        places = self._place[slots]
        places[self._ids[slots] != wanted] = np.nan
        return [tuple(p) for p in places.tolist()]

    def forget_absent(self, ids: np.ndarray) -> None:
        """Note that beliefs ``ids`` are not present (a search's hits the store found gone)."""
        slots = np.searchsorted(self._ids[: self._size], ids)
        self._present[slots] = False

    # ------------------------------------------------------------------ updating

    def update(self, written: Sequence[tuple[int, str, str, float, float, float]]) -> bool:
        """Follow committed R*Tree writes: ``written`` (id, frame, recording, entry centre) of beliefs; an id larger
        than all known is appended. False when the index cannot follow them (then drop it)."""
        if not written:
            return True
        latest = {w[0]: w for w in written}  # an id written twice: its last entry
        written = [latest[k] for k in sorted(latest)]
        n = self._size
        ids = np.array([w[0] for w in written], dtype=np.int64)
        slots = np.searchsorted(self._ids[:n], ids)
        fresh = slots == n
        count = int(fresh.sum())
        if count:
            new = ids[fresh]
            self._grow(n + count)
            slots[fresh] = np.arange(n, n + count)
            self._ids[n : n + count] = new
            self._size = n + count
        if not bool((self._ids[slots] == ids).all()):
            return False
        self._place[slots] = [w[3:6] for w in written]
        self._world[slots] = [self._code(w[1], w[2]) for w in written]
        self._present[slots] = True
        self._recent.extend(slots.tolist())
        if len(self._recent) > RESORT_AFTER:
            self._sort()
        else:
            recent = np.unique(np.array(self._recent, dtype=np.int64))
            keys = self._keys_of(self._place[recent], self._world[recent])
            order = np.argsort(keys)
            self._recent_keys, self._recent_slots = keys[order], recent[order]
        return True

    def _grow(self, size: int) -> None:
        capacity = len(self._ids)
        if size <= capacity:
            return
        capacity = max(size, 2 * capacity, 1024)

        def grown(array: np.ndarray) -> np.ndarray:
            bigger = np.zeros((capacity, *array.shape[1:]), dtype=array.dtype)
            bigger[: len(array)] = array
            return bigger

        self._ids = grown(self._ids)
        self._place = grown(self._place)
        self._world = grown(self._world)
        self._present = grown(self._present)
