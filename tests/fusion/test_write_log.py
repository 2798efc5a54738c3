"""The belief store's write log: the statements and rows each integration wrote, which the update benchmark's
reference replays. Replayed with plain ``executemany`` on a copy of the store as it was, they give the same file."""

from __future__ import annotations

import shutil
import sqlite3
from pathlib import Path

import numpy as np

from reasoning.beliefs.store import BeliefStore
from reasoning.fusion.association import CameraModel
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import Evidence
from reasoning.fusion.tracking import BeliefTracker, TrackerConfig
from robokudo.core.types import CameraIntrinsics

TABLES = ("objects", "objects_place", "attribute_index", "observations", "meta", "classes")


def thing(x: float, y: float, cls: str, color: str, confidence: float = 0.8) -> FrameObject:
    return FrameObject(
        position=np.array([x, y, 0.8]),
        frame="world",
        dimensions=np.array([0.2, 0.07, 0.07]),
        evidence=[Evidence("class", cls, confidence, "Detector"), Evidence("color", color, 0.7, "Colors")],
        sources={"Segmenter", "Detector", "Colors"},
        roi=(1, 2, 3, 4),
    )


def contents(path: Path) -> dict[str, list[tuple]]:
    with sqlite3.connect(path) as conn:
        return {table: conn.execute(f"SELECT * FROM {table} ORDER BY 1").fetchall() for table in TABLES}


def test_replaying_the_write_log_gives_the_same_store(tmp_path: Path) -> None:
    path, start, replayed = tmp_path / "b.sqlite", tmp_path / "start.sqlite", tmp_path / "replayed.sqlite"
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = (1, 0, 0), (0, 0, -1), (0, 1, 0), (0.0, -2.0, 0.8)
    camera = CameraModel(CameraIntrinsics(500.0, 500.0, 320.0, 240.0, 640, 480), pose)
    rng = np.random.default_rng(3)
    with BeliefStore(path, tracker=BeliefTracker(TrackerConfig(gone_after=2.0)), history_limit=20) as store:
        store.integrate([thing(0.0, 0.0, "Cup", "red")], 0.0)
        store.close()
        shutil.copy(path, start)
    with BeliefStore(path, tracker=BeliefTracker(TrackerConfig(gone_after=2.0)), history_limit=20) as store:
        store.write_log = []
        for k in range(60):  # re-sightings, new objects, a class changing its mind, misses and gone marks
            seen = [thing(float(i) * 0.3 + rng.normal(0, 0.01), 0.0, "Cup", "red") for i in range(k % 4)]
            seen.append(thing(1.5, 0.5, "Milk" if k < 30 else "Bowl", "white", 0.9))
            store.integrate(seen, 1.0 + k * 0.5, camera=camera if k % 5 == 0 else None)
        log = store.write_log
    assert len(log) == 60 and all(log)
    shutil.copy(start, replayed)
    conn = sqlite3.connect(replayed, isolation_level=None)
    for frame in log:
        conn.execute("BEGIN IMMEDIATE")
        for statement, rows in frame:
            conn.executemany(statement, rows)
        conn.execute("COMMIT")
    conn.close()
    assert contents(replayed) == contents(path)
    assert any("observations" in statement for frame in log for statement, _ in frame)
    assert any("status = 'gone'" in statement for frame in log for statement, _ in frame)
