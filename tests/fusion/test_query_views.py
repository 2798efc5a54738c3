"""Answers from memory remember a view per stored row: they equal the designators made afresh from the beliefs the
store gives, also after this store, another connection or a new frame changed the rows, and a row's view is made
again exactly when the row changed."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from reasoning.beliefs.answer import answer_from_memory, class_label, designator
from reasoning.beliefs.store import BeliefFilter, BeliefStore
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import AttributeBelief, Evidence, ValueSupport
from reasoning.fusion.tracking import BeliefTracker, ObjectBelief
from robokudo.core.regions import RegionBox

PARENT = {"LactoseFreeMilk": "Milk", "WholeMilk": "Milk"}


def is_subclass(a: str, b: str) -> bool:
    return a == b or PARENT.get(a) == b


def belief(object_id: int, x: float, classes: dict[str, float], color: str = "white") -> ObjectBelief:
    """A stored belief whose class attribute holds ``classes`` (value -> log-odds): several values conflict or
    subsume one another."""
    return ObjectBelief(
        id=object_id,
        frame="world",
        position=np.array([x, 0.5, 0.8]),
        dimensions=np.array([0.2, 0.1, 0.07]),
        attributes={
            "class": AttributeBelief(
                "class", {c: ValueSupport(lo, 1, {"Detector"}, 0.0, 0.0) for c, lo in classes.items()}
            ),
            "color": AttributeBelief("color", {color: ValueSupport(0.8, 1, {"ColorExpert"}, 0.0, 0.0)}),
        },
        existence=1.0 + object_id / 10.0,
        class_name=max(classes, key=classes.__getitem__) if max(classes.values()) > 0 else None,
        sources={"Detector", "ColorExpert"},
        observations=1,
        region="kitchen" if object_id % 2 else "",
    )


FRIDGE = RegionBox("fridge", "FridgeInterior", "world", (1.0, 0.5, 0.8), (0.0, 0.0, 0.383, 0.924), (1.0, 1.0, 1.0))
FILTERS = [
    BeliefFilter(object_class="Milk", class_test=is_subclass),
    BeliefFilter(object_class="Milk", class_test=is_subclass, region="fridge", region_boxes=(FRIDGE,)),
    BeliefFilter(region="kitchen"),
    BeliefFilter(attributes={"color": "red"}),
    BeliefFilter(),
]


def afresh(store: BeliefStore, belief_filter: BeliefFilter) -> list[dict]:
    """The reference: every designator made from the beliefs :meth:`BeliefStore.query` gives."""
    beliefs = sorted(store.query(belief_filter), key=lambda b: (-b.confidence, b.id))
    return [
        designator(b, class_test=belief_filter.class_test, asked_class=belief_filter.object_class).to_dict()
        for b in beliefs
    ]


def remembered(store: BeliefStore, belief_filter: BeliefFilter) -> list[dict]:
    return [d.to_dict() for d in answer_from_memory(store, belief_filter).objects]


def seeded(path: Path) -> BeliefStore:
    store = BeliefStore(path, tracker=BeliefTracker(class_test=is_subclass))
    unnamed = belief(6, 2.0, {"Cup": 1.0, "Bowl": 0.2})  # named by its fused class only
    unnamed.class_name = None
    store.put(
        [
            unnamed,
            belief(1, 0.8, {"Milk": 1.4}),
            belief(2, 1.1, {"LactoseFreeMilk": 1.2, "Milk": 0.4}),  # subsumption: the class test decides
            belief(3, 1.3, {"WholeMilk": 0.9, "Cup": 0.9}, "red"),  # a conflict
            belief(4, 3.0, {"Cup": 2.0}, "red"),
            belief(5, 0.9, {"Milk": -0.5, "Bowl": -0.2}),  # no class supported
        ],
        is_subclass,
    )
    return store


def test_remembered_answers_equal_designators_made_afresh(tmp_path: Path) -> None:
    store = seeded(tmp_path / "b.sqlite")
    for _ in range(2):  # the second time from the memo
        for belief_filter in FILTERS:
            assert remembered(store, belief_filter) == afresh(store, belief_filter)
    # the same rows under another class test: the class attribute is fused with the test asked for
    plain = BeliefFilter(object_class="Milk")
    assert remembered(store, plain) == afresh(store, plain)
    store.close()


def test_answers_follow_changes_by_this_store_another_connection_and_frames(tmp_path: Path) -> None:
    path = tmp_path / "b.sqlite"
    store = seeded(path)
    before = {id(f): remembered(store, f) for f in FILTERS}
    store.put([belief(4, 3.0, {"Cup": 2.0, "Milk": 2.5})], is_subclass)  # this store
    with BeliefStore(path) as other:  # another connection
        other.put([belief(1, 0.8, {"Milk": 1.4}, "red")], is_subclass)
    evidence = [Evidence("color", "green", 0.9, "ColorExpert"), Evidence("class", "Milk", 0.9, "Detector")]
    store.integrate([FrameObject(np.array([1.1, 0.5, 0.8]), "world", dimensions=np.array([0.2, 0.1, 0.07]),
                                 evidence=evidence)], 5.0)  # fmt: skip
    changed = False
    for belief_filter in FILTERS:
        now = remembered(store, belief_filter)
        assert now == afresh(store, belief_filter)
        changed |= now != before[id(belief_filter)]
    assert changed
    store.close()


def test_a_view_is_made_again_exactly_for_changed_rows(tmp_path: Path) -> None:
    store = seeded(tmp_path / "b.sqlite")
    made: list[int] = []

    def view(b: ObjectBelief) -> int:
        made.append(b.id)
        return b.id

    everything = BeliefFilter()
    assert store.query_views(everything, view) == [1, 2, 3, 4, 5, 6]
    assert sorted(made) == [1, 2, 3, 4, 5, 6]
    made.clear()
    assert store.query_views(everything, view) == [1, 2, 3, 4, 5, 6]
    assert made == []
    store.put([belief(3, 1.35, {"WholeMilk": 0.9, "Cup": 0.9}, "red")], is_subclass)
    assert store.query_views(everything, view) == [1, 2, 3, 4, 5, 6]
    assert made == [3]
    store.close()


def test_designators_carry_each_attribute_fused_with_the_query_class_test(tmp_path: Path) -> None:
    """Against the fusion rule itself (:meth:`ObjectBelief.fused`): the class attribute of several values is fused
    with the filter's class test, the others as they are; an unnamed belief takes the supported fused class."""
    store = seeded(tmp_path / "b.sqlite")
    for class_test in (is_subclass, None):
        belief_filter = BeliefFilter(class_test=class_test)
        beliefs = {b.id: b for b in store.query(belief_filter)}
        for found in answer_from_memory(store, belief_filter).objects:
            every = beliefs[found.id].fused(class_test)
            assert {
                name: (a.value, a.confidence, a.experts, [(x.value, x.confidence, x.experts) for x in a.alternatives])
                for name, a in found.attributes.items()
            } == {
                name: (f.value, f.confidence, f.sources, [(s.value, s.confidence, s.sources) for s in f.support])
                for name, f in every.items()
            }
            assert {name: a.conflict for name, a in found.attributes.items()} == {
                name: f.conflict for name, f in every.items()
            }
            named = beliefs[found.id].class_name
            fused_class = every.get("class")
            if named is None and fused_class is not None and fused_class.supported:
                named = fused_class.value
            assert found.class_label == (class_label(named) if named else "unknown object")
    store.close()
