"""The probability that an object answers to the asked class: the fused class distribution's mass on the classes the
query's class test accepts (the class, its subclasses, classes packaged in it), each counted once.

A small taxonomy with packaging stands in for the ontology: a mustard and a dish soap are packaged in plastic
bottles, a ketchup (a subclass of bottle in this taxonomy) is packaged in one too, so it answers "bottle" by both
paths; a lemon soda is packaged in a can.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from reasoning.beliefs.answer import Answer, designator
from reasoning.beliefs.ranking import match_probability
from reasoning.beliefs.store import BeliefFilter
from reasoning.fusion.rule import (
    CLASS_ATTRIBUTE,
    MAX_LOG_ODDS,
    AttributeBelief,
    Evidence,
    ValueSupport,
    answer_probability,
    fuse_values,
    logit,
)
from reasoning.fusion.tracking import ObjectBelief

PARENT = {
    "Bottle": "Container",
    "PlasticBottle": "Bottle",
    "GlassBottle": "Bottle",
    "Ketchup": "Bottle",
    "Can": "Container",
    "Cup": "Container",
    "Mug": "Container",
    "Mustard": "Condiment",
    "Condiment": "Food",
    "LemonSoda": "Drink",
    "DishSoap": "Cleaner",
}
PACKAGED_IN = {"Mustard": "PlasticBottle", "Ketchup": "PlasticBottle", "DishSoap": "PlasticBottle", "LemonSoda": "Can"}


def is_subclass(name: str, ancestor: str) -> bool:
    while name:
        if name == ancestor:
            return True
        name = PARENT.get(name, "")
    return False


def answers_to(name: str, asked: str) -> bool:
    package = PACKAGED_IN.get(name)
    return is_subclass(name, asked) or (package is not None and is_subclass(package, asked))


def supports(**confidences: float) -> dict[str, ValueSupport]:
    return {name: ValueSupport(logit(c), 1, {"E"}) for name, c in confidences.items()}


def test_one_statement_gives_back_its_confidence_for_every_class_it_answers_to() -> None:
    mustard = supports(Mustard=0.01)
    assert answer_probability(mustard, "Bottle", answers_to) == pytest.approx(0.01)  # packaged in one
    assert answer_probability(mustard, "Condiment", answers_to) == pytest.approx(0.01)  # is one
    assert answer_probability(mustard, "Can", answers_to) == 0.0
    assert answer_probability(mustard, "Mustard", answers_to) == pytest.approx(0.01)


def test_a_class_that_is_a_subclass_and_packaged_in_the_asked_class_counts_once() -> None:
    # the ketchup is a bottle and packaged in a plastic bottle: its support counts once toward "bottle"
    alone = supports(Ketchup=0.7)
    assert answer_probability(alone, "Bottle", answers_to) == pytest.approx(0.7)
    both = supports(PlasticBottle=0.6, Ketchup=0.7)
    expected = 1.0 / (1.0 + math.exp(-(logit(0.6) + logit(0.7))))
    assert answer_probability(both, "Bottle", answers_to) == pytest.approx(expected)
    fused = fuse_values(CLASS_ATTRIBUTE, both, answers_to)
    naive = fused.confidence_of("PlasticBottle") + fused.confidence_of("Ketchup")
    assert naive > 1.0 > answer_probability(both, "Bottle", answers_to)


def test_unrelated_answering_classes_add_up_and_the_rest_argues_against() -> None:
    values = supports(Mustard=0.3, DishSoap=0.2, LemonSoda=0.3)
    fused = fuse_values(CLASS_ATTRIBUTE, values, answers_to)
    mass = answer_probability(values, "Bottle", answers_to)
    assert mass == pytest.approx(fused.confidence_of("Mustard") + fused.confidence_of("DishSoap"))
    odds = {name: c / (1 - c) for name, c in (("Mustard", 0.3), ("DishSoap", 0.2), ("LemonSoda", 0.3))}
    assert mass == pytest.approx((odds["Mustard"] + odds["DishSoap"]) / (1 + sum(odds.values())))


def test_a_class_above_an_answering_one_does_not_argue_against_the_asked_class() -> None:
    # "condiment" includes the mustard: it says nothing against "bottle"
    values = supports(Mustard=0.3, Condiment=0.9)
    assert answer_probability(values, "Bottle", answers_to) == pytest.approx(0.3)


def test_the_asked_class_stated_gives_its_fused_probability() -> None:
    values = supports(Cup=0.33, Mug=0.4, PlasticBottle=0.2)
    fused = fuse_values(CLASS_ATTRIBUTE, values, answers_to)
    assert answer_probability(values, "Cup", answers_to) == pytest.approx(fused.confidence_of("Cup"))


# ---------------------------------------------------------------------------------------------------- properties

CLASSES = [f"C{i}" for i in range(8)]


@st.composite
def taxonomies(draw: st.DrawFn, packaging: bool = True) -> tuple[dict[str, str], dict[str, str]]:
    """A random tree (each class' parent comes before it, or none) and, when ``packaging``, some classes packaged in
    others."""
    parent = {}
    for i, name in enumerate(CLASSES[1:], start=1):
        above = draw(st.one_of(st.none(), st.integers(0, i - 1)))
        if above is not None:
            parent[name] = CLASSES[above]
    package = {}
    if packaging:
        for name in CLASSES:
            inside = draw(st.one_of(st.none(), st.sampled_from(CLASSES)))
            if inside is not None and inside != name:
                package[name] = inside
    return parent, package


def relations(parent: dict[str, str], package: dict[str, str]) -> tuple:
    def subclass(name: str, ancestor: str) -> bool:
        while name:
            if name == ancestor:
                return True
            name = parent.get(name, "")
        return False

    def answers(name: str, asked: str) -> bool:
        return subclass(name, asked) or (name in package and subclass(package[name], asked))

    return subclass, answers


STATED = st.dictionaries(
    st.sampled_from(CLASSES), st.floats(-MAX_LOG_ODDS, MAX_LOG_ODDS, allow_nan=False), min_size=1, max_size=6
).map(lambda log_odds: {v: ValueSupport(lo, 1, {"E"}) for v, lo in log_odds.items()})


@given(taxonomy=taxonomies(), values=STATED, asked=st.sampled_from(CLASSES))
def test_the_probability_of_answering_is_a_probability(taxonomy: tuple, values: dict, asked: str) -> None:
    _, answers = relations(*taxonomy)
    assert 0.0 <= answer_probability(values, asked, answers) <= 1.0


@given(taxonomy=taxonomies(packaging=False), values=STATED, asked=st.sampled_from(CLASSES))
def test_the_asked_class_stated_keeps_todays_figure(taxonomy: tuple, values: dict, asked: str) -> None:
    subclass, _ = relations(*taxonomy)
    values.setdefault(asked, ValueSupport(0.4, 1, {"E"}))
    fused = fuse_values(CLASS_ATTRIBUTE, values, subclass)
    assert answer_probability(values, asked, subclass) == pytest.approx(fused.confidence_of(asked), rel=1e-9)


@given(taxonomy=taxonomies(packaging=False), values=STATED, asked=st.sampled_from(CLASSES))
def test_the_answering_mass_is_at_least_that_of_each_most_general_answering_class(
    taxonomy: tuple, values: dict, asked: str
) -> None:
    subclass, _ = relations(*taxonomy)
    fused = fuse_values(CLASS_ATTRIBUTE, values, subclass)
    mass = answer_probability(values, asked, subclass)
    members = [v for v in values if subclass(v, asked)]
    for m in members:
        if not any(n != m and subclass(m, n) for n in members):
            assert mass >= fused.confidence_of(m) - 1e-9


@given(
    packaged=st.lists(st.booleans(), min_size=8, max_size=8),
    log_odds=st.lists(st.floats(-MAX_LOG_ODDS, MAX_LOG_ODDS, allow_nan=False), min_size=8, max_size=8),
)
def test_unrelated_classes_answering_add_up_each_once(packaged: list[bool], log_odds: list[float]) -> None:
    """Leaves of no common class, some packaged in a container ``Box`` nobody stated (an answering class through
    its package, or a subclass of it, counts once either way)."""
    package = {name: "Box" for name, p in zip(CLASSES, packaged, strict=True) if p}
    parent = {name: "Box" for name in CLASSES[:2] if name in package}  # both a subclass and packaged
    _, answers = relations(parent, package)
    values = {name: ValueSupport(lo, 1, {"E"}) for name, lo in zip(CLASSES, log_odds, strict=True)}
    fused = fuse_values(CLASS_ATTRIBUTE, values, answers)
    expected = sum(fused.confidence_of(name) for name in values if answers(name, "Box"))
    assert answer_probability(values, "Box", answers) == pytest.approx(expected, rel=1e-9, abs=1e-12)


# ---------------------------------------------------------------------------------------------------- answers


def belief(object_id: int, confidence: float, **classes: float) -> ObjectBelief:
    made = ObjectBelief(id=object_id, frame="camera", position=np.zeros(3), existence=logit(confidence))
    statements = AttributeBelief(CLASS_ATTRIBUTE)
    for name, c in classes.items():
        statements.add(Evidence(CLASS_ATTRIBUTE, name, c, "KnowledgeClassifier"))
    made.attributes[CLASS_ATTRIBUTE] = statements
    return made


def test_an_answer_shows_and_ranks_by_the_probability_of_answering_the_query() -> None:
    mustard = belief(1, 0.8, Mustard=0.4, DishSoap=0.4)  # which of two bottled products: likely a bottle
    glass = belief(2, 0.8, GlassBottle=0.5)
    asked = BeliefFilter(object_class="Bottle", class_test=answers_to, limit=1)
    shown = designator(mustard, class_test=answers_to, asked_class="Bottle", guessed_class="Bottle")
    odds = 0.4 / 0.6
    assert shown.answers == pytest.approx(2 * odds / (1 + 2 * odds))
    assert shown.attributes[CLASS_ATTRIBUTE].confidence == pytest.approx(odds / (1 + 2 * odds))  # the leaf's
    line = Answer("find all bottles", (shown,)).summary()
    assert line.startswith("#1 bottle at") and f"class {shown.answers:.2f}" in line
    assert json.loads(json.dumps(shown.to_dict()))["class"]["answers"] == pytest.approx(shown.answers, abs=1e-6)
    assert match_probability(mustard, asked) > match_probability(glass, asked)
    unasked = designator(mustard, class_test=answers_to)
    assert unasked.answers is None and "answers" not in unasked.to_dict()["class"]
    assert "?" in unasked.shown_label()
