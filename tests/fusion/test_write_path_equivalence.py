"""The belief write path's faster steps give exactly what the plain ones give: statements accumulated in one
pass the supports of :meth:`AttributeBelief.add` one by one (bit for bit), the assignment that skips the Hungarian
when no two feasible pairs conflict the Hungarian's own, and the support update and log-odds with min, max and
clamp written out the values of the plain forms."""

from __future__ import annotations

import json
import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linear_sum_assignment

from reasoning.beliefs.packed import rounded as _rounded
from reasoning.fusion.association import INFEASIBLE, assign
from reasoning.fusion.rule import (
    CONFIDENCE_CLIP,
    MAX_LOG_ODDS,
    AttributeBelief,
    Evidence,
    ValueSupport,
    accumulate_into,
    logit,
)

STATEMENTS = st.lists(
    st.tuples(
        st.sampled_from(["class", "color", "shape"]),
        st.sampled_from(["a", "b", "c"]),
        st.floats(-0.5, 1.5, allow_nan=False) | st.sampled_from([0.0, 0.01, 0.5, 0.99, 1.0]),
        st.sampled_from(["E1", "E2"]),
        st.floats(-5.0, 5.0, allow_nan=False),
    ),
    max_size=30,
)


def _state(beliefs: dict[str, AttributeBelief]) -> list[tuple]:
    return [
        (name, value, s.log_odds, s.count, sorted(s.sources), s.first_seen, s.last_seen)
        for name, belief in beliefs.items()
        for value, s in belief.values.items()
    ]


@settings(max_examples=300, deadline=None)
@given(first=STATEMENTS, second=STATEMENTS, stamp=st.none() | st.floats(-5.0, 5.0, allow_nan=False))
def test_accumulating_in_one_pass_equals_adding_statements_one_by_one(
    first: list[tuple], second: list[tuple], stamp: float | None
) -> None:
    one_pass: dict[str, AttributeBelief] = {}
    one_by_one: dict[str, AttributeBelief] = {}
    for batch in (first, second):  # a second frame meets the supports the first one left
        evidence = [Evidence(a, v, c, s, t) for a, v, c, s, t in batch]
        accumulate_into(one_pass, evidence, stamp)
        for item in evidence:
            one_by_one.setdefault(item.attribute, AttributeBelief(item.attribute)).add(item, stamp)
    assert _state(one_pass) == _state(one_by_one)


def hungarian(cost: np.ndarray) -> list[tuple[int, int]]:
    """The reference: one Hungarian on the whole matrix, infeasible pairs rejected afterwards."""
    rows, cols = linear_sum_assignment(cost)
    return sorted((int(i), int(j)) for i, j in zip(rows, cols, strict=True) if cost[i, j] < INFEASIBLE)


@settings(max_examples=400, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    shape=st.tuples(st.integers(2, 12), st.integers(2, 12)),
    density=st.sampled_from([0.05, 0.15, 0.4, 1.0]),
)
def test_assignment_equals_the_hungarian_on_random_sparse_frames(
    seed: int, shape: tuple[int, int], density: float
) -> None:
    rng = np.random.default_rng(seed)
    cost = np.where(rng.random(shape) < density, rng.uniform(0.0, 20.0, shape), INFEASIBLE)
    found = assign(cost)
    assert sorted((i, j) for i, j, _ in found.matches) == hungarian(cost)
    assert [i for i, _, _ in found.matches] == sorted(i for i, _, _ in found.matches)  # by observation
    assert all(c == cost[i, j] for i, j, c in found.matches)


@settings(max_examples=300, deadline=None)
@given(
    values=st.lists(
        st.floats(allow_nan=True, allow_infinity=True) | st.integers(-5, 5) | st.sampled_from([0.0, -0.0, 0.8, 1.4]),
        max_size=20,
    ),
    digits=st.sampled_from([6, 9]),
)
def test_remembered_rounding_gives_the_text_of_round(values: list[float], digits: int) -> None:
    numpy = [np.float64(v) for v in values if abs(v) < 1e6]  # (numpy warns of overflow rounding huge ones)
    for value in values + values + numpy:  # the second time answered from the cache
        assert json.dumps(_rounded(value, digits)) == json.dumps(round(value, digits))
        assert type(_rounded(value, digits)) is type(round(value, digits))


NUMBERS = (
    st.floats(allow_nan=True, allow_infinity=True)
    | st.integers(-10, 10)
    | st.sampled_from([0.0, -0.0, 0.01, 0.99, MAX_LOG_ODDS, -MAX_LOG_ODDS, 6.0, -6.0])
)


def _same(a: object, b: object) -> bool:
    """Equal values of one type (NaN equal to NaN, 0.0 not to -0.0)."""
    return type(a) is type(b) and (json.dumps(a) == json.dumps(b)) and (a == b or a != a)


@settings(max_examples=400, deadline=None)
@given(
    start=st.tuples(NUMBERS, st.integers(0, 3), NUMBERS, NUMBERS),
    steps=st.lists(st.tuples(NUMBERS, NUMBERS, st.integers(1, 3)), max_size=6),
)
def test_value_support_add_is_the_rule_with_min_max_and_clamp(start: tuple, steps: list[tuple]) -> None:
    log_odds, count, first_seen, last_seen = start
    support = ValueSupport(log_odds, count, set(), first_seen, last_seen)
    reference = [log_odds, count, first_seen, last_seen]
    for added, time, times in steps:
        support.add(added, ("E",), time, times)
        reference[2] = time if reference[1] == 0 else min(reference[2], time)
        reference[0] = min(max(reference[0] + added, -MAX_LOG_ODDS), MAX_LOG_ODDS)
        reference[1] += times
        reference[3] = max(reference[3], time)
        found = [support.log_odds, support.count, support.first_seen, support.last_seen]
        assert all(_same(a, b) for a, b in zip(found, reference, strict=True)), (found, reference)


@settings(max_examples=300, deadline=None)
@given(confidence=NUMBERS)
def test_logit_is_the_log_odds_of_the_clipped_confidence(confidence: float) -> None:
    low, high = CONFIDENCE_CLIP
    p = min(max(float(confidence), low), high)
    expected = math.log(p / (1.0 - p))
    assert _same(logit(confidence), expected)
