"""The write-behind writer's checkpointer (issue 19): the writer's WAL is checkpointed beside its commits and stays
as short as SQLite's autocheckpoint keeps it."""

from __future__ import annotations

import sqlite3
from pathlib import Path

from reasoning.beliefs.frame_writer import CATCH_UP, Checkpointer

PAGE = 4096
BOUND = 20
"""The checkpoint bound of these tests, in pages."""
COMMITS = 300
"""Each commit writes a row of 3,000 bytes: at least one page, so the WAL would hold at least this many pages."""


def _committing(path: Path) -> sqlite3.Connection:
    conn = sqlite3.connect(path, isolation_level=None)
    conn.execute(f"PRAGMA page_size = {PAGE}")
    conn.execute("PRAGMA journal_mode = WAL")
    conn.execute("PRAGMA wal_autocheckpoint = 0")
    conn.execute("CREATE TABLE t (k INTEGER PRIMARY KEY, v BLOB)")
    return conn


def _commit(conn: sqlite3.Connection, k: int) -> None:
    conn.execute("BEGIN IMMEDIATE")
    conn.execute("INSERT INTO t VALUES (?, ?)", (k, bytes(3000)))
    conn.execute("COMMIT")


def _wal_pages(path: Path) -> int:
    return (Path(f"{path}-wal").stat().st_size - 32) // (PAGE + 24)


def test_without_checkpoints_the_wal_grows(tmp_path: Path) -> None:
    """The control: the same commits on a connection that never checkpoints leave every page in the WAL."""
    path = tmp_path / "store.sqlite"
    conn = _committing(path)
    for k in range(COMMITS):
        _commit(conn, k)
    assert _wal_pages(path) >= COMMITS
    conn.close()


def test_the_thread_checkpoints_and_the_wal_starts_over(tmp_path: Path) -> None:
    """A checkpoint the thread ran once the WAL reached the bound lets the next commit start the WAL over: the WAL
    file never grows much beyond the bound, and every row is stored."""
    path = tmp_path / "store.sqlite"
    conn = _committing(path)
    checkpointer = Checkpointer(str(path), "NORMAL", BOUND)
    for k in range(COMMITS):
        _commit(conn, k)
        checkpointer.committed(conn)
        checkpointer.settle()  # one commit at a time: the WAL may start over at every commit after a checkpoint
        assert checkpointer.wal_pages() < 2 * BOUND
    checkpointer.close()
    assert _wal_pages(path) < 2 * BOUND
    assert conn.execute("SELECT count(*) FROM t").fetchone()[0] == COMMITS
    conn.close()


def test_a_wal_the_thread_did_not_keep_short_is_caught_up(tmp_path: Path) -> None:
    """Commits that outran the thread (here: none reported until the WAL held three times the bound): the committing
    connection checkpoints the rest itself, and the next commit starts the WAL over."""
    path = tmp_path / "store.sqlite"
    conn = _committing(path)
    checkpointer = Checkpointer(str(path), "NORMAL", BOUND)
    k = 0
    while checkpointer.wal_pages() < (CATCH_UP + 1) * BOUND:
        _commit(conn, k)
        k += 1
    checkpointer.committed(conn)
    _commit(conn, k)
    assert checkpointer.wal_pages() < BOUND
    checkpointer.close()
    assert conn.execute("SELECT count(*) FROM t").fetchone()[0] == k + 1
    conn.close()
