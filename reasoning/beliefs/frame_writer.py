"""A belief store's write-behind writer: a child process that commits the frames a store has fused, one transaction
per frame, while the store's process fuses the next frame (issue 19).

A process and not a thread: ``sqlite3`` releases the GIL around each statement step only, so a writer thread takes
the GIL back after every row and waits behind the fusing thread's Python each time; a process runs its SQLite calls
on the second core without that hand-over.

Protocol (both ways: a 4-byte little-endian length, then a :mod:`marshal` record):

* store -> writer: ``(seq, next_id, writes)``: the frame's number, the ``meta.next_id`` the frame read (``None``:
  not checked), and its ``(statement, rows)`` pairs in order. The writer runs them in ``BEGIN IMMEDIATE`` ...
  ``COMMIT`` after checking that ``meta.next_id`` still holds ``next_id`` (another writer of the same file would
  otherwise hand out the same ids).
* writer -> store: ``(seq, None)`` once the frame is committed, or ``(seq, (error class, message))`` when it failed;
  the failed frame is rolled back and the writer exits without running any later frame (they were fused on top of it).

At the end of its input (the store closed, or its process died) the writer commits the frames it has read whole and
exits.

Checkpoints run beside the commits (:class:`Checkpointer`): a checkpoint that syncs the files takes tens of ms, and
run by the committing connection (SQLite's autocheckpoint) it would hold up every frame behind it, and with them the
store, which waits for the frame before its last one.

This module imports the standard library only: the writer runs as ``python -I frame_writer.py <path> <synchronous>
<busy timeout s> <autocheckpoint pages>``.
"""

from __future__ import annotations

import contextlib
import marshal
import os
import sqlite3
import struct
import subprocess
import sys
import threading
import weakref
from pathlib import Path

LENGTH = struct.Struct("<I")
"""The length prefix of every record."""

MAX_WRITE_BEHIND = 256
"""The most frames a store may leave uncommitted: their answers (about 15 bytes each) wait unread in the writer's
output pipe, which must hold them all (at least one 4 KiB page on every system), or the writer blocks on them while
the store blocks sending it the next frame."""

NEXT_ID = "SELECT value FROM meta WHERE key = 'next_id'"
"""The statement that reads the next belief id the store hands out."""

WAL_FRAMES = struct.Struct("=I")
"""``mxFrame`` of the WAL-index header at the start of the ``-shm`` file: the frames (pages) the WAL holds, a native
32-bit unsigned integer at byte 16 (https://www.sqlite.org/walformat.html, "The WAL-Index Header")."""
WAL_FRAMES_OFFSET = 16

CATCH_UP = 2
"""The WAL length, in multiples of the checkpoint bound, from which the committing connection checkpoints itself."""


class WriterGoneError(Exception):
    """The writer process ended without answering for every frame sent."""


def _read_exactly(fd: int, count: int) -> bytes | None:
    """``count`` bytes from ``fd`` (None at the end of input, also when it ends part-way)."""
    chunks: list[bytes] = []
    left = count
    while left:
        chunk = os.read(fd, left)
        if not chunk:
            return None
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)


def _read_record(fd: int) -> object | None:
    header = _read_exactly(fd, LENGTH.size)
    if header is None:
        return None
    body = _read_exactly(fd, LENGTH.unpack(header)[0])
    return None if body is None else marshal.loads(body)


def _write_record(fd: int, record: object) -> None:
    body = marshal.dumps(record)
    view = memoryview(LENGTH.pack(len(body)) + body)
    while view:
        view = view[os.write(fd, view) :]


