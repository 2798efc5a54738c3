"""The belief store: persistence, queries with subsumption and regions, concurrency, history."""

from __future__ import annotations

import sqlite3
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from reasoning.beliefs.store import BeliefFilter, BeliefStore
from reasoning.fusion.association import CameraModel
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import AttributeBelief, Evidence, ValueSupport
from reasoning.fusion.tracking import GONE, PRESENT, BeliefTracker, ObjectBelief, TrackerConfig
from robokudo.core.regions import RegionBox
from robokudo.core.types import CameraIntrinsics
from tests.fusion.camera_poses import camera_looking_at_origin

SUBCLASSES = {("LactoseFreeMilk", "Milk"), ("Milk", "Drink"), ("LactoseFreeMilk", "Drink")}


def is_subclass(a: str, b: str) -> bool:
    return a == b or (a, b) in SUBCLASSES


def box(name: str, centre: tuple[float, float, float], size: tuple[float, float, float], yaw: float = 0.0) -> RegionBox:
    orientation = (0.0, 0.0, float(np.sin(yaw / 2)), float(np.cos(yaw / 2)))
    return RegionBox(name, name.title() + "Region", "world", centre, orientation, size)


FRIDGE = box("fridge", (1.3, 0.85, 0.8), (0.5, 0.5, 1.5))
TABLE = box("table", (0.0, 0.0, 0.95), (1.2, 0.8, 0.5))
CAMERA = CameraIntrinsics(500.0, 500.0, 320.0, 240.0, 640, 480)


def thing(position: tuple[float, float, float], cls: str, color: str, source: str = "Detector") -> FrameObject:
    return FrameObject(
        position=np.array(position, dtype=float),
        frame="world",
        dimensions=np.array([0.2, 0.07, 0.07]),
        evidence=[Evidence("class", cls, 0.8, source), Evidence("color", color, 0.7, "ColorExpert")],
        sources={"Segmenter", source, "ColorExpert"},
        roi=(10, 20, 30, 40),
        confidence=0.9,
    )


@pytest.fixture
def store_path(tmp_path: Path) -> Path:
    return tmp_path / "nested" / "beliefs.sqlite"


def new_store(path: Path) -> BeliefStore:
    return BeliefStore(path, tracker=BeliefTracker(class_test=is_subclass, regions=(FRIDGE, TABLE)))


def test_write_reopen_same_beliefs(store_path: Path) -> None:
    with new_store(store_path) as store:
        store.integrate(
            [thing((1.3, 0.8, 1.05), "LactoseFreeMilk", "white"), thing((0.0, -0.1, 0.8), "Cup", "red")], 1.0
        )
        store.integrate([thing((1.31, 0.8, 1.05), "Milk", "white", "OtherDetector")], 2.0)
        before = {b.id: b for b in store.beliefs()}
        history = store.history(1)
    with new_store(store_path) as reopened:
        after = {b.id: b for b in reopened.beliefs()}
        assert reopened.history(1) == history
    assert set(before) == set(after) == {1, 2}
    for belief_id, old in before.items():
        new = after[belief_id]
        np.testing.assert_allclose(new.position, old.position)
        np.testing.assert_allclose(new.dimensions, old.dimensions)
        for name in ("class_name", "region", "status", "first_seen", "last_seen", "observations", "sources"):
            assert getattr(new, name) == getattr(old, name), name
        assert new.existence == pytest.approx(old.existence)
        assert new.fused(is_subclass) == old.fused(is_subclass)
    milk = after[1]
    assert milk.class_name == "LactoseFreeMilk" and milk.region == "fridge" and milk.observations == 2
    assert {"Detector", "OtherDetector"} <= milk.sources
    assert [h.time for h in history] == [1.0, 2.0]
    assert history[1].evidence[0] == ("class", "Milk", 0.8, "OtherDetector")


def test_query_with_subsumption_region_and_attributes(store_path: Path) -> None:
    with new_store(store_path) as store:
        store.integrate(
            [
                thing((1.3, 0.8, 1.05), "LactoseFreeMilk", "white"),
                thing((0.0, -0.1, 0.8), "Milk", "white"),
                thing((0.3, 0.0, 0.8), "Cup", "red"),
                thing((5.0, 5.0, 0.8), "Milk", "blue"),
            ],
            1.0,
        )
        ids = {b.class_name + "@" + (b.region or "-"): b.id for b in store.beliefs()}
        assert ids.keys() == {"LactoseFreeMilk@fridge", "Milk@table", "Cup@table", "Milk@-"}

        def found(**kwargs: object) -> set[int]:
            return {b.id for b in store.query(BeliefFilter(class_test=is_subclass, **kwargs))}  # type: ignore[arg-type]

        assert found(object_class="Milk") == {ids["LactoseFreeMilk@fridge"], ids["Milk@table"], ids["Milk@-"]}
        assert found(object_class="Drink", region="fridge") == {ids["LactoseFreeMilk@fridge"]}
        assert found(object_class="milk", region="Fridge") == {ids["LactoseFreeMilk@fridge"]}
        assert found(object_class="LactoseFreeMilk") == {ids["LactoseFreeMilk@fridge"]}
        assert found(object_class="Bowl") == set()
        assert found(attributes={"color": "RED"}) == {ids["Cup@table"]}
        assert found(object_class="Milk", attributes={"color": "blue"}) == {ids["Milk@-"]}
        # containment in a region box given by the knowledge base, whatever name the belief stored
        cold = box("cold_zone", (5.0, 5.0, 0.8), (0.4, 0.4, 0.4), yaw=0.7)
        assert found(region="cold_zone", region_boxes=(cold,)) == {ids["Milk@-"]}
        assert found(region="Fridge", region_boxes=(FRIDGE,)) == {ids["LactoseFreeMilk@fridge"]}
        assert len(store.query(BeliefFilter(limit=2))) == 2


