"""The persistent belief store: one SQLite file holding object beliefs and their observation history.

* Embedded, one file, WAL journal: readers (other connections, other processes) read a consistent snapshot
  while the engine writes; every write is one ``BEGIN IMMEDIATE`` ... ``COMMIT`` transaction.
* ``synchronous=NORMAL`` by default: with WAL, a committed transaction survives a crash of the process
  (SIGKILL) and the file never corrupts; only a power loss or OS crash may lose the last commits: those since the
  last checkpoint synced the WAL (at most :data:`WAL_AUTOCHECKPOINT_PAGES` pages, about 16 MB of WAL; a frame of
  20 hypotheses writes some 60 to 80 pages, so at most the last 50 to 70 frames, about two seconds at 30 Hz). The store
  rolls back to an earlier consistent state and never corrupts. Pass ``synchronous="FULL"`` to also survive power
  loss, at the cost of an fsync per commit.
* ``write_behind=N`` (off by default; N at most :data:`~reasoning.beliefs.frame_writer.MAX_WRITE_BEHIND`):
  :meth:`BeliefStore.integrate` hands each frame's transaction to a writer process
  (:mod:`reasoning.beliefs.frame_writer`) and returns with at most N frames uncommitted; the next frame is
  fused through an overlay of the pending ones (:mod:`reasoning.beliefs.pending`), so the results are those of
  committing each frame at once. Every other method first waits for the pending frames; :meth:`BeliefStore.flush`
  or ``integrate(..., wait=True)`` commit them on demand. What a crash may lose grows by those N frames: a SIGKILL
  of the store's process loses none the writer has read whole (it commits them, then exits), a SIGKILL of both or a
  power loss loses up to N more than above; a failed write loses its frame and the frames fused after it (raised by
  the next call). The store must be the file's only writer while it runs this way (a frame whose ``next_id`` was
  changed by another writer fails rather than reuse ids).
* A file that is not a valid belief store is never modified: opening it raises :class:`BeliefStoreError`
  naming the file and how to move it aside. A store of schema version 1 (before recordings were stored) is
  migrated in one transaction: its beliefs and sightings get an empty recording, so its camera-frame beliefs are
  never confused with new observations, while its world-frame beliefs go on being updated. A store of version 2
  (attribute supports as JSON text) gets its attribute column rewritten as packed supports in that transaction.

Tables: ``objects`` (one row per belief: class, pose, size, region, recording, existence, first/last seen,
experts and the support of every attribute value, packed: one binary record per value, see :data:`SUPPORT`),
``interned`` (the attribute names, values and expert sets those records refer to by code, append-only),
``objects_place`` (R*Tree over positions),
``attribute_index`` (the attribute values each belief holds more likely than not, for queries; colours also as last
seen, :mod:`reasoning.beliefs.seen_together`),
``observations`` (every sighting
with its recording and the experts' statements, packed, bounded per object), ``views`` (one row per recording and
frame: the last camera pose and support plane seen from it, so that a selection from memory measures as the last
frame did, :meth:`BeliefStore.viewpoints`), ``classes`` and ``meta``. A store of version 4 gets an empty ``views``
table.
"""

from __future__ import annotations

import functools
import json
import operator
import os
import shlex
import sqlite3
import struct
import threading
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import TypeVar

import numpy as np
import platformdirs

from queries.selection import SelectionRequest
from reasoning.beliefs.class_candidates import (
    BY_ID,
    GUESSED_CLASSES,
    candidate_class_clauses,
    general_classes,
    leading_refinement,
)
from reasoning.beliefs.frame_writer import MAX_WRITE_BEHIND, NEXT_ID, FrameWriter, WriterGoneError
from reasoning.beliefs.interned import INTERN, InternedTexts, decoded_supports
from reasoning.beliefs.packed import (
    FIELDS,
    INDEX_SEPARATOR,
    SUPPORT,
    decoded_sources,
    floats,
    roi_from_text,
    roi_text,
    rounded_cached,
    supports_packing,
)
from reasoning.beliefs.pending import PendingFrame, PendingFrames, entries_of, rtree_bounds
from reasoning.beliefs.row_update import RowUpdate, Support, belief_of
from reasoning.beliefs.seen_together import SEEN_TOGETHER, last_stated
from reasoning.beliefs.selection import Viewpoint
from reasoning.fusion.association import CameraModel, in_view
from reasoning.fusion.frame import WORLD_FRAME, FrameObject
from reasoning.fusion.rule import (
    CLASS_ATTRIBUTE,
    AttributeBelief,
    ClassTest,
    Evidence,
    ValueSupport,
    fuse_values,
    sigmoid,
)
from reasoning.fusion.tracking import PRESENT, BeliefTracker, ChangedBeliefs, ObjectBelief, TrackStep
from robokudo.core.regions import RegionBox
from robokudo.core.text_match import text_matches
from robokudo.core.types import Text

SCHEMA_NAME = "robokudo-beliefs"
SCHEMA_VERSION = 5
MIGRATIONS = {
    1: (
        "ALTER TABLE objects ADD COLUMN recording TEXT NOT NULL DEFAULT ''",
        "ALTER TABLE observations ADD COLUMN recording TEXT NOT NULL DEFAULT ''",
    ),
    2: (),  # and the attribute column rewritten from JSON to packed supports (_pack_attribute_column)
    3: (),  # and the classes guessed for beliefs without a supported class listed in ``classes`` (GUESSED_CLASSES)
    4: (),  # and the ``views`` table (empty: an older store answers selections as before until a frame is seen)
}
"""Version -> the statements that bring a store of that version to the next one."""
SQLITE_HEADER = b"SQLite format 3\x00"
SYNCHRONOUS_MODES = ("OFF", "NORMAL", "FULL", "EXTRA")
_CORRUPT_ERRORS = {"SQLITE_CORRUPT", "SQLITE_NOTADB"}
RTREE_SLACK = 0.05
"""Half-width (metres) of a belief's R*Tree entry around its position."""
SOURCES_CACHE_LIMIT = 4096
"""Distinct expert sets a store keeps the JSON of (beyond that the cache starts afresh)."""
VIEW_CACHE_LIMIT = 4096
"""Rows :meth:`BeliefStore.query_views` remembers the views of (beyond that the memo starts afresh)."""
CLASS_WAYS_CACHE_LIMIT = 256
"""(Asked class, class test) pairs a store remembers the answering classes of (beyond that it starts afresh)."""
WAL_AUTOCHECKPOINT_PAGES = 4000
"""Checkpoint the WAL into the file every ~16 MB (fewer fsyncs than SQLite's default of 1000 pages)."""


T = TypeVar("T")


class BeliefStoreError(Exception):
    """The store file cannot be used (corrupt, not a belief store, newer schema, ...)."""


@dataclass(frozen=True)
class BeliefFilter:
    """Which beliefs a query asks for; every given part must hold.

    ``class_test(a, b)`` tells whether class ``a`` is ``b`` or a subclass of it (default: equal names, case
    ignored). A belief is in ``region`` when its stored region has that name (case ignored) or when its world
    position lies in one of ``region_boxes``. ``attributes`` (e.g. ``{"color": "red"}``, case ignored) match the
    fused value or any value more likely than not (a colour also any of those stated when the belief's colour was
    last stated: a red-and-white can answers to "red" and to "white"); ``text`` matches when each of its words is
    read in such a value, tolerating OCR errors (:func:`~robokudo.core.text_match.text_matches`). An attribute given
    several values (``{"color": ("red", "blue")}``) matches when any of them does. ``ids`` restricts the answer to
    those beliefs. ``selection`` (``the top box``) is applied by the answer (:mod:`reasoning.beliefs.selection`),
    not by the store.
    """

    object_class: str | None = None
    class_test: ClassTest | None = None
    region: str | None = None
    region_boxes: tuple[RegionBox, ...] = ()
    attributes: Mapping[str, str | tuple[str, ...]] = field(default_factory=dict)
    include_gone: bool = False
    min_confidence: float = 0.0
    limit: int | None = None
    ids: tuple[int, ...] | None = None
    selection: SelectionRequest | None = None


@dataclass(frozen=True, slots=True)
class ObservationRecord:
    """One sighting of an object: when, where, the image box, and every statement the experts made."""

    object_id: int
    time: float
    frame: str
    position: tuple[float, float, float]
    roi: tuple[int, int, int, int] | None
    sources: tuple[str, ...]
    evidence: tuple[tuple[str, str, float, str], ...]
    recording: str = ""


def _corrupt_message(path: Path, detail: str) -> str:
    quoted = shlex.quote(str(path))
    aside = shlex.quote(f"{path}.corrupt")
    return (
        f"belief store {path} is not usable: {detail}. The file was left untouched. "
        f"Move it aside to start a new store (the old one stays available for inspection): mv {quoted} {aside}"
    )


