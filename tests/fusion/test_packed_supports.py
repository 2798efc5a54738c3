"""Attribute supports and sightings' statements packed with interned texts (schema version 3): what is written is
read back as it was (any texts, by this and by another connection), a rolled-back transaction's codes are not kept,
and a version-2 store (JSON text) is migrated to the same beliefs and its sightings read back."""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from reasoning.beliefs.store import SCHEMA_VERSION, BeliefStore
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import AttributeBelief, Evidence, ValueSupport
from reasoning.fusion.tracking import ObjectBelief

TEXTS = st.text(max_size=12)
SUPPORTS = st.builds(
    ValueSupport,
    st.floats(-20, 20).map(lambda v: round(v, 9)),
    st.integers(0, 2**40),
    st.sets(TEXTS, max_size=3),
    st.floats(0, 1e9),
    st.floats(0, 1e9),
)
ATTRIBUTES = st.dictionaries(TEXTS, st.dictionaries(TEXTS, SUPPORTS, min_size=1, max_size=3), max_size=4)


def belief(object_id: int, attributes: dict[str, dict[str, ValueSupport]]) -> ObjectBelief:
    return ObjectBelief(
        id=object_id,
        frame="world",
        position=np.array([float(object_id), 0.0, 0.8]),
        attributes={name: AttributeBelief(name, dict(values)) for name, values in attributes.items()},
        sources={"Detector"},
    )


@settings(max_examples=60, deadline=None)
@given(attributes=st.lists(ATTRIBUTES, min_size=1, max_size=3))
def test_packed_supports_read_back_as_written_by_this_and_another_connection(
    tmp_path_factory: pytest.TempPathFactory, attributes: list[dict[str, dict[str, ValueSupport]]]
) -> None:
    path = tmp_path_factory.mktemp("packed") / "b.sqlite"
    with BeliefStore(path) as reader, BeliefStore(path) as writer:
        reader.count()  # opened (and its codes read) before the writer interns anything
        written = [belief(i + 1, a) for i, a in enumerate(attributes)]
        writer.put(written)
        for store in (writer, reader):
            for b in written:
                found = store.get(b.id)
                assert found is not None and found.attributes == b.attributes


def test_a_rolled_back_transaction_leaves_no_codes_behind(tmp_path: Path) -> None:
    path = tmp_path / "b.sqlite"
    support = ValueSupport(1.0, 1, {"Expert"}, 1.0, 1.0)
    with BeliefStore(path) as store, BeliefStore(path) as other:
        with pytest.raises(RuntimeError), store._transaction() as conn:
            store._write_beliefs(conn, [belief(1, {"color": {"teal": support}})], None)
            raise RuntimeError("abandoned")
        other.put([belief(2, {"shape": {"round": support}})])  # may take the codes the rollback freed
        store.put([belief(3, {"color": {"teal": support}})])
        for object_id, attributes in ((2, {"shape": {"round": support}}), (3, {"color": {"teal": support}})):
            for reader in (store, other):
                found = reader.get(object_id)
                assert found is not None and found.attributes == belief(object_id, attributes).attributes


def test_a_version_2_store_is_migrated_to_the_same_beliefs(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    two = ValueSupport(2.5, 3, {"A", "B"}, 1.0, 4.0)
    written = [
        belief(1, {"color": {"red": two, "blue": ValueSupport(-0.5, 1, {"B"}, 2.0, 2.0)}}),
        belief(2, {"class": {"Milk": two}, "text": {"oat \u00e9": ValueSupport(0.7, 1, set(), 3.0, 3.0)}}),
    ]
    with BeliefStore(path) as store:
        store.put(written)
    with sqlite3.connect(path) as conn:  # what robokudo with schema version 2 wrote: supports as JSON text
        for b in written:
            text = json.dumps(
                {
                    name: {
                        v: [s.log_odds, s.count, sorted(s.sources), s.first_seen, s.last_seen]
                        for v, s in a.values.items()
                    }
                    for name, a in b.attributes.items()
                },
                separators=(",", ":"),
            )
            conn.execute("UPDATE objects SET attributes = ? WHERE id = ?", (text, b.id))
        conn.execute("DROP TABLE interned")
        conn.execute("UPDATE meta SET value = '2' WHERE key = 'version'")
    with BeliefStore(path) as store:
        assert store.integrity_check() == "ok"
        for b in written:
            found = store.get(b.id)
            assert found is not None and found.attributes == b.attributes
    with sqlite3.connect(path) as conn:
        assert conn.execute("SELECT value FROM meta WHERE key = 'version'").fetchone()[0] == str(SCHEMA_VERSION)
        assert {row[0] for row in conn.execute("SELECT typeof(attributes) FROM objects")} == {"blob"}


@settings(max_examples=40, deadline=None)
@given(
    statements=st.lists(
        st.tuples(TEXTS, TEXTS, st.floats(0.01, 0.99), TEXTS).map(lambda t: Evidence(*t)), min_size=0, max_size=6
    )
)
def test_a_sightings_statements_read_back_as_stated(
    tmp_path_factory: pytest.TempPathFactory, statements: list[Evidence]
) -> None:
    path = tmp_path_factory.mktemp("sightings") / "b.sqlite"
    seen = FrameObject(np.array([0.0, 0.0, 0.8]), "world", evidence=statements, sources={"Segmenter"})
    with BeliefStore(path) as store, BeliefStore(path) as reader:
        reader.count()
        object_id = store.integrate([seen], 1.0).assigned[0]
        expected = tuple((e.attribute, e.value, round(e.confidence, 6), e.source) for e in statements)
        for each in (store, reader):
            (record,) = each.history(object_id)
            assert record.evidence == expected and record.sources == ("Segmenter",)


def test_a_version_2_sighting_reads_back(tmp_path: Path) -> None:
    path = tmp_path / "b.sqlite"
    seen = FrameObject(np.array([0.0, 0.0, 0.8]), "world", evidence=[Evidence("color", "red", 0.8, "C")])
    with BeliefStore(path) as store:
        object_id = store.integrate([seen], 1.0).assigned[0]
    with sqlite3.connect(path) as conn:  # the statements as schema version 2 wrote them
        conn.execute("UPDATE observations SET evidence = ?", (json.dumps([["color", "red", 0.8, "C"]]),))
    with BeliefStore(path) as store:
        assert store.history(object_id)[0].evidence == (("color", "red", 0.8, "C"),)