def test_beliefs_seen_again_keep_their_id_and_new_ones_get_new_ids(store_path: Path) -> None:
    with new_store(store_path) as store:
        first = store.integrate([thing((0.0, 0.0, 0.8), "Cup", "red"), thing((0.4, 0.0, 0.8), "Bowl", "blue")], 1.0)
        second = store.integrate([thing((0.41, 0.01, 0.8), "Bowl", "blue"), thing((0.0, 0.02, 0.8), "Cup", "red")], 2.0)
        assert second.assigned == (first.assigned[1], first.assigned[0]) and second.created == ()
        third = store.integrate([thing((2.0, 0.0, 0.8), "Cup", "red")], 3.0)
        assert third.created == (3,)


def test_ids_are_never_reused_after_clear(store_path: Path) -> None:
    with new_store(store_path) as store:
        store.integrate([thing((0.0, 0.0, 0.8), "Cup", "red")], 1.0)
        assert store.clear() == 1
        assert store.count() == 0 and store.history(1) == []
        step = store.integrate([thing((0.0, 0.0, 0.8), "Cup", "red")], 2.0)
        assert step.created == (2,)


def test_history_is_bounded_per_object(store_path: Path) -> None:
    store = BeliefStore(store_path, history_limit=10)
    for t in range(40):
        store.integrate([thing((0.0, 0.0, 0.8), "Cup", "red")], float(t))
    history = store.history(1)
    assert 10 <= len(history) <= 26
    assert history[-1].time == 39.0
    assert store.get(1).observations == 40  # type: ignore[union-attr]
    store.close()


def test_put_and_get_round_trip_a_belief(store_path: Path) -> None:
    belief = ObjectBelief(id=7, frame="world", position=np.array([1.0, 2.0, 3.0]), appearance=np.full(4, 0.25))
    with BeliefStore(store_path) as store:
        store.put([belief])
        loaded = store.get(7)
        assert loaded is not None and store.get(8) is None
        np.testing.assert_allclose(loaded.appearance, belief.appearance)
        assert store.allocate_ids(2) == [8, 9]


def test_a_belief_put_twice_in_one_call_is_stored_as_its_last_object(store_path: Path) -> None:
    def painted(color: str, x: float) -> ObjectBelief:
        attributes = {"color": AttributeBelief("color", {color: ValueSupport(1.0, 1, {"Colour"})})}
        return ObjectBelief(id=3, frame="world", position=np.array([x, 0.0, 0.0]), attributes=attributes)

    with BeliefStore(store_path) as store:
        store.put([painted("red", 0.0), painted("blue", 2.0)])
        stored = store.get(3)
        assert stored is not None and stored.value("color") == "blue" and stored.position[0] == 2.0
        assert [b.id for b in store.query(BeliefFilter(attributes={"color": "blue"}))] == [3]
        assert store.query(BeliefFilter(attributes={"color": "red"})) == []  # no index entry of the first object


def test_readers_see_committed_snapshots_while_the_engine_writes(store_path: Path) -> None:
    writer = new_store(store_path)
    errors: list[BaseException] = []
    counts: list[list[int]] = [[], []]
    started = threading.Barrier(3)
    done = threading.Event()

    def read(seen: list[int]) -> None:
        try:
            with BeliefStore(store_path) as reader:
                started.wait()
                while not done.is_set():
                    beliefs = reader.beliefs()
                    seen.append(len(beliefs))
                    # every belief a reader sees is complete: its attributes came in the same transaction
                    assert all(b.class_name == "Cup" and "color" in b.attributes for b in beliefs)
        except BaseException as error:
            errors.append(error)

    readers = [threading.Thread(target=read, args=(seen,)) for seen in counts]
    for t in readers:
        t.start()
    try:
        started.wait()
        for i in range(150):
            writer.integrate([thing((0.5 * i, 0.0, 0.8), "Cup", "red")], float(i))
    finally:
        done.set()
        for t in readers:
            t.join()
        writer.close()
    assert not errors, errors
    for seen in counts:
        assert len(seen) > 5 and seen == sorted(seen)  # a reader only ever sees more committed objects
        assert seen[0] < 150 and seen[-1] <= 150