_OBJECT_COLUMNS = (
    "id, class_name, frame, px, py, pz, qx, qy, qz, qw, sx, sy, sz, position_variance, appearance, existence, "
    "status, first_seen, last_seen, misses, observations, region, region_class, recording, roi, sources, attributes, "
    "indexed"
)

_INTERNED_TABLE = "CREATE TABLE IF NOT EXISTS interned (code INTEGER PRIMARY KEY, text TEXT NOT NULL UNIQUE)"

_SCHEMA = (
    "CREATE TABLE IF NOT EXISTS meta (key TEXT PRIMARY KEY, value TEXT NOT NULL) WITHOUT ROWID",
    """CREATE TABLE IF NOT EXISTS objects (
        id INTEGER PRIMARY KEY,
        class_name TEXT,
        frame TEXT NOT NULL,
        px REAL NOT NULL, py REAL NOT NULL, pz REAL NOT NULL,
        qx REAL NOT NULL, qy REAL NOT NULL, qz REAL NOT NULL, qw REAL NOT NULL,
        sx REAL, sy REAL, sz REAL,
        position_variance REAL NOT NULL,
        appearance BLOB,
        existence REAL NOT NULL,
        status TEXT NOT NULL,
        first_seen REAL NOT NULL,
        last_seen REAL NOT NULL,
        misses INTEGER NOT NULL,
        observations INTEGER NOT NULL,
        region TEXT NOT NULL,
        region_class TEXT NOT NULL,
        recording TEXT NOT NULL DEFAULT '',
        roi TEXT,
        sources TEXT NOT NULL,
        attributes BLOB NOT NULL,
        indexed TEXT NOT NULL
    )""",
    "CREATE INDEX IF NOT EXISTS objects_class ON objects (class_name, region COLLATE NOCASE)",
    "CREATE INDEX IF NOT EXISTS objects_region ON objects (region COLLATE NOCASE)",
    "CREATE INDEX IF NOT EXISTS objects_missed ON objects (last_seen) WHERE misses > 0 AND status = 'present'",
    "CREATE VIRTUAL TABLE IF NOT EXISTS objects_place USING rtree (id, x0, x1, y0, y1, z0, z1)",
    """CREATE TABLE IF NOT EXISTS attribute_index (
        name TEXT NOT NULL,
        value TEXT NOT NULL COLLATE NOCASE,
        object_id INTEGER NOT NULL,
        PRIMARY KEY (name, value, object_id)
    ) WITHOUT ROWID""",
    """CREATE TABLE IF NOT EXISTS observations (
        object_id INTEGER NOT NULL,
        seq INTEGER NOT NULL,
        time REAL NOT NULL,
        frame TEXT NOT NULL,
        px REAL NOT NULL, py REAL NOT NULL, pz REAL NOT NULL,
        roi TEXT,
        sources TEXT NOT NULL,
        evidence TEXT NOT NULL,
        recording TEXT NOT NULL DEFAULT ''
    )""",
    "CREATE UNIQUE INDEX IF NOT EXISTS observations_object ON observations (object_id, seq)",
    "CREATE INDEX IF NOT EXISTS attribute_index_object ON attribute_index (object_id)",
    "CREATE TABLE IF NOT EXISTS classes (name TEXT PRIMARY KEY) WITHOUT ROWID",
    _INTERNED_TABLE,
    """CREATE TABLE IF NOT EXISTS views (
        recording TEXT NOT NULL,
        frame TEXT NOT NULL,
        time REAL NOT NULL,
        pose BLOB,
        plane BLOB,
        PRIMARY KEY (recording, frame)
    ) WITHOUT ROWID""",
    "CREATE INDEX IF NOT EXISTS views_latest ON views (frame, time)",
)


_TABLES = {"meta", "objects", "objects_place", "attribute_index", "observations", "classes", "interned"}
"""The tables of a complete store of schema 4 (schema 5 adds ``views``, :data:`_VIEW_TABLES`)."""
_VIEW_TABLES = {"views"}

_RECORD_VIEW = (
    "INSERT INTO views VALUES (?, ?, ?, ?, ?) ON CONFLICT (recording, frame) DO UPDATE SET time = excluded.time, "
    "pose = excluded.pose, plane = excluded.plane WHERE excluded.time >= views.time"
)
"""The last view of a recording and frame: the camera pose (world frame) and the support plane (camera frame)."""


class _Candidate:
    """A stored candidate row as the association sees it (position, size, histogram, class, world, colour): its
    supports unpacked only when read (a colour asked for, or the row updated), the ``ObjectBelief`` decoded only when
    the general update path needs it."""

    __slots__ = (
        "_records",
        "appearance",
        "class_name",
        "dimensions",
        "frame",
        "id",
        "position",
        "recording",
        "row",
        "update",
    )

    def __init__(self, row: tuple, update: RowUpdate) -> None:
        self.row = row
        self.update = update
        self._records: list[Support] | None = None
        self.id: int = row[0]
        self.class_name: str | None = row[1]
        self.frame: str = row[2]
        self.position = row[3:6]
        self.dimensions = None if row[10] is None else row[10:13]
        appearance = row[14]
        self.appearance = None if appearance is None else np.frombuffer(appearance, dtype=np.float32).astype(np.float64)
        self.recording: str = row[23]

    @property
    def records(self) -> list[Support]:
        """The row's supports (:meth:`RowUpdate.supports`), unpacked on first read."""
        records = self._records
        if records is None:
            records = self._records = self.update.supports(self.row)
        return records

    def value(self, attribute: str) -> str | None:
        """``ObjectBelief.value(attribute)`` of the stored belief."""
        found = [r for r in self.records if r[7] == attribute]
        if len(found) == 1:
            return found[0][8]
        return self.belief().value(attribute) if found else None

    def belief(self) -> ObjectBelief:
        """The stored belief, decoded."""
        return _belief_from_row(self.row, self.update.interned, self.update.conn)


