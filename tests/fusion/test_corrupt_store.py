"""Bad input: a corrupt or foreign store file gives a clear error and is never modified."""

from __future__ import annotations

import argparse
import hashlib
import sqlite3
from pathlib import Path

import numpy as np
import pytest

from reasoning.beliefs.store import BeliefStore, BeliefStoreError
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import Evidence
from robokudo.application.commands import beliefs as beliefs_cli


def digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def filled_store(path: Path, objects: int = 300) -> None:
    with BeliefStore(path) as store:
        for i in range(objects):
            item = FrameObject(
                position=np.array([float(i), 0.0, 0.0]),
                frame="world",
                evidence=[Evidence("color", "red", 0.8, "X"), Evidence("text", "x" * 200, 0.5, "OCR")],
            )
            store.integrate([item], float(i))
    with sqlite3.connect(path) as conn:  # fold the WAL into the file so the damage below hits real pages
        conn.execute("PRAGMA wal_checkpoint(TRUNCATE)")


def assert_clear_error(path: Path, error: BeliefStoreError) -> None:
    message = str(error)
    assert str(path) in message
    assert f"mv {path} {path}.corrupt" in message
    assert "left untouched" in message


def test_a_file_that_is_not_a_database(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    path.write_bytes(b"this is not sqlite\n" * 500)
    before = digest(path)
    with pytest.raises(BeliefStoreError) as caught:
        BeliefStore(path)
    assert_clear_error(path, caught.value)
    assert digest(path) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["beliefs.sqlite"]


def test_a_store_with_damaged_pages(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    filled_store(path)
    data = bytearray(path.read_bytes())
    page = 4096
    assert len(data) > 6 * page
    for offset in range(2 * page + 100, len(data) - page, 3 * page):  # scribble over several b-tree pages
        data[offset : offset + 600] = bytes(range(256)) * 2 + bytes(88)
    path.write_bytes(bytes(data))
    before = digest(path)
    with pytest.raises(BeliefStoreError) as caught:
        BeliefStore(path)
    assert_clear_error(path, caught.value)
    assert digest(path) == before


def test_a_foreign_sqlite_database(tmp_path: Path) -> None:
    path = tmp_path / "other.sqlite"
    with sqlite3.connect(path) as conn:
        conn.execute("CREATE TABLE recipes (name TEXT)")
    before = digest(path)
    with pytest.raises(BeliefStoreError, match="not a belief store") as caught:
        BeliefStore(path)
    assert_clear_error(path, caught.value)
    assert digest(path) == before


def test_the_cli_reports_a_corrupt_store_without_touching_it(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    path = tmp_path / "beliefs.sqlite"
    path.write_bytes(b"\x00garbage" * 100)
    before = digest(path)
    for clear in (False, True):
        args = argparse.Namespace(query=None, json=False, clear=clear, yes=clear, all=False, store=path)
        assert beliefs_cli.run(args) == 2
        err = capsys.readouterr().err
        assert str(path) in err and "mv " in err
    assert digest(path) == before