class FrameWriter:
    """The store's side of one writer process: send frames, collect what became of them."""

    def __init__(self, path: Path, synchronous: str, busy_timeout: float, autocheckpoint: int) -> None:
        self.process = subprocess.Popen(
            [sys.executable, "-I", __file__, str(path), synchronous, str(busy_timeout), str(autocheckpoint)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            close_fds=True,
        )
        assert self.process.stdin is not None and self.process.stdout is not None
        self._out = self.process.stdin.fileno()
        self._in = self.process.stdout.fileno()
        # a store dropped without close: the writer's input ends with it, not with the interpreter
        self._ended = weakref.finalize(self, _end_writer, self.process)

    def send(self, seq: int, next_id: int | None, writes: list[tuple[str, list[tuple]]]) -> None:
        """Hand one frame's writes to the writer (raises :class:`WriterGoneError` when it has ended)."""
        try:
            _write_record(self._out, (seq, next_id, writes))
        except BrokenPipeError as error:
            raise WriterGoneError(f"the writer process ended (exit code {self.process.poll()})") from error

    def answer(self) -> tuple[int, tuple[str, str] | None]:
        """The next frame's outcome (waiting for it): ``(seq, None)`` committed, ``(seq, (error class, message))``
        failed. Raises :class:`WriterGoneError` when the writer ended without answering."""
        record = _read_record(self._in)
        if record is None:
            code = self.process.wait()
            raise WriterGoneError(f"the writer process ended without committing every frame (exit code {code})")
        return record  # type: ignore[return-value]

    def close(self) -> None:
        """End the writer's input and wait for it (it commits what it has read first)."""
        self._ended()


def _end_writer(process: subprocess.Popen) -> None:
    """End the writer's input, wait for it to commit what it has read and exit, and close its output."""
    assert process.stdin is not None and process.stdout is not None
    with contextlib.suppress(BrokenPipeError):
        process.stdin.close()
    process.wait()
    process.stdout.close()


class Checkpointer:
    """Checkpoints of one store's WAL on a thread of their own, beside the writer's commits.

    The committing connection does not checkpoint (``wal_autocheckpoint = 0``); after each commit :meth:`committed`
    reads how many pages the WAL holds from the WAL index and, from ``pages`` on (the bound SQLite's autocheckpoint
    applies after a commit), wakes the thread, which runs a PASSIVE checkpoint on its own connection: SQLite lets
    one writer append to the WAL while it is checkpointed, and releases the GIL while it copies and syncs, so the
    next frames are committed meanwhile. What is stored and synced is SQLite's affair as before; only which
    connection checkpoints changes.

    SQLite starts the WAL over only after a checkpoint that copied all of it, and frames committed during a
    checkpoint are left for the next one; so that a steady stream of frames cannot grow the WAL without end, the
    committing connection checkpoints itself (as autocheckpoint does: the rest, a few frames) once the WAL holds
    :data:`CATCH_UP` times ``pages`` and the thread is idle."""

    def __init__(self, path: str, synchronous: str, pages: int) -> None:
        self.pages = pages
        self._shm = os.open(f"{path}-shm", os.O_RDONLY)  # the store's connection has made it (WAL mode)
        self._conn = sqlite3.connect(path, isolation_level=None, check_same_thread=False)
        self._conn.execute(f"PRAGMA synchronous = {synchronous}")
        self._wanted = threading.Event()
        self._idle = threading.Event()
        self._idle.set()
        self._stop = False
        self._thread = threading.Thread(target=self._run, name="checkpointer", daemon=True)
        self._thread.start()

    def wal_pages(self) -> int:
        """The pages the WAL holds (0 when the WAL index cannot be read)."""
        header = os.pread(self._shm, WAL_FRAMES.size, WAL_FRAMES_OFFSET)
        return WAL_FRAMES.unpack(header)[0] if len(header) == WAL_FRAMES.size else 0

    def committed(self, conn: sqlite3.Connection) -> None:
        """A frame was committed on ``conn``: when the WAL has reached the bound and no checkpoint runs, wake the
        thread, or from :data:`CATCH_UP` times the bound on checkpoint on ``conn`` (see the class docstring)."""
        pages = self.wal_pages()
        if pages < self.pages or not self._idle.is_set():
            return
        if pages >= CATCH_UP * self.pages:
            with contextlib.suppress(sqlite3.Error):  # as the thread's: the next commit asks again
                conn.execute("PRAGMA wal_checkpoint(PASSIVE)").fetchall()
            return
        self._idle.clear()
        self._wanted.set()

    def settle(self) -> None:
        """Wait until no checkpoint runs."""
        self._idle.wait()

    def _run(self) -> None:
        while True:
            self._wanted.wait()
            self._wanted.clear()
            if self._stop:
                return
            # a failed checkpoint loses nothing (the WAL holds every commit); the next commit asks again
            with contextlib.suppress(sqlite3.Error):
                self._conn.execute("PRAGMA wal_checkpoint(PASSIVE)").fetchall()
            self._idle.set()

    def close(self) -> None:
        """Let a running checkpoint finish, end the thread and close its connection."""
        self.settle()
        self._stop = True
        self._wanted.set()
        self._thread.join()
        self._conn.close()
        os.close(self._shm)


def _checkpointer(path: str, synchronous: str, pages: int) -> Checkpointer | None:
    """A checkpointer for the store at ``path``, or None when its WAL index cannot be read (the writer's connection
    then checkpoints as SQLite's autocheckpoint does)."""
    try:
        return Checkpointer(path, synchronous, pages)
    except (OSError, sqlite3.Error):
        return None


def serve(path: str, synchronous: str, busy_timeout: float, autocheckpoint: int) -> int:
    """The writer's loop (see the module docstring); returns the exit code."""
    if hasattr(os, "SCHED_BATCH"):  # throughput work: waking it (a frame sent) must not preempt the fusing process
        with contextlib.suppress(OSError):
            os.sched_setscheduler(0, os.SCHED_BATCH, os.sched_param(0))
    conn = sqlite3.connect(path, timeout=busy_timeout, isolation_level=None)
    conn.execute(f"PRAGMA busy_timeout = {int(busy_timeout * 1000)}")
    conn.execute(f"PRAGMA synchronous = {synchronous}")
    checkpointer = _checkpointer(path, synchronous, autocheckpoint) if autocheckpoint > 0 else None
    conn.execute(f"PRAGMA wal_autocheckpoint = {0 if checkpointer else autocheckpoint}")
    try:
        return _commit_frames(conn, checkpointer)
    finally:
        if checkpointer is not None:
            checkpointer.close()
        conn.close()


def _commit_frames(conn: sqlite3.Connection, checkpointer: Checkpointer | None) -> int:
    """Commit each frame read from the input and answer for it (see the module docstring); the exit code."""
    source, sink = sys.stdin.fileno(), sys.stdout.fileno()
    while (record := _read_record(source)) is not None:
        seq, next_id, writes = record  # type: ignore[misc]
        try:
            conn.execute("BEGIN IMMEDIATE")
            if next_id is not None:
                stored = int(conn.execute(NEXT_ID).fetchone()[0])
                if stored != next_id:
                    raise sqlite3.OperationalError(
                        f"another writer changed the store (next id {stored}, the frame was fused at {next_id})"
                    )
            for statement, rows in writes:
                conn.executemany(statement, rows)
            conn.execute("COMMIT")
        except sqlite3.Error as error:
            if conn.in_transaction:
                conn.execute("ROLLBACK")
            with contextlib.suppress(BrokenPipeError):
                _write_record(sink, (seq, (type(error).__name__, str(error))))
            return 1
        with contextlib.suppress(BrokenPipeError):  # the store's process ended: go on committing what it sent
            _write_record(sink, (seq, None))
        if checkpointer is not None:
            checkpointer.committed(conn)
    return 0


if __name__ == "__main__":
    sys.exit(serve(sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4])))