class BeliefStore:
    """Object beliefs persisted in one SQLite file (see the module docstring).

    One instance holds one connection and may be shared between threads; open another instance (in this or
    another process) for concurrent reading.
    """

    def __init__(
        self,
        path: str | Path,
        *,
        tracker: BeliefTracker | None = None,
        synchronous: str = "NORMAL",
        busy_timeout: float = 10.0,
        check: bool = True,
        history_limit: int = 100,
        write_behind: int = 0,
    ) -> None:
        self.path = Path(path).expanduser()
        if synchronous.upper() not in SYNCHRONOUS_MODES:
            raise ValueError(f"synchronous must be one of {', '.join(SYNCHRONOUS_MODES)}, not {synchronous!r}")
        self.tracker = tracker or BeliefTracker()
        self.history_limit = history_limit
        self.write_log: list[list[tuple[str, list[tuple]]]] | None = None
        """When a list, each :meth:`integrate` appends the statements it wrote, with their rows (benchmarks)."""
        self._sources_text: dict[frozenset[str], str] = {}
        """JSON of the expert sets written (few distinct sets recur on every row)."""
        self._views: dict[tuple[object, tuple], object] = {}
        """What :meth:`query_views` made, by (view, stored row)."""
        self._class_ways: dict[tuple[int, str, ClassTest | None], tuple[list[str], list[str]]] = {}
        """(known classes, asked class, class test) -> the classes answering it and those more general
        (:meth:`_answering_classes`)."""
        self._interned = InternedTexts()
        """The codes of the attribute names, values and expert sets in the packed supports."""
        self._row_updates: RowUpdate | None = None
        """The row-level update of :meth:`integrate`, for the last tracker configuration."""
        if not 0 <= write_behind <= MAX_WRITE_BEHIND:
            raise ValueError(
                f"write_behind must be 0 (off) or a number of frames up to {MAX_WRITE_BEHIND}, not {write_behind}"
            )
        self.write_behind = write_behind
        """Frames :meth:`integrate` may return before they are committed (0: each is committed before it returns)."""
        self._pending = PendingFrames()
        """The frames fused and handed to the writer process but not known to be committed (write-behind)."""
        self._writer: FrameWriter | None = None
        self._frames_sent = 0
        self._settings = (synchronous.upper(), busy_timeout)
        self._lock = threading.RLock()
        self._conn = self._open(synchronous.upper(), busy_timeout, check)
        if write_behind:  # started with the store, as its connection is (later ones start when a frame needs them)
            try:
                self._writer = FrameWriter(self.path, synchronous.upper(), busy_timeout, WAL_AUTOCHECKPOINT_PAGES)
            except BaseException:
                self._conn.close()  # no store was made: nothing else would ever close its connection
                raise

    # ------------------------------------------------------------------ opening

    def _open(self, synchronous: str, busy_timeout: float, check: bool) -> sqlite3.Connection:
        path = self.path
        if path.is_dir():
            raise BeliefStoreError(f"belief store {path} is a directory, not a file")
        existed = path.exists() and path.stat().st_size > 0
        if existed:
            with path.open("rb") as handle:
                header = handle.read(len(SQLITE_HEADER))
            if header != SQLITE_HEADER:
                raise BeliefStoreError(_corrupt_message(path, "it is not an SQLite database"))
        else:
            path.parent.mkdir(parents=True, exist_ok=True)
        conn = sqlite3.connect(path, timeout=busy_timeout, isolation_level=None, check_same_thread=False)
        try:
            conn.execute(f"PRAGMA busy_timeout = {int(busy_timeout * 1000)}")
            if existed and check:
                rows = conn.execute("PRAGMA quick_check(20)").fetchall()
                result = [line for row in rows for line in row[0].splitlines() if not line.startswith("***")]
                if result != ["ok"]:
                    detail = f"integrity check failed: {result[0]!r}" + (
                        f" and {len(result) - 1} more problem(s)" if len(result) > 1 else ""
                    )
                    raise BeliefStoreError(_corrupt_message(path, detail))
            version = self._check_schema(conn) if existed else None
            ready = version == SCHEMA_VERSION
            mode = conn.execute("PRAGMA journal_mode = WAL").fetchone()[0]
            if str(mode).lower() != "wal":
                raise BeliefStoreError(f"belief store {path}: cannot use WAL journal mode (got {mode})")
            conn.execute(f"PRAGMA synchronous = {synchronous}")
            conn.execute(f"PRAGMA wal_autocheckpoint = {WAL_AUTOCHECKPOINT_PAGES}")
            if not ready:  # a store in use is opened without writing, so readers never wait for the writer
                conn.execute("BEGIN IMMEDIATE")
                self._migrate(conn)
                for statement in _SCHEMA:
                    conn.execute(statement)
                if version is not None and version < 4:  # a guessed class is found from memory (class_candidates)
                    conn.execute(f"INSERT OR IGNORE INTO classes {GUESSED_CLASSES}", (CLASS_ATTRIBUTE,))
                conn.execute("INSERT OR IGNORE INTO meta VALUES ('schema', ?)", (SCHEMA_NAME,))
                conn.execute("INSERT OR REPLACE INTO meta VALUES ('version', ?)", (str(SCHEMA_VERSION),))
                conn.execute("INSERT OR IGNORE INTO meta VALUES ('next_id', '1')")
                conn.execute("COMMIT")
        except BeliefStoreError:
            conn.close()
            raise
        except sqlite3.DatabaseError as error:
            conn.close()
            if getattr(error, "sqlite_errorname", "") in _CORRUPT_ERRORS or not isinstance(
                error, sqlite3.OperationalError
            ):
                raise BeliefStoreError(_corrupt_message(path, str(error))) from error
            raise BeliefStoreError(f"belief store {path}: {error}") from error
        return conn

    def _check_schema(self, conn: sqlite3.Connection) -> int | None:
        """The version of the complete belief store the file holds (None when empty or incomplete); raises when
        it holds another thing or a newer version."""
        tables = {row[0] for row in conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        if not tables:
            return None
        meta = dict(conn.execute("SELECT key, value FROM meta").fetchall()) if "meta" in tables else {}
        if meta.get("schema") != SCHEMA_NAME:
            raise BeliefStoreError(_corrupt_message(self.path, "it is an SQLite database but not a belief store"))
        version = int(meta.get("version", "0"))
        if version > SCHEMA_VERSION:
            raise BeliefStoreError(
                f"belief store {self.path} has schema version {version}, newer than this robokudo "
                f"({SCHEMA_VERSION}); upgrade robokudo or use another store path"
            )
        required = _TABLES | _VIEW_TABLES if version >= 5 else _TABLES
        return version if "next_id" in meta and tables >= required else None

    @staticmethod
    def _migrate(conn: sqlite3.Connection) -> None:
        """Bring the tables of an older store up to :data:`SCHEMA_VERSION` (inside the caller's transaction)."""
        tables = {row[0] for row in conn.execute("SELECT name FROM sqlite_master WHERE type = 'table'")}
        if "meta" not in tables:
            return
        found = conn.execute("SELECT value FROM meta WHERE key = 'version'").fetchone()
        version = int(found[0]) if found is not None else SCHEMA_VERSION
        for step in range(version, SCHEMA_VERSION):
            for statement in MIGRATIONS[step]:
                table = statement.split()[2]
                column = statement.split()[5]
                present = {row[1] for row in conn.execute(f"PRAGMA table_info({table})")}
                if table in tables and column not in present:
                    conn.execute(statement)
        if version < 3 and "objects" in tables:
            _pack_attribute_column(conn)

    @staticmethod
    def default_path() -> Path:
        """``$ROBOKUDO_BELIEF_STORE`` or ``<user data dir>/robokudo/beliefs.sqlite``."""
        override = os.environ.get("ROBOKUDO_BELIEF_STORE")
        if override:
            return Path(override).expanduser()
        return Path(platformdirs.user_data_dir("robokudo")) / "beliefs.sqlite"

    def close(self) -> None:
        """Commit the pending frames (write-behind), end the writer and close the connection (idempotent); a failed
        pending frame raises here, after everything is closed."""
        with self._lock:
            try:
                self.flush()
            finally:
                if self._writer is not None:
                    self._writer.close()
                    self._writer = None
                self._conn.close()

    def flush(self) -> None:
        """Wait until every frame :meth:`integrate` has returned is committed (a no-op unless ``write_behind``).

        Raises the error of a pending frame whose write failed (that frame and those fused after it are not stored;
        every frame before it is)."""
        with self._lock:
            while self._pending:
                self._settle()

    def _settle(self) -> None:
        """Wait for the writer's answer on the oldest pending frame. A failed frame empties the pending frames, ends
        the writer and raises its error."""
        writer = self._writer
        if writer is None or not self._pending:
            return
        try:
            seq, failure = writer.answer()
        except WriterGoneError as gone:
            self._abandon()
            raise BeliefStoreError(f"belief store {self.path}: {gone}; the pending frames were not stored") from gone
        if failure is None:
            self._pending.committed(seq)
            return
        lost = len(self._pending)
        self._abandon()
        kind, message = failure
        error_class = getattr(sqlite3, kind, sqlite3.DatabaseError)
        if not (isinstance(error_class, type) and issubclass(error_class, sqlite3.Error)):
            error_class = sqlite3.DatabaseError
        raise error_class(
            f"belief store {self.path}: writing a fused frame failed ({message}); it and the {lost - 1} frame(s) "
            "fused after it were not stored, every earlier frame was"
        )

    def _abandon(self) -> None:
        """Drop the pending frames and end the writer (after a failure; the next frame starts a new one)."""
        self._pending.clear()
        writer, self._writer = self._writer, None
        if writer is not None:
            writer.close()

    def __enter__(self) -> BeliefStore:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()

    # ------------------------------------------------------------------ transactions

    @contextmanager
    def _guard(self, drain: bool = True) -> Iterator[sqlite3.Connection]:
        """Hold the lock and turn corruption found while running into a BeliefStoreError; with ``drain``, first wait
        for the pending frames (every read and write but :meth:`integrate` sees each frame integrated before it)."""
        with self._lock:
            try:
                if drain and self._pending:
                    self.flush()
                yield self._conn
            except sqlite3.DatabaseError as error:
                if getattr(error, "sqlite_errorname", "") in _CORRUPT_ERRORS:
                    raise BeliefStoreError(_corrupt_message(self.path, str(error))) from error
                raise

    @contextmanager
    def _transaction(self) -> Iterator[sqlite3.Connection]:
        with self._guard() as conn:
            conn.execute("BEGIN IMMEDIATE")
            try:
                yield conn
                conn.execute("COMMIT")
            except BaseException:
                self._interned.forget()  # it may hold codes the rollback undoes
                if conn.in_transaction:
                    conn.execute("ROLLBACK")
                raise

    # ------------------------------------------------------------------ writing

    def integrate(
        self,
        objects: Sequence[FrameObject],
        time: float,
        *,
        camera: CameraModel | None = None,
        plane: Sequence[float] | None = None,
        tracker: BeliefTracker | None = None,
        wait: bool = False,
    ) -> TrackStep:
        """Fuse one frame's objects into the store in one transaction and record the observations.

        Beliefs near the observations (and, with ``camera``, in front of it) are loaded, associated and
        updated by the tracker; new objects get new ids; the changes and the sightings are written. Beliefs
        missed earlier and not seen for the tracker's ``gone_after`` seconds are marked gone, wherever they are.
        With ``camera``, the view is recorded as the last of its recording and frame: the camera pose (world frame)
        and ``plane``, the support plane ``(a, b, c, d)`` in the camera frame (None: none found), from which a
        selection from memory measures (:meth:`viewpoints`).

        With the plain :class:`BeliefTracker` (no named regions) the step runs on the stored rows: matched beliefs in
        the common case are updated on their rows (:mod:`reasoning.beliefs.row_update`) and the step's ``changed``
        makes their ``ObjectBelief`` only when read; results are those of ``tracker.step`` on decoded beliefs.

        With ``write_behind`` the frame's transaction is committed by the writer process while the caller goes on
        (:mod:`reasoning.beliefs.frame_writer`); the call returns with at most ``write_behind`` frames uncommitted,
        or none with ``wait``. Every other method first waits for them; a failed write raises on the next call.
        """
        tracker = tracker or self.tracker
        if self.write_behind:
            step = self._integrate_behind(objects, time, camera, tracker, plane)
            if wait:
                self.flush()
            return step
        writes: list[tuple[str, list[tuple]]] = []
        with self._transaction() as conn:
            next_id = int(conn.execute(NEXT_ID).fetchone()[0])
            write = functools.partial(_write, conn, writes)
            step, *_ = self._fuse(conn, objects, time, camera, tracker, next_id, write, writes, None, plane)
        if self.write_log is not None:
            self.write_log.append(writes)
        return step

    def _integrate_behind(
        self,
        objects: Sequence[FrameObject],
        time: float,
        camera: CameraModel | None,
        tracker: BeliefTracker,
        plane: Sequence[float] | None = None,
    ) -> TrackStep:
        """:meth:`integrate` with the frame's writes handed to the writer process: the candidate rows are read from
        the committed store through the overlay of the pending frames (:mod:`reasoning.beliefs.pending`)."""
        pending = self._pending
        writes: list[tuple[str, list[tuple]]] = []
        with self._guard(drain=False) as conn:
            next_id = pending.next_id if pending else int(conn.execute(NEXT_ID).fetchone()[0])
            write = functools.partial(_write_behind, conn, writes)
            step, written, loaded, moved, after = self._fuse(
                conn, objects, time, camera, tracker, next_id, write, writes, pending if pending else None, plane
            )
            stored_moves = {entry[0]: entry for entry in rtree_bounds(moved)}
            rows = entries_of(written, stored_moves, loaded, _COLUMN_COUNT)
            if self._writer is None:
                synchronous, busy_timeout = self._settings
                self._writer = FrameWriter(self.path, synchronous, busy_timeout, WAL_AUTOCHECKPOINT_PAGES)
            self._frames_sent += 1
            try:
                self._writer.send(self._frames_sent, next_id, writes)
            except WriterGoneError as gone:
                self._abandon()
                raise BeliefStoreError(f"belief store {self.path}: {gone}; this frame and the pending ones were not "
                                       "stored") from gone  # fmt: skip
            pending.add(PendingFrame(self._frames_sent, rows, time - tracker.config.gone_after, after))
            while len(pending) > self.write_behind:  # answers are taken here only: the overlay is always in use
                self._settle()
        if self.write_log is not None:
            self.write_log.append(writes)
        return step

    def _fuse(
        self,
        conn: sqlite3.Connection,
        objects: Sequence[FrameObject],
        time: float,
        camera: CameraModel | None,
        tracker: BeliefTracker,
        next_id: int,
        write: Callable[[str, list[tuple]], None],
        writes: list[tuple[str, list[tuple]]],
        pending: PendingFrames | None,
        plane: Sequence[float] | None = None,
    ) -> tuple[TrackStep, list[tuple], dict[int, tuple], list[tuple], int]:
        """The step of one frame and its writes (through ``write``, into ``writes``), new ids from ``next_id``.
        Returns the step, the object rows written, the candidate rows by id (with their R*Tree entries), the R*Tree
        entries rewritten and ``meta.next_id`` after the frame."""
        rows, loaded = self._candidates(conn, objects, camera, tracker.config.association.gate_distance, pending)
        allocated = [next_id]

        def new_id() -> int:
            value = allocated[0]
            allocated[0] += 1
            return value

        moved: list[tuple] = []
        if RowUpdate.applies(tracker):
            step, updated = self._step_on_rows(conn, tracker, rows, objects, time, new_id, camera)
            cache = self._sources_cache()
            update = self._row_update(tracker)
            written = [
                _object_row(made, tracker.class_test, cache, self._interned, conn, write)
                if isinstance(made, ObjectBelief)
                else update.pack(made[0], made[1], write)
                for made in updated
            ]
            self._write_rows(conn, written, loaded, writes, write, moved)
        else:
            beliefs = [_belief_from_row(row, self._interned, conn) for row in rows]
            step = tracker.step(beliefs, objects, time, new_id, camera)
            written = self._write_beliefs(conn, step.changed, tracker.class_test, loaded, writes, write, moved)
        counts = {row[0]: row[20] for row in written}
        self._write_observations(conn, objects, [(i, counts.get(i, 0)) for i in step.assigned], time, write)
        if allocated[0] != next_id:
            write("UPDATE meta SET value = ? WHERE key = 'next_id'", [(str(allocated[0]),)])
        seen = set(step.assigned)
        self._prune_history([(row[0], row[20]) for row in written if row[0] in seen], write)
        # beliefs missed earlier and not seen since, wherever they are, are gone after gone_after seconds
        write(_MARK_GONE, [(time - tracker.config.gone_after,)])
        if camera is not None:
            write(_RECORD_VIEW, [_view_row(camera, time, plane)])
        return step, written, loaded, moved, allocated[0]

    def _row_update(self, tracker: BeliefTracker) -> RowUpdate:
        """The row-level update for ``tracker`` (one per tracker configuration, kept while it is the same)."""
        current = self._row_updates
        if current is None or current.config is not tracker.config:
            current = self._row_updates = RowUpdate(tracker, self._interned, self._conn)
        return current

    def _step_on_rows(
        self,
        conn: sqlite3.Connection,
        tracker: BeliefTracker,
        rows: Sequence[tuple],
        objects: Sequence[FrameObject],
        time: float,
        new_id: Callable[[], int],
        camera: CameraModel | None,
    ) -> tuple[TrackStep, list[ObjectBelief | tuple[tuple, list[Support]]]]:
        """``tracker.step`` on the stored candidate rows: the same association (on light views of the rows), the
        same updates, creations, misses and departures, with matched beliefs in the common case updated on their
        rows and new ones in the common case made as rows (:mod:`reasoning.beliefs.row_update`; their
        ``ObjectBelief`` made only when the step's ``changed`` is read). Returns the step and each changed belief:
        the belief, or its new row and supports when it was updated or made as a row."""
        update = self._row_update(tracker)
        candidates = [_Candidate(row, update) for row in rows]
        association = tracker.associate(objects, candidates)
        changed: dict[int, ObjectBelief | tuple[tuple, list[Support]]] = {}
        makers: dict[int, ObjectBelief | Callable[[], ObjectBelief]] = {}
        assigned = [0] * len(objects)
        for i, j, _ in association.matches:
            candidate, observation = candidates[j], objects[i]
            records = candidate.records
            row = update.update(candidate.row, records, observation, time)
            if row is not None:
                changed[candidate.id] = (row, records)
                makers[candidate.id] = functools.partial(belief_of, row, records, observation.roi)
            else:
                belief = candidate.belief()
                tracker.update(belief, observation, time)
                changed[candidate.id] = makers[candidate.id] = belief
            assigned[i] = candidate.id
        created = []
        for i in association.new:
            observation = objects[i]
            if observation.doubt:
                continue
            belief_id = new_id()
            made = update.create(observation, time, belief_id)
            if made is not None:
                changed[belief_id] = made
                makers[belief_id] = functools.partial(belief_of, made[0], made[1], observation.roi)
            else:
                changed[belief_id] = makers[belief_id] = tracker.create(observation, time, belief_id)
            assigned[i] = belief_id
            created.append(belief_id)
        missed, gone = [], []
        for j in association.unmatched:
            candidate = candidates[j]
            if camera is None and not candidate.row[19]:
                continue  # neither in view nor missed before: unchanged
            belief = candidate.belief()
            was_missed, is_gone = tracker.unseen(belief, time, camera)
            if was_missed:
                missed.append(belief.id)
            if is_gone:
                gone.append(belief.id)
            if was_missed or is_gone:
                changed[belief.id] = makers[belief.id] = belief
        step = TrackStep(
            ChangedBeliefs(makers.values()), tuple(assigned), tuple(created), tuple(missed), tuple(gone), association
        )
        return step, list(changed.values())

    def put(self, beliefs: Sequence[ObjectBelief], class_test: ClassTest | None = None) -> None:
        """Write beliefs as they are (insert or replace, attributes included) in one transaction."""
        with self._transaction() as conn:
            self._write_beliefs(conn, beliefs, class_test)
            top = max((b.id for b in beliefs), default=0) + 1
            conn.execute(
                "UPDATE meta SET value = CAST(MAX(CAST(value AS INTEGER), ?) AS TEXT) WHERE key = 'next_id'", (top,)
            )

    def allocate_ids(self, count: int) -> list[int]:
        """Reserve ``count`` fresh object ids (ids are never reused, not even after :meth:`clear`)."""
        with self._transaction() as conn:
            first = int(conn.execute("SELECT value FROM meta WHERE key = 'next_id'").fetchone()[0])
            conn.execute("UPDATE meta SET value = ? WHERE key = 'next_id'", (str(first + count),))
        return list(range(first, first + count))

    def clear(self) -> int:
        """Forget every belief and its history; returns how many beliefs there were."""
        with self._transaction() as conn:
            count = int(conn.execute("SELECT COUNT(*) FROM objects").fetchone()[0])
            for table in ("objects", "objects_place", "attribute_index", "observations", "classes", "views"):
                conn.execute(f"DELETE FROM {table}")
        return count

    def forget(self, ids: Sequence[int]) -> int:
        """Forget the beliefs ``ids`` and their history (unknown ids are skipped); returns how many were forgotten."""
        rows = [(int(i),) for i in set(ids)]
        with self._transaction() as conn:
            count = conn.executemany("DELETE FROM objects WHERE id = ?", rows).rowcount
            conn.executemany("DELETE FROM objects_place WHERE id = ?", rows)
            conn.executemany("DELETE FROM attribute_index WHERE object_id = ?", rows)
            conn.executemany("DELETE FROM observations WHERE object_id = ?", rows)
        return count

    def _candidates(
        self,
        conn: sqlite3.Connection,
        objects: Sequence[FrameObject],
        camera: CameraModel | None,
        gate: float,
        pending: PendingFrames | None = None,
    ) -> tuple[list[tuple], dict[int, tuple]]:
        """The rows of the present beliefs within ``gate`` of an observation or in view of ``camera`` (R*Tree
        look-ups), by id; with ``pending``, as they are once its frames are committed (:meth:`PendingFrames.overlaid`).

        Also returns each row by id with its R*Tree entry after its columns, so unchanged R*Tree entries and index
        columns are not rewritten.
        """
        rows: dict[int, tuple] = {}
        groups: dict[tuple[str, str], list[FrameObject]] = {}
        for item in objects:
            groups.setdefault((item.frame, item.recording), []).append(item)
        for (frame, recording), members in groups.items():
            # one statement per world: the union of the R*Tree boxes around its observations
            centres = np.array([item.position[:3] for item in members], dtype=np.float64)
            bounds = np.empty((len(members), 6))
            bounds[:, 0::2] = centres + gate  # x1, y1, z1 of each box, then x0, y0, z0 in between
            bounds[:, 1::2] = centres - gate
            parameters = bounds.ravel().tolist()
            found = conn.execute(_candidate_query(len(members)), (*parameters, frame, WORLD_FRAME, recording, PRESENT))
            found = found.fetchall()
            if pending is not None:
                found = pending.overlaid(found, bounds, frame, WORLD_FRAME, recording)
            if not found:
                continue
            positions = np.array([row[3:6] for row in found], dtype=np.float64)
            delta = positions[:, None, :] - centres[None, :, :]
            near = (np.sqrt(np.einsum("ijk,ijk->ij", delta, delta)) <= gate).any(axis=1)
            for row, keep in zip(found, near.tolist(), strict=True):
                if keep:
                    rows[row[0]] = row
        if camera is not None:
            low, high = _frustum_bounds(camera)
            world = (camera.frame, WORLD_FRAME, camera.recording)
            box = (high[0], low[0], high[1], low[1], high[2], low[2])
            found = conn.execute(_candidate_query(1), (*box, *world, PRESENT)).fetchall()
            if pending is not None:
                found = pending.overlaid(found, np.array(box), *world)
            in_frustum = [row for row in found if row[0] not in rows]
            if in_frustum:
                positions = np.array([(row[3], row[4], row[5]) for row in in_frustum], dtype=np.float64)
                for row, seen in zip(in_frustum, in_view(positions, camera), strict=True):
                    if seen:
                        rows[row[0]] = row
        return [rows[i] for i in sorted(rows)], rows

    def _write_beliefs(
        self,
        conn: sqlite3.Connection,
        beliefs: Sequence[ObjectBelief],
        class_test: ClassTest | None,
        loaded: Mapping[int, tuple] | None = None,
        writes: list[tuple[str, list[tuple]]] | None = None,
        write: Callable[[str, list[tuple]], None] | None = None,
        moved: list[tuple] | None = None,
    ) -> list[tuple]:
        """Write the object rows of ``beliefs`` (:meth:`_write_rows`; with ``write``, through it, else run on
        ``conn`` and noted in ``writes``); returns the rows written."""
        if not beliefs:
            return []
        if write is None:
            write = functools.partial(_write, conn, [] if writes is None else writes)
        cache = self._sources_cache()
        latest = {b.id: b for b in beliefs}  # a belief given twice is written as its last object is
        written = beliefs if len(latest) == len(beliefs) else [latest[b.id] for b in beliefs]
        rows = [_object_row(b, class_test, cache, self._interned, conn, write) for b in written]
        self._write_rows(conn, rows, loaded, writes, write, moved)
        return rows

    def _write_rows(
        self,
        conn: sqlite3.Connection,
        rows: Sequence[tuple],
        loaded: Mapping[int, tuple] | None,
        log: list[tuple[str, list[tuple]]] | None,
        write: Callable[[str, list[tuple]], None] | None = None,
        moved_out: list[tuple] | None = None,
    ) -> None:
        """Write object rows, their R*Tree entries and attribute-index entries (through ``write``, else run on
        ``conn`` and noted in ``log``); the R*Tree entries rewritten are added to ``moved_out``.

        ``loaded`` holds the stored rows of beliefs as the candidate search read them (their columns, then their
        R*Tree entry: x0, x1, y0, y1, z0, z1); those beliefs are updated in place, their indexed columns and index
        entries touched only when they changed. The R*Tree entry of a belief is a box of half-width
        ``RTREE_SLACK`` around a recent position; it is rewritten only when the belief has moved more than half of
        that from the entry's centre, so the true position always lies inside the entry and look-ups by position
        miss nothing.
        """
        if not rows:
            return
        if write is None:
            write = functools.partial(_write, conn, [] if log is None else log)
        loaded = loaded or {}
        fresh: list[tuple] = []
        volatile: list[tuple] = []
        relabelled: list[tuple] = []
        added: list[tuple[str, str, int]] = []
        removed: list[tuple[str, str, int]] = []
        moved: list[tuple] = []
        classes: set[tuple[str]] = set()
        r = RTREE_SLACK
        n = _COLUMN_COUNT  # a loaded row's R*Tree entry: x0, x1, y0, y1, z0, z1 after its columns
        for row in rows:  # one pass: each statement's rows in belief order
            belief_id = row[0]
            state = loaded.get(belief_id)
            indexed = row[_INDEXED]
            if state is None:
                fresh.append(row)
                old: set[tuple[str, str]] = set()
            else:
                volatile.append(_volatile(row))
                labels = _labels(row)
                if labels != _labels(state):
                    relabelled.append((*labels, belief_id))
                old = _index_entries(state[_INDEXED]) if state[_INDEXED] != indexed else set()
            if state is None or state[_INDEXED] != indexed:
                new = _index_entries(indexed)
                added.extend((name, value, belief_id) for name, value in new - old)
                removed.extend((name, value, belief_id) for name, value in old - new)
                # a leading class below 0.5 is indexed too: a query for it finds the belief as a candidate
                classes.update((value,) for name, value in new - old if name == CLASS_ATTRIBUTE)
            x, y, z = row[3:6]
            if (
                state is None
                or max(
                    abs(x - (state[n] + state[n + 1]) / 2),
                    abs(y - (state[n + 2] + state[n + 3]) / 2),
                    abs(z - (state[n + 4] + state[n + 5]) / 2),
                )
                > RTREE_SLACK / 2
            ):
                moved.append((belief_id, x - r, x + r, y - r, y + r, z - r, z + r))
            class_name = row[1]
            if class_name and class_name != (state[1] if state is not None else None):
                classes.add((class_name,))
        if fresh:
            write("DELETE FROM attribute_index WHERE object_id = ?", [(row[0],) for row in fresh])
            write(f"INSERT OR REPLACE INTO objects ({_OBJECT_COLUMNS}) VALUES ({_PLACEHOLDERS})", fresh)
        if volatile:
            write(_UPDATE_VOLATILE, volatile)
            if relabelled:
                write(
                    "UPDATE objects SET class_name = ?, region = ?, region_class = ?, indexed = ? WHERE id = ?",
                    relabelled,
                )
        if removed:
            write("DELETE FROM attribute_index WHERE name = ? AND value = ? AND object_id = ?", removed)
        if added:
            write("INSERT OR IGNORE INTO attribute_index VALUES (?, ?, ?)", added)
        if moved:
            if moved_out is not None:
                moved_out.extend(moved)
            write("INSERT OR REPLACE INTO objects_place VALUES (?, ?, ?, ?, ?, ?, ?)", moved)
        if classes:
            write("INSERT OR IGNORE INTO classes VALUES (?)", list(classes))

    def _write_observations(
        self,
        conn: sqlite3.Connection,
        objects: Sequence[FrameObject],
        assigned: Sequence[tuple[int, int]],
        time: float,
        write: Callable[[str, list[tuple]], None],
    ) -> None:
        """Record each object's sighting under (belief id, its sighting number), its statements packed
        (:data:`STATEMENT`), through ``write``."""
        cache = self._sources_cache()
        interned = self._interned
        rows = [
            (
                object_id,
                seq,
                time,
                item.frame,
                *floats(item.position, 3),
                roi_text(item.roi),
                _encoded_sources(item.sources, cache),
                _pack_evidence(item.evidence, interned, conn, write),
                item.recording,
            )
            for item, (object_id, seq) in zip(objects, assigned, strict=True)
            if object_id
        ]
        if rows:
            write(
                "INSERT OR REPLACE INTO observations (object_id, seq, time, frame, px, py, pz, roi, sources, evidence, "
                "recording) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)",
                rows,
            )

    def _sources_cache(self) -> dict[frozenset[str], str]:
        """The cache of encoded expert sets, emptied when it grows past :data:`SOURCES_CACHE_LIMIT` entries."""
        if len(self._sources_text) > SOURCES_CACHE_LIMIT:
            self._sources_text.clear()
        return self._sources_text

    def _prune_history(self, seen: Sequence[tuple[int, int]], write: Callable[[str, list[tuple]], None]) -> None:
        """Drop the oldest sightings of the ``seen`` (belief id, sightings) beyond ``history_limit`` (every 16th)."""
        limit = self.history_limit
        due = [(i, count - limit) for i, count in seen if count > limit and count % 16 == 0]
        if due:
            write("DELETE FROM observations WHERE object_id = ? AND seq <= ?", due)

    # ------------------------------------------------------------------ reading

    def get(self, object_id: int) -> ObjectBelief | None:
        """One belief by id (gone or not), or None."""
        with self._guard() as conn:
            rows = conn.execute(f"SELECT {_OBJECT_COLUMNS} FROM objects WHERE id = ?", (object_id,)).fetchall()
            found = [_belief_from_row(row, self._interned, conn) for row in rows]
        return found[0] if found else None

    def beliefs(self, include_gone: bool = False) -> list[ObjectBelief]:
        """All beliefs (present ones unless ``include_gone``), by id."""
        return self.query(BeliefFilter(include_gone=include_gone))

    def count(self, include_gone: bool = True) -> int:
        """How many beliefs are stored."""
        with self._guard() as conn:
            if include_gone:
                return int(conn.execute("SELECT COUNT(*) FROM objects").fetchone()[0])
            return int(conn.execute("SELECT COUNT(*) FROM objects WHERE status = ?", (PRESENT,)).fetchone()[0])

    def query(self, belief_filter: BeliefFilter) -> list[ObjectBelief]:
        """The beliefs matching ``belief_filter`` (class subsumption, region, attributes), by id; a ``limit`` keeps
        the first by id (answers rank before they cut: :mod:`reasoning.beliefs.ranking`)."""
        rows = self._select(belief_filter)
        with self._guard() as conn:
            return [_belief_from_row(row, self._interned, conn) for row in rows]

    def query_views(self, belief_filter: BeliefFilter, view: Callable[[ObjectBelief], T]) -> list[T]:
        """``view(belief)`` of each belief :meth:`query` gives, by id, remembered per stored row.

        A row unchanged since an earlier call gives the earlier result (the stored row is the key, so a change by
        any writer makes a new one). ``view`` must be a pure function of the belief and the same function object
        on every call (e.g. a module-level function); its results are shared between calls: never change them.
        At most :data:`VIEW_CACHE_LIMIT` rows are remembered (beyond that the memo starts afresh).
        """
        rows = self._select(belief_filter)
        with self._guard() as conn:
            memo = self._views
            if len(memo) > VIEW_CACHE_LIMIT:
                memo.clear()
            found: list[T] = []
            for row in rows:
                key = (view, row)
                made = memo.get(key)
                if made is None:
                    made = memo[key] = view(_belief_from_row(row, self._interned, conn))
                found.append(made)  # type: ignore[arg-type]
            return found

    def _select(self, belief_filter: BeliefFilter) -> list[tuple]:
        """The ``objects`` rows of the beliefs matching ``belief_filter``, by id (see :meth:`query`)."""
        clauses: list[str] = []
        parameters: list[object] = []
        f = belief_filter
        with self._guard() as conn:
            if not f.include_gone:
                clauses.append("status = ?")
                parameters.append(PRESENT)
            if f.ids is not None:
                if not f.ids:
                    return []
                clauses.append(f"id IN ({', '.join('?' * len(f.ids))})")
                parameters.extend(f.ids)
            # the class a query asks for, each way a belief answers to it (:func:`candidate_class_clauses`)
            class_ways: list[tuple[str, list[object], str]] = [("", [], "")]
            if f.object_class:
                classes, general = self._answering_classes(conn, f.object_class, f.class_test)
                if not classes:
                    return []
                class_ways = candidate_class_clauses(
                    classes, narrowed=bool(f.region) or f.ids is not None, general=general
                )
            texts = {name: value for name, value in f.attributes.items() if name == Text.attribute}
            for name, value in f.attributes.items():
                if name in texts:
                    continue  # read text is matched word by word below, tolerating OCR errors
                wanted = _alternatives(value)
                marks = ", ".join("?" * len(wanted))
                # with a class filter, check each candidate; without one, start from the attribute's objects
                clauses.append(
                    f"EXISTS (SELECT 1 FROM attribute_index a WHERE a.name = ? AND a.value IN ({marks}) "
                    "AND a.object_id = id)"
                    if f.object_class
                    else f"id IN (SELECT object_id FROM attribute_index WHERE name = ? AND value IN ({marks}))"
                )
                parameters.extend([name, *wanted])
            # one SELECT per way of being in the region (by stored name, or inside a box), united
            branches: list[tuple[list[str], list[object]]] = [([], [])]
            if f.region:
                names = [f.region, *(box.name for box in f.region_boxes)]
                branches = [([f"region COLLATE NOCASE IN ({', '.join('?' * len(names))})"], list(names))]
                for box in f.region_boxes:
                    low, high = _box_bounds(box.pose, box.size)
                    branches.append(
                        (
                            [
                                "id IN (SELECT id FROM objects_place "
                                "WHERE x0 <= ? AND x1 >= ? AND y0 <= ? AND y1 >= ? AND z0 <= ? AND z1 >= ?)"
                            ],
                            [high[0], low[0], high[1], low[1], high[2], low[2]],
                        )
                    )
            selects, values = [], []
            # (class way, region branch) pairs: the region by name (or none) once per class way, read through the
            # class index; a box once, its objects' ids from the R*Tree, every class way tested per object
            either = " OR ".join(f"({clause})" for clause, _, _ in class_ways if clause)
            either_parameters = [value for _, way_parameters, _ in class_ways for value in way_parameters]
            pairs = [(clause, way_parameters, reading, *branches[0]) for clause, way_parameters, reading in class_ways]
            pairs += [(f"({either})" if either else "", either_parameters, BY_ID, *box) for box in branches[1:]]
            for class_clause, class_parameters, reading, extra, extra_parameters in pairs:
                where = " AND ".join(([class_clause] if class_clause else []) + clauses + extra)
                # without statistics SQLite may pick the region index and filter the class row by row; the class
                # index (class, region) answers both at once; a box starts from the R*Tree's ids (never from the
                # class index's beliefs without a supported class), a query by ids from them
                table = f"objects {reading}" if reading and f.ids is None else "objects"
                selects.append(f"SELECT {_OBJECT_COLUMNS} FROM {table}" + (f" WHERE {where}" if where else ""))
                values.extend(class_parameters + parameters + extra_parameters)
            rows = conn.execute(" UNION ".join(selects) + " ORDER BY id", values).fetchall()
            if f.region and f.region_boxes:
                rows = _in_named_region(rows, f)
            for name, value in texts.items():
                rows = [row for row in rows if any(_reads(row, name, wanted) for wanted in _alternatives(value))]
            if f.min_confidence > 0:
                rows = [row for row in rows if sigmoid(row[15]) >= f.min_confidence]
            if f.limit is not None:
                rows = rows[: f.limit]
            return rows

    def history(self, object_id: int, limit: int | None = None) -> list[ObservationRecord]:
        """The recorded sightings of one object, oldest first (the newest ``limit`` when given)."""
        with self._guard() as conn:
            rows = conn.execute(
                "SELECT object_id, time, frame, px, py, pz, roi, sources, evidence, recording FROM observations "
                "WHERE object_id = ? ORDER BY seq DESC LIMIT ?",
                (object_id, -1 if limit is None else limit),
            ).fetchall()
            records = [
                ObservationRecord(
                    object_id=row[0],
                    time=row[1],
                    frame=row[2],
                    position=(row[3], row[4], row[5]),
                    roi=roi_from_text(row[6]),
                    sources=tuple(json.loads(row[7])),
                    evidence=_unpack_evidence(row[8], self._interned, conn),
                    recording=row[9],
                )
                for row in rows
            ]
        records.reverse()
        return records

    def viewpoints(self, keys: Iterable[tuple[str, str]]) -> dict[tuple[str, str], Viewpoint]:
        """The view a belief of each ``(recording, frame)`` asked is measured from (those never seen are left out):
        in a camera frame, the last view of that recording and frame (its support plane); in the world frame, which
        all recordings with a camera pose share, the last view of any recording (its camera pose and support plane,
        the plane in that view's camera frame)."""
        wanted = sorted(set(keys))
        found: dict[tuple[str, str], Viewpoint] = {}
        with self._guard() as conn:
            for recording, frame in wanted:
                if frame == WORLD_FRAME:
                    row = conn.execute(
                        "SELECT pose, plane FROM views WHERE frame = ? ORDER BY time DESC LIMIT 1", (frame,)
                    ).fetchone()
                else:
                    row = conn.execute(
                        "SELECT pose, plane FROM views WHERE recording = ? AND frame = ?", (recording, frame)
                    ).fetchone()
                if row is not None:
                    found[(recording, frame)] = Viewpoint(
                        cam_to_world=None if row[0] is None else np.frombuffer(row[0], dtype="<f8").reshape(4, 4),
                        plane=None if row[1] is None else np.frombuffer(row[1], dtype="<f8"),
                    )
        return found

    def _answering_classes(
        self, conn: sqlite3.Connection, wanted: str, class_test: ClassTest | None
    ) -> tuple[list[str], list[str]]:
        """The stored class names answering a query for ``wanted`` and those more general than one of them
        (:func:`~reasoning.beliefs.class_candidates.general_classes`), remembered while the ``classes`` table (which
        only grows) keeps its size."""
        known = [row[0] for row in conn.execute("SELECT name FROM classes")]
        key = (len(known), wanted, class_test)
        found = self._class_ways.get(key)
        if found is None:
            if len(self._class_ways) > CLASS_WAYS_CACHE_LIMIT:
                self._class_ways.clear()
            test = class_test or (lambda a, b: a.lower() == b.lower())
            classes = _matching_classes(known, wanted, test)
            found = self._class_ways[key] = (classes, general_classes(known, classes, test))
        return found

    def integrity_check(self) -> str:
        """SQLite's ``PRAGMA integrity_check`` result (``"ok"`` when sound)."""
        with self._guard() as conn:
            return "; ".join(row[0] for row in conn.execute("PRAGMA integrity_check"))


def _matching_classes(known: Sequence[str], wanted: str, test: ClassTest) -> list[str]:
    """The ``known`` class names that answer a query for ``wanted`` (its stored spelling, or a class ``test``
    accepts for it)."""
    canonical = next((name for name in known if name.lower() == wanted.lower()), wanted)
    return [name for name in known if name == canonical or test(name, canonical)]


# ---------------------------------------------------------------------------------------- row mapping


_MARK_GONE = "UPDATE objects SET status = 'gone' WHERE misses > 0 AND status = 'present' AND last_seen <= ?"


def _write(conn: sqlite3.Connection, log: list[tuple[str, list[tuple]]], statement: str, rows: list[tuple]) -> None:
    """Run one write statement over ``rows`` and note it in ``log`` (what the benchmark's reference replays)."""
    conn.executemany(statement, rows)
    log.append((statement, rows))


def _write_behind(
    conn: sqlite3.Connection, log: list[tuple[str, list[tuple]]], statement: str, rows: list[tuple]
) -> None:
    """Note one write statement over ``rows`` in ``log`` for the writer process; texts to intern are interned at once
    on ``conn`` (committed on their own: the table is append-only and a code never changes, so the frame's reads know
    their codes; the writer's repetition of the statement then changes nothing)."""
    if statement == INTERN:
        conn.executemany(statement, rows)
    log.append((statement, rows))


def _view_row(camera: CameraModel, time: float, plane: Sequence[float] | None) -> tuple:
    """The ``views`` row of a frame seen by ``camera``: its recording and frame, the time, the camera pose (only in
    the world frame) and the support plane, as little-endian float64."""
    pose = np.asarray(camera.to_frame, dtype="<f8").tobytes() if camera.frame == WORLD_FRAME else None
    packed_plane = None if plane is None else np.asarray(plane, dtype="<f8").reshape(4).tobytes()
    return (camera.recording, camera.frame, float(time), pose, packed_plane)


@functools.lru_cache(maxsize=64)
def _candidate_query(boxes: int) -> str:
    """The present beliefs of one world whose R*Tree entries meet any of ``boxes`` boxes (one statement; its
    parameters: x1, x0, y1, y0, z1, z0 of each box, then the frame, the world frame, the recording, the status)."""
    box = "SELECT * FROM objects_place WHERE x0 <= ? AND x1 >= ? AND y0 <= ? AND y1 >= ? AND z0 <= ? AND z1 >= ?"
    columns = ", ".join(f"o.{c.strip()}" for c in _OBJECT_COLUMNS.split(","))
    return (
        f"WITH hit AS ({' UNION '.join([box] * boxes)}) "
        f"SELECT {columns}, hit.x0, hit.x1, hit.y0, hit.y1, hit.z0, hit.z1 FROM hit JOIN objects o ON o.id = hit.id "
        "WHERE o.frame = ? AND (o.frame = ? OR o.recording = ?) AND o.status = ?"
    )


def _object_row(
    b: ObjectBelief,
    class_test: ClassTest | None,
    sources: dict[frozenset[str], str],
    interned: InternedTexts,
    conn: sqlite3.Connection,
    write: Callable[[str, list[tuple]], None],
) -> tuple:
    """The ``objects`` row of a belief (columns as in ``_OBJECT_COLUMNS``); ``sources`` caches encodings, texts
    new to ``interned`` are interned with ``write`` (inside the caller's write transaction on ``conn``)."""
    x, y, z = floats(b.position, 3)
    qx, qy, qz, qw = floats(b.orientation, 4)
    sx, sy, sz = (None, None, None) if b.dimensions is None else floats(b.dimensions, 3)
    appearance = None if b.appearance is None else np.asarray(b.appearance, dtype=np.float32).tobytes()
    encoded, indexed = _pack_attributes(b.attributes, class_test, interned, conn, write)
    return (
        b.id,
        b.class_name,
        b.frame,
        x,
        y,
        z,
        qx,
        qy,
        qz,
        qw,
        sx,
        sy,
        sz,
        float(b.position_variance),
        appearance,
        float(b.existence),
        b.status,
        float(b.first_seen),
        float(b.last_seen),
        int(b.misses),
        int(b.observations),
        b.region,
        b.region_class,
        b.recording,
        roi_text(b.roi),
        _encoded_sources(b.sources, sources),
        encoded,
        indexed,
    )


_COLUMN_COUNT = len(_OBJECT_COLUMNS.split(","))
_INDEXED = _COLUMN_COUNT - 1
_LABEL_COLUMNS = (1, 21, 22, _INDEXED)
_VOLATILE_INDEXES = (*(i for i in range(1, _COLUMN_COUNT) if i not in _LABEL_COLUMNS), 0)
_VOLATILE_COLUMNS = tuple(_OBJECT_COLUMNS.split(",")[i].strip() for i in _VOLATILE_INDEXES[:-1])
_UPDATE_VOLATILE = f"UPDATE objects SET {', '.join(c + ' = ?' for c in _VOLATILE_COLUMNS)} WHERE id = ?"
_PLACEHOLDERS = ", ".join("?" * _COLUMN_COUNT)

_volatile = operator.itemgetter(*_VOLATILE_INDEXES)
"""The values of ``_VOLATILE_COLUMNS`` of an object row, then its id."""

_labels = operator.itemgetter(*_LABEL_COLUMNS)
"""The indexed columns of an object row: class, region, region class, attribute-index entries."""


def _encoded_sources(experts: set[str], cache: dict[frozenset[str], str]) -> str:
    key = frozenset(experts)
    found = cache.get(key)
    if found is None:
        found = cache[key] = json.dumps(sorted(key))
    return found


def _pack_attributes(
    attributes: Mapping[str, AttributeBelief],
    class_test: ClassTest | None,
    interned: InternedTexts,
    conn: sqlite3.Connection,
    write: Callable[[str, list[tuple]], None],
) -> tuple[bytes, str]:
    """The packed supports of every value (:data:`SUPPORT`, in the order of the attributes and their values) and
    the attribute-index entries (values more likely than not, or fused)."""
    codes = interned.codes
    expert_codes = interned.expert_codes
    flat: list = []
    entries: list[str] = []
    for name, attribute in attributes.items():
        values = attribute.values
        if not values:
            continue
        name_code = codes.get(name)
        if name_code is None:
            name_code = interned.code(conn, name, write)
        for value, s in values.items():
            value_code = codes.get(value)
            if value_code is None:
                value_code = interned.code(conn, value, write)
            experts = expert_codes.get(frozenset(s.sources))
            if experts is None:
                experts = interned.experts_code(conn, s.sources, write)
            log_odds = s.log_odds  # _rounded(log_odds, 9), inlined (four values per belief, every frame)
            rounded = rounded_cached(log_odds, 9) if log_odds else round(log_odds, 9)
            flat += (name_code, value_code, rounded, s.count, experts, s.first_seen, s.last_seen)
        if len(values) == 1:  # the common case: one value said, indexed
            entries.append(f"{name}={next(iter(values))}")
            continue
        fused = fuse_values(name, attribute.values, class_test if name == CLASS_ATTRIBUTE else None)
        entries.extend(f"{name}={s.value}" for s in fused.support if s.value == fused.value or s.confidence > 0.5)
        if name == CLASS_ATTRIBUTE and class_test is not None:
            refinement = leading_refinement(fused, class_test)
            if refinement is not None and f"{name}={refinement}" not in entries:
                entries.append(f"{name}={refinement}")
        if name in SEEN_TOGETHER:
            entries.extend(f"{name}={value}" for value in last_stated(values) if f"{name}={value}" not in entries)
    return supports_packing(len(flat) // FIELDS).pack(*flat), INDEX_SEPARATOR.join(sorted(entries))


def _unpack_attributes(packed: bytes, interned: InternedTexts, conn: sqlite3.Connection) -> dict[str, AttributeBelief]:
    """The attributes of a packed attribute column (see :func:`_pack_attributes`)."""
    decoded: dict[str, AttributeBelief] = {}
    for _, _, log_odds, count, _, first_seen, last_seen, name, value, sources in decoded_supports(
        packed, SUPPORT, interned, conn
    ):
        attribute = decoded.get(name)
        if attribute is None:
            attribute = decoded[name] = AttributeBelief(name, {})
        attribute.values[value] = ValueSupport(log_odds, count, set(sources), first_seen, last_seen)
    return decoded


def _pack_attribute_column(conn: sqlite3.Connection) -> None:
    """Rewrite a version-2 store's attribute column (JSON text) as packed supports (inside the migration's
    transaction); the attribute index is left as it is (the same values are indexed)."""
    conn.execute(_INTERNED_TABLE)
    interned = InternedTexts()

    def write(statement: str, rows: list[tuple]) -> None:
        conn.executemany(statement, rows)

    last = -1
    while rows := conn.execute(
        "SELECT id, attributes FROM objects WHERE id > ? ORDER BY id LIMIT 10000", (last,)
    ).fetchall():
        packed = []
        for object_id, text in rows:
            if not isinstance(text, str):
                continue  # packed already
            attributes = {}
            for name, values in json.loads(text).items():
                supports = {value: ValueSupport(s[0], s[1], set(s[2]), s[3], s[4]) for value, s in values.items()}
                attributes[name] = AttributeBelief(name, supports)
            packed.append((_pack_attributes(attributes, None, interned, conn, write)[0], object_id))
        conn.executemany("UPDATE objects SET attributes = ? WHERE id = ?", packed)
        last = rows[-1][0]


STATEMENT = struct.Struct("<iidi")
"""One packed statement of a sighting: attribute name code, value code, confidence (rounded to 6 digits), expert
code (the evidence column is these records one after another; a version-2 store's sightings keep JSON text)."""


@functools.lru_cache(maxsize=64)
def _statements(count: int) -> struct.Struct:
    """The packing of ``count`` statements."""
    return struct.Struct("<" + STATEMENT.format[1:] * count)


def _pack_evidence(
    evidence: Sequence[Evidence],
    interned: InternedTexts,
    conn: sqlite3.Connection,
    write: Callable[[str, list[tuple]], None],
) -> bytes:
    """A sighting's statements packed (:data:`STATEMENT`), texts new to ``interned`` interned with ``write``."""
    codes = interned.codes
    flat: list = []
    for e in evidence:
        attribute = codes.get(e.attribute)
        if attribute is None:
            attribute = interned.code(conn, e.attribute, write)
        value = codes.get(e.value)
        if value is None:
            value = interned.code(conn, e.value, write)
        source = codes.get(e.source)
        if source is None:
            source = interned.code(conn, e.source, write)
        confidence = e.confidence  # _rounded(confidence, 6), inlined
        flat += (attribute, value, rounded_cached(confidence, 6) if confidence else round(confidence, 6), source)
    return _statements(len(evidence)).pack(*flat)


def _unpack_evidence(
    packed: bytes | str, interned: InternedTexts, conn: sqlite3.Connection
) -> tuple[tuple[str, str, float, str], ...]:
    """The statements of a sighting's evidence column: packed, or JSON text (written by schema version 2)."""
    if isinstance(packed, str):
        return tuple((e[0], e[1], float(e[2]), e[3]) for e in json.loads(packed))
    numbers = _statements(len(packed) // STATEMENT.size).unpack(packed)
    text = interned.text
    return tuple(
        (text(conn, numbers[i]), text(conn, numbers[i + 1]), numbers[i + 2], text(conn, numbers[i + 3]))
        for i in range(0, len(numbers), 4)
    )


def _index_entries(indexed: str) -> set[tuple[str, str]]:
    if not indexed:
        return set()
    return {(name, value) for name, _, value in (entry.partition("=") for entry in indexed.split(INDEX_SEPARATOR))}


def _belief_from_row(row: tuple, interned: InternedTexts, conn: sqlite3.Connection) -> ObjectBelief:
    """The belief of an ``objects`` row (extra trailing columns are ignored; codes unknown to ``interned`` are read
    from ``conn``)."""
    (
        object_id,
        class_name,
        frame,
        px,
        py,
        pz,
        qx,
        qy,
        qz,
        qw,
        sx,
        sy,
        sz,
        variance,
        appearance,
        existence,
        status,
        first_seen,
        last_seen,
        misses,
        observations,
        region,
        region_class,
        recording,
        roi,
        sources,
        attributes,
        _indexed,
    ) = row[:_COLUMN_COUNT]
    return ObjectBelief(
        id=object_id,
        frame=frame,
        position=np.array([px, py, pz]),
        orientation=np.array([qx, qy, qz, qw]),
        dimensions=None if sx is None else np.array([sx, sy, sz]),
        appearance=None if appearance is None else np.frombuffer(appearance, dtype=np.float32).astype(np.float64),
        attributes=_unpack_attributes(attributes, interned, conn),
        position_variance=variance,
        existence=existence,
        status=status,
        first_seen=first_seen,
        last_seen=last_seen,
        misses=misses,
        region=region,
        region_class=region_class,
        roi=roi_from_text(roi),
        sources=set(decoded_sources(sources)),
        observations=observations,
        class_name=class_name,
        recording=recording,
    )


def _box_bounds(pose: np.ndarray, size: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    pose = np.asarray(pose, dtype=np.float64)
    half = np.abs(pose[:3, :3]) @ (np.asarray(size, dtype=np.float64) / 2.0)
    return pose[:3, 3] - half, pose[:3, 3] + half


def _alternatives(value: str | tuple[str, ...]) -> tuple[str, ...]:
    """The values an attribute filter accepts: the one given, or each of several."""
    return (value,) if isinstance(value, str) else tuple(value)


def _reads(row: tuple, name: str, wanted: str) -> bool:
    """True when one of the belief's indexed ``name`` values (more likely than not, or fused) reads ``wanted``."""
    return any(entry == name and text_matches(wanted, value) for entry, value in _index_entries(row[_INDEXED]))


def _in_named_region(rows: list[tuple], f: BeliefFilter) -> list[tuple]:
    """The rows whose stored region is one of the filter's names or whose position lies in one of its boxes
    (:meth:`RegionBox.contains`, with each box's pose made once)."""
    names = {n.lower() for n in [f.region or "", *(box.name for box in f.region_boxes)]}
    boxes = []
    for box in f.region_boxes:
        pose = box.pose
        boxes.append((box.frame, pose[:3, :3].T, pose[:3, 3], np.asarray(box.size, dtype=np.float64) / 2.0 + 1e-9))
    kept = []
    for row in rows:
        if str(row[21]).lower() in names:
            kept.append(row)
            continue
        position = np.array([row[3], row[4], row[5]], dtype=np.float64)
        if any(row[2] == frame and bool((np.abs(rotation @ (position - centre)) <= half).all()) for frame, rotation,
               centre, half in boxes):  # fmt: skip
            kept.append(row)
    return kept


def _frustum_bounds(camera: CameraModel) -> tuple[np.ndarray, np.ndarray]:
    k = camera.intrinsics
    corners = [(0.0, 0.0), (k.width, 0.0), (0.0, k.height), (k.width, k.height)]
    rays = [k.ray(u, v) for u, v in corners]
    points = [np.zeros(3)] + [ray * camera.max_range for ray in rays]
    transform = np.asarray(camera.to_frame, dtype=np.float64)
    world = np.stack(points) @ transform[:3, :3].T + transform[:3, 3]
    return world.min(axis=0), world.max(axis=0)