def test_a_slowly_drifting_object_is_tracked_and_found_where_it_is_now(store_path: Path) -> None:
    with new_store(store_path) as store:
        ids = set()
        for step in range(30):  # 1 cm per frame: 30 cm in all, more than the association gate
            ids.update(store.integrate([thing((0.01 * step, 0.0, 0.8), "Cup", "red")], float(step)).assigned)
        assert ids == {1}
        (cup,) = store.beliefs()
        assert cup.position[0] > 0.2
        here = box("here", (cup.position[0], 0.0, 0.8), (0.04, 0.04, 0.04))
        assert [b.id for b in store.query(BeliefFilter(region="here", region_boxes=(here,)))] == [1]
        start = box("start", (0.0, 0.0, 0.8), (0.04, 0.04, 0.04))
        assert store.query(BeliefFilter(region="start", region_boxes=(start,))) == []


def test_the_attribute_index_follows_the_fused_value(store_path: Path) -> None:
    with new_store(store_path) as store:
        store.integrate([thing((0.0, 0.0, 0.8), "Cup", "red")], 0.0)

        def colours() -> tuple[int, int]:
            red = len(store.query(BeliefFilter(attributes={"color": "red"})))
            blue = len(store.query(BeliefFilter(object_class="Cup", attributes={"color": "blue"})))
            return red, blue

        assert colours() == (1, 0)
        for t in range(1, 6):
            store.integrate([thing((0.0, 0.0, 0.8), "Cup", "blue")], float(t))
        assert colours() == (0, 1)
        (cup,) = store.beliefs()
        fused = cup.fused()["color"]
        assert fused.value == "blue" and fused.conflict and {s.value for s in fused.support} == {"red", "blue"}


def test_a_reader_opens_and_reads_while_a_write_transaction_is_open(store_path: Path) -> None:
    with new_store(store_path) as store:
        store.integrate([thing((0.0, 0.0, 0.8), "Cup", "red")], 0.0)
    writer = sqlite3.connect(store_path, isolation_level=None)
    writer.execute("BEGIN IMMEDIATE")
    writer.execute("UPDATE objects SET last_seen = 99")
    try:
        started = time.monotonic()
        with BeliefStore(store_path, busy_timeout=5.0) as reader:
            (cup,) = reader.beliefs()
            assert cup.last_seen == 0.0  # the committed snapshot, not the open transaction
        assert time.monotonic() - started < 1.0
    finally:
        writer.execute("ROLLBACK")
        writer.close()


def test_a_missed_object_is_gone_after_the_configured_time_even_out_of_view(store_path: Path) -> None:
    looking_at_origin = CameraModel(CAMERA, camera_looking_at_origin((0.0, -1.0, 0.8)))
    looking_away = CameraModel(CAMERA, camera_looking_at_origin((0.0, 1.0, 0.8)))
    tracker = BeliefTracker(TrackerConfig(gone_after=5.0))
    with BeliefStore(store_path, tracker=tracker) as store:
        store.integrate([thing((0.0, 0.0, 0.8), "Cup", "red")], 0.0, camera=looking_at_origin)
        step = store.integrate([], 1.0, camera=looking_at_origin)  # it should have been seen: a miss
        assert step.missed == (1,) and store.get(1).status == PRESENT  # type: ignore[union-attr]
        store.integrate([thing((0.0, 3.0, 0.8), "Bowl", "blue")], 4.0, camera=looking_away)
        assert store.get(1).status == PRESENT  # type: ignore[union-attr]
        store.integrate([thing((0.0, 3.0, 0.8), "Bowl", "blue")], 5.5, camera=looking_away)
        assert store.get(1).status == GONE  # type: ignore[union-attr]
        assert [b.class_name for b in store.beliefs()] == ["Bowl"]
        assert len(store.beliefs(include_gone=True)) == 2


def test_a_frame_misses_only_the_classes_its_detectors_look_for(store_path: Path) -> None:
    in_view = camera_looking_at_origin((0.0, -1.0, 0.8))
    people_only = CameraModel(CAMERA, in_view, looks_for=lambda name: name == "Human")
    with BeliefStore(store_path) as store:
        store.integrate([thing((0.0, 0.0, 0.8), "Cup", "red"), thing((0.3, 0.0, 0.8), "Human", "blue")], 0.0)
        step = store.integrate([], 1.0, camera=people_only)  # a tree that finds people says nothing of the cup
        assert step.missed == (2,)
        assert store.get(1).misses == 0 and store.get(2).misses == 1  # type: ignore[union-attr]
        step = store.integrate([], 2.0, camera=CameraModel(CAMERA, in_view))  # one that looks for everything
        assert set(step.missed) == {1, 2}
