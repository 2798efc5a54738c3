"""The attribute index without an index by object id (schema 4): a belief's entries are found from its stored
``indexed`` column and deleted by key, so put, forget and integrate keep exactly the entries of the stored beliefs,
and a version-3 store is migrated (its index by object id dropped, its entries kept)."""

from __future__ import annotations

import sqlite3
from pathlib import Path

import numpy as np

from reasoning.beliefs.store import SCHEMA_VERSION, BeliefFilter, BeliefStore, _index_entries
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import AttributeBelief, Evidence, ValueSupport
from reasoning.fusion.tracking import ObjectBelief


def thing(position: tuple[float, float, float], cls: str, color: str) -> FrameObject:
    return FrameObject(
        position=np.array(position, dtype=float),
        frame="world",
        dimensions=np.array([0.2, 0.07, 0.07]),
        evidence=[Evidence("class", cls, 0.8, "Detector"), Evidence("color", color, 0.7, "ColorExpert")],
        sources={"Segmenter", "Detector", "ColorExpert"},
        confidence=0.9,
    )


def belief(object_id: int, position: tuple[float, float, float], values: dict[str, str]) -> ObjectBelief:
    attributes = {
        name: AttributeBelief(name, {value: ValueSupport(1.2, 1, {"Expert"}, 0.0, 0.0)})
        for name, value in values.items()
    }
    return ObjectBelief(
        id=object_id, frame="world", position=np.array(position), orientation=np.array([0.0, 0.0, 0.0, 1.0]),
        dimensions=np.array([0.1, 0.1, 0.1]), attributes=attributes, first_seen=0.0, last_seen=0.0,
        class_name=values.get("class"),
    )  # fmt: skip


def stored_entries(path: Path) -> tuple[set[tuple[str, str, int]], set[tuple[str, str, int]]]:
    """The attribute index's entries, and those the stored beliefs' indexed columns name."""
    with sqlite3.connect(path) as conn:
        entries = {tuple(row) for row in conn.execute("SELECT name, value, object_id FROM attribute_index")}
        named = {
            (name, value, object_id)
            for object_id, indexed in conn.execute("SELECT id, indexed FROM objects")
            for name, value in _index_entries(indexed)
        }
    return entries, named  # type: ignore[return-value]


def test_put_over_a_stored_belief_replaces_its_entries(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    with BeliefStore(path) as store:
        store.put(
            [belief(1, (0.0, 0.0, 0.8), {"class": "Cup", "color": "red"}), belief(2, (1.0, 0, 0.8), {"color": "red"})]
        )
        store.put([belief(1, (0.0, 0.0, 0.8), {"class": "Bowl", "shape": "round"})])
        assert [b.id for b in store.query(BeliefFilter(attributes={"color": "red"}))] == [2]
        assert [b.id for b in store.query(BeliefFilter(attributes={"shape": "round"}))] == [1]
    entries, named = stored_entries(path)
    assert entries == named and ("color", "red", 1) not in entries and ("class", "Bowl", 1) in entries


def test_forget_drops_the_entries_of_the_forgotten_beliefs_only(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    with BeliefStore(path) as store:
        store.integrate([thing((0.0, 0.0, 0.8), "Cup", "red"), thing((2.0, 0.0, 0.8), "Bowl", "red")], 0.0)
        assert store.forget([1, 7]) == 1
        assert [b.id for b in store.query(BeliefFilter(attributes={"color": "red"}))] == [2]
    entries, named = stored_entries(path)
    assert entries == named and {i for _, _, i in entries} == {2}


def test_integrate_put_and_forget_keep_the_index_equal_to_the_stored_beliefs(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    rng = np.random.default_rng(3)
    classes, colors = ["Cup", "Bowl", "Milk"], ["red", "blue", "green"]
    with BeliefStore(path) as store:
        for t in range(40):
            frame = [
                thing(
                    (float(rng.integers(5)), float(rng.integers(3)), 0.8),
                    str(rng.choice(classes)),
                    str(rng.choice(colors)),
                )
                for _ in range(4)
            ]
            store.integrate(frame, float(t))
            if t % 10 == 5:
                stored = store.beliefs()
                store.put([belief(stored[0].id, tuple(stored[0].position), {"color": "white"})])
                store.forget([stored[-1].id])
    entries, named = stored_entries(path)
    assert entries == named and len(entries) > 10


def test_a_version_3_store_loses_its_index_by_object_and_keeps_its_entries(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    with BeliefStore(path) as store:
        store.integrate([thing((0.0, 0.0, 0.8), "Cup", "red"), thing((2.0, 0.0, 0.8), "Bowl", "blue")], 0.0)
    with sqlite3.connect(path) as conn:  # what robokudo with schema version 3 wrote
        conn.execute("CREATE INDEX attribute_index_object ON attribute_index (object_id)")
        conn.execute("UPDATE meta SET value = '3' WHERE key = 'version'")
    before, _ = stored_entries(path)
    with BeliefStore(path) as store:
        assert store.integrity_check() == "ok"
        store.put([belief(1, (0.0, 0.0, 0.8), {"class": "Cup", "color": "green"})])
    with sqlite3.connect(path) as conn:
        indexes = {row[0] for row in conn.execute("SELECT name FROM sqlite_master WHERE type = 'index'")}
        assert conn.execute("SELECT value FROM meta WHERE key = 'version'").fetchone()[0] == str(SCHEMA_VERSION)
    entries, named = stored_entries(path)
    assert "attribute_index_object" not in indexes and entries == named
    assert ("color", "blue", 2) in before and ("color", "blue", 2) in entries and ("color", "green", 1) in entries
