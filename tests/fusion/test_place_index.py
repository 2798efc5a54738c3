"""The store's in-memory place index answers what the tables say: the present beliefs of a world within the gate
of an observation (against a brute-force search of the stored rows), and it follows other connections' writes
(``PRAGMA data_version``) and the store's own writes that it does not update itself."""

from __future__ import annotations

import sqlite3
from pathlib import Path

import numpy as np

from reasoning.beliefs.place_index import PlaceIndex
from reasoning.beliefs.store import RTREE_SLACK, BeliefStore
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import Evidence
from reasoning.fusion.tracking import PRESENT, BeliefTracker, TrackerConfig


def thing(position: np.ndarray, frame: str = "world", recording: str = "", cls: str = "Cup") -> FrameObject:
    return FrameObject(
        position=np.asarray(position, dtype=float),
        frame=frame,
        dimensions=np.array([0.1, 0.1, 0.1]),
        evidence=[Evidence("class", cls, 0.8, "Detector")],
        sources={"Detector"},
        recording=recording,
    )


def within(path: Path, centres: np.ndarray, frame: str, recording: str, reach: float) -> tuple[set[int], set[int]]:
    """The present beliefs of a world whose R*Tree entry centre lies within ``reach`` (per axis) of a centre, and
    those whose position lies within ``reach`` (distance) of one."""
    with sqlite3.connect(path) as conn:
        rows = conn.execute(
            "SELECT o.id, o.px, o.py, o.pz, (p.x0 + p.x1) / 2, (p.y0 + p.y1) / 2, (p.z0 + p.z1) / 2 "
            "FROM objects o JOIN objects_place p ON p.id = o.id "
            "WHERE o.status = ? AND o.frame = ? AND (o.frame = 'world' OR o.recording = ?)",
            (PRESENT, frame, recording),
        ).fetchall()
    entries, positions = set(), set()
    for object_id, *numbers in rows:
        if (np.abs(np.asarray(numbers[3:]) - centres).max(axis=1) <= reach).any():
            entries.add(object_id)
        if (np.linalg.norm(np.asarray(numbers[:3]) - centres, axis=1) <= reach).any():
            positions.add(object_id)
    return entries, positions


def present(path: Path) -> set[int]:
    with sqlite3.connect(path) as conn:
        return {row[0] for row in conn.execute("SELECT id FROM objects WHERE status = ?", (PRESENT,))}


def test_the_index_finds_the_stored_entries_near_each_place(tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    path = tmp_path / "b.sqlite"
    gate = TrackerConfig().association.gate_distance
    reach = gate + RTREE_SLACK / 2
    worlds = [("world", ""), ("camera", "take1"), ("camera", "take2")]
    with BeliefStore(path, tracker=BeliefTracker(config=TrackerConfig(gone_after=5.0))) as store:
        for step in range(150):  # objects appear, drift (some across cells), are missed and go
            frame, recording = worlds[step % 3]
            centre = rng.uniform(-1.5, 1.5, 3)
            objects = [thing(centre + rng.normal(0.0, 0.3, 3), frame, recording) for _ in range(8)]
            store.integrate(objects, float(step))
            index = store._index
            assert index is not None
            if step % 50 == 49:  # and one built afresh from the tables
                with sqlite3.connect(path) as conn:
                    index = PlaceIndex.build(conn, index.reach)
            alive = present(path)
            for frame, recording in worlds:
                centres = rng.uniform(-1.7, 1.7, (5, 3))
                found = set(index.near(centres, frame, recording, reach).tolist())
                inner, _ = within(path, centres, frame, recording, reach - 1e-5)
                outer, _ = within(path, centres, frame, recording, reach + 1e-5)
                assert inner <= found and found & alive <= outer  # R*Tree entries (float32) within the reach
                assert within(path, centres, frame, recording, gate)[1] <= found  # every belief within the gate


def test_another_connections_write_is_seen_by_the_next_integration(tmp_path: Path) -> None:
    path = tmp_path / "b.sqlite"
    with BeliefStore(path) as engine, BeliefStore(path) as other:
        first = engine.integrate([thing(np.array([0.0, 0.0, 0.8]))], 1.0).assigned[0]
        belief = other.get(first)
        assert belief is not None
        belief.position = np.array([3.0, 0.0, 0.8])
        other.put([belief])  # moved by another connection
        step = engine.integrate([thing(np.array([3.0, 0.0, 0.8]))], 2.0)
        assert step.assigned == (first,) and not step.created


def test_the_stores_own_untracked_writes_drop_the_index(tmp_path: Path) -> None:
    path = tmp_path / "b.sqlite"
    with BeliefStore(path) as store:
        first = store.integrate([thing(np.array([0.0, 0.0, 0.8]))], 1.0).assigned[0]
        belief = store.get(first)
        assert belief is not None
        belief.position = np.array([3.0, 0.0, 0.8])
        store.put([belief])
        assert store.integrate([thing(np.array([3.0, 0.0, 0.8]))], 2.0).assigned == (first,)
        store.forget([first])
        step = store.integrate([thing(np.array([3.0, 0.0, 0.8]))], 3.0)
        assert step.created and step.assigned != (first,)
