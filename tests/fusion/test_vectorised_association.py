"""The tracker's vectorised association (one numpy cost matrix per frame) against the reference: :func:`pair_cost`
for every pair and one Hungarian on the full matrix. Random frames mix worlds, sizes (some missing or with zero
extents), histograms (some of another shape), colours and classes, with many pairs inside the gates."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from reasoning.fusion.association import (
    INFEASIBLE,
    AssociationConfig,
    assign,
    associate,
    geometric_costs,
    pair_cost,
    typical_size,
    typical_sizes,
)
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import AttributeBelief, Evidence, ValueSupport
from reasoning.fusion.tracking import BeliefTracker, ObjectBelief, TrackerConfig

CLASSES = ("Milk", "LactoseFreeMilk", "Cup", "Bowl")
COLORS = ("red", "blue", "white")


def is_subclass(a: str, b: str) -> bool:
    return a == b or (a, b) == ("LactoseFreeMilk", "Milk")


def _dimensions(rng: np.random.Generator) -> np.ndarray | None:
    kind = rng.integers(5)
    if kind == 0:
        return None
    dims = rng.uniform(0.02, 0.4, 3)
    if kind == 1:
        dims[rng.integers(3)] = 0.0  # a flat extent: typical size of the positive ones
    return dims


def _appearance(rng: np.random.Generator) -> np.ndarray | None:
    kind = rng.integers(4)
    if kind == 0:
        return None
    histogram = rng.random(8 if kind == 1 else 4) ** 3
    return histogram / histogram.sum()


def _world(rng: np.random.Generator) -> tuple[str, str]:
    return ("world", "") if rng.random() < 0.8 else ("camera", str(rng.integers(2)))


def random_frame(seed: int) -> tuple[list[FrameObject], list[ObjectBelief]]:
    """Observations and beliefs crowded into a 40 cm cube, so that gates and costs decide the assignment."""
    rng = np.random.default_rng(seed)
    observations, beliefs = [], []
    for _ in range(int(rng.integers(0, 12))):
        frame, recording = _world(rng)
        evidence = [Evidence("color", str(rng.choice(COLORS)), 0.8, "Colour")] if rng.random() < 0.7 else []
        if rng.random() < 0.7:
            evidence.append(Evidence("class", str(rng.choice(CLASSES)), 0.7, "Detector"))
        observations.append(
            FrameObject(
                position=rng.uniform(0.0, 0.4, 3),
                frame=frame,
                recording=recording,
                dimensions=_dimensions(rng),
                appearance=_appearance(rng),
                evidence=evidence,
            )
        )
    for number in range(int(rng.integers(0, 12))):
        frame, recording = _world(rng)
        attributes = {}
        if rng.random() < 0.7:
            values = {str(c): ValueSupport(float(rng.uniform(-1, 3)), 1, {"Colour"}) for c in rng.choice(COLORS, 2)}
            attributes["color"] = AttributeBelief("color", values)
        beliefs.append(
            ObjectBelief(
                id=number + 1,
                frame=frame,
                recording=recording,
                position=rng.uniform(0.0, 0.4, 3),
                dimensions=_dimensions(rng),
                appearance=_appearance(rng),
                attributes=attributes,
                class_name=str(rng.choice(CLASSES)) if rng.random() < 0.7 else None,
            )
        )
    return observations, beliefs


def reference_cost(
    observations: list[FrameObject], beliefs: list[ObjectBelief], config: AssociationConfig
) -> np.ndarray:
    """pair_cost for every pair (no pre-gate), with the colours and classes the tracker passes."""
    cost = np.full((len(observations), len(beliefs)), INFEASIBLE)
    for i, observation in enumerate(observations):
        for j, belief in enumerate(beliefs):
            cost[i, j] = pair_cost(
                observation,
                belief,
                config,
                observation_colors=observation.values("color"),
                belief_color=belief.value("color"),
                observation_classes=observation.values("class"),
                belief_class=belief.class_name,
                class_test=is_subclass,
            )
    return cost


@settings(max_examples=300, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), gate=st.sampled_from([0.05, 0.15, 0.3]))
def test_vectorised_association_gives_the_reference_assignment(seed: int, gate: float) -> None:
    observations, beliefs = random_frame(seed)
    config = AssociationConfig(gate_distance=gate)
    reference = reference_cost(observations, beliefs, config)
    tracker = BeliefTracker(TrackerConfig(association=config), class_test=is_subclass)
    vectorised = tracker.associate(observations, beliefs)
    expected = assign(reference)
    assert sorted((i, j) for i, j, _ in vectorised.matches) == sorted((i, j) for i, j, _ in expected.matches)
    assert vectorised.new == expected.new and vectorised.unmatched == expected.unmatched
    for i, j, cost in vectorised.matches:
        assert cost == reference[i, j] or abs(cost - reference[i, j]) <= 1e-9 * max(1.0, reference[i, j])


@settings(max_examples=200, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_geometric_costs_match_pair_cost_without_colours_and_classes(seed: int) -> None:
    observations, beliefs = random_frame(seed)
    config = AssociationConfig()
    cost, _ = geometric_costs(observations, beliefs, config)
    for i, observation in enumerate(observations):
        for j, belief in enumerate(beliefs):
            expected = pair_cost(observation, belief, config)
            assert (cost[i, j] == INFEASIBLE) == (expected == INFEASIBLE)
            assert abs(cost[i, j] - expected) <= 1e-9 * max(1.0, expected)
    assert associate(observations, beliefs, config).matches == assign(cost).matches


def test_typical_sizes_of_many_equal_typical_size_of_each() -> None:
    rng = np.random.default_rng(3)
    items = [FrameObject(position=np.zeros(3), frame="world", dimensions=_dimensions(rng)) for _ in range(200)]
    items.append(FrameObject(position=np.zeros(3), frame="world", dimensions=np.array([0.3, 0.2])))
    sizes = typical_sizes(items)
    for item, size in zip(items, sizes.tolist(), strict=True):
        assert size == (0.0 if item.dimensions is None else typical_size(item.dimensions))
