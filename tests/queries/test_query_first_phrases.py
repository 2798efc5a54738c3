"""Properties of the first phrases and keys a new user tries: sizes, confidence, shapes, 'anywhere'."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from queries import QueryError, Symbol, format_query, parse_query
from queries.lexicon import COLORS, SHAPE_NOUNS, SIZES

_UNITS = {"mm": 0.001, "cm": 0.01, "m": 1.0}
lengths = st.tuples(st.integers(0, 5000), st.sampled_from(sorted(_UNITS)))


@given(lengths, lengths)
def test_any_metric_size_range_is_refused_at_the_size_key(low: tuple[int, str], high: tuple[int, str]) -> None:
    (a, unit_a), (b, unit_b) = sorted([low, high], key=lambda q: q[0] * _UNITS[q[1]])
    text = f"detect {{ obj: {{ type: Box, size: {a}{unit_a}..{b}{unit_b} }} }}"
    with pytest.raises(QueryError) as caught:
        parse_query(text)
    assert (caught.value.line, caught.value.column) == (1, 28)
    assert "'size' takes a size word" in str(caught.value)


@given(lengths, lengths)
def test_any_metric_width_range_parses_and_prints_canonically(low: tuple[int, str], high: tuple[int, str]) -> None:
    (a, unit_a), (b, unit_b) = sorted([low, high], key=lambda q: q[0] * _UNITS[q[1]])
    query = parse_query(f"detect {{ obj: {{ width: {a}{unit_a}..{b}{unit_b} }} }}")
    canonical = format_query(query)
    assert parse_query(canonical) == query
    assert format_query(parse_query(canonical)) == canonical


@given(st.floats(-2.0, 3.0, allow_nan=False))
def test_confidence_is_accepted_exactly_from_0_to_1(value: float) -> None:
    text = f"detect {{ obj: {{ type: Cup, confidence: {value!r} }} }}"
    if 0.0 <= value <= 1.0:
        query = parse_query(text)
        assert parse_query(format_query(query)) == query
    else:
        with pytest.raises(QueryError, match="'confidence' must be a number from 0 to 1"):
            parse_query(text)


@given(
    st.lists(st.sampled_from(sorted(COLORS)), max_size=2),
    st.lists(st.sampled_from(sorted(SIZES)), max_size=1),
    st.sampled_from(sorted(SHAPE_NOUNS)),
    st.sampled_from(["", " anywhere", " on the table"]),
)
def test_a_shape_noun_is_a_shape_never_a_class(colors: list[str], sizes: list[str], noun: str, place: str) -> None:
    query = parse_query(f"find the {' '.join([*sizes, *colors, noun])}{place}")
    obj = query.get("obj")
    assert query.get("obj.type") is None
    shapes = query.get("obj.shape")
    assert shapes == Symbol(SHAPE_NOUNS[noun]), obj
    assert (query.get("obj.location") == Symbol("anywhere")) == (place == " anywhere")
    assert parse_query(format_query(query)) == query
