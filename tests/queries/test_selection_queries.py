"""Selections among the objects found: ``the top box``, ``the leftmost cup``, ``the box on the left``, ``the second
biggest bowl`` and their nested form ``select: top`` / ``select: { by: biggest, rank: 2 }``."""

from __future__ import annotations

import json

import pytest
from hypothesis import given
from hypothesis import strategies as st

from queries import (
    Block,
    Field,
    Number,
    Query,
    QueryError,
    Symbol,
    format_query,
    parse_nested,
    parse_query,
    query_from_json,
    query_to_json,
)
from queries.lexicon import ORDINALS, SELECTION_PHRASES, SELECTION_WORDS
from queries.selection import SELECTIONS, selection_request
from tests.queries.test_query_properties import FAST, only_query_errors

NOUNS = st.sampled_from(["cup", "bowl", "can", "bottle", "cereal box", "mug", "milk"])
"""Class nouns (no lexicon word among them)."""


def selected(query: Query) -> tuple[str, int] | None:
    request = selection_request(query.get("select"))
    return None if request is None else (request.selection.name, request.rank)


def round_trips(query: Query) -> None:
    assert parse_nested(format_query(query)) == query
    assert query_from_json(query_to_json(query)) == query
    assert parse_query(json.dumps(query_to_json(query))) == query


@FAST
@given(st.sampled_from(sorted(SELECTION_WORDS)), NOUNS)
def test_a_selection_word_before_the_noun_selects_one_object(word: str, noun: str) -> None:
    query = parse_query(f"find the {word} {noun}")
    assert selected(query) == (SELECTION_WORDS[word], 1)
    assert query.get("obj.type") == Symbol(noun.replace(" ", "_"))
    assert query.get("max_results") == Number(1)
    round_trips(query)


@FAST
@given(st.sampled_from(sorted(SELECTION_PHRASES)), NOUNS, st.sampled_from(["", " on the table"]))
def test_a_selection_phrase_after_the_noun_selects_the_same_way(phrase: tuple[str, ...], noun: str, place: str) -> None:
    query = parse_query(f"find the {noun} {' '.join(phrase)}{place}")
    assert selected(query) == (SELECTION_PHRASES[phrase], 1)
    assert query.get("obj.type") == Symbol(noun.replace(" ", "_"))
    assert (query.get("obj.location.on") == Symbol("table")) == bool(place)
    round_trips(query)


@FAST
@given(st.sampled_from(sorted(ORDINALS)), st.sampled_from(sorted(SELECTION_WORDS)), NOUNS)
def test_an_ordinal_gives_the_rank_along_the_selection(ordinal: str, word: str, noun: str) -> None:
    query = parse_query(f"find the {ordinal} {word} {noun}")
    assert selected(query) == (SELECTION_WORDS[word], ORDINALS[ordinal])
    round_trips(query)


@FAST
@given(st.integers(2, 10), st.sampled_from(sorted(SELECTION_WORDS)), st.sampled_from(["bowls", "cups", "cans"]))
def test_a_number_before_a_selection_sets_how_many_are_answered(count: int, word: str, nouns: str) -> None:
    query = parse_query(f"find the {count} {word} {nouns}")
    assert selected(query) == (SELECTION_WORDS[word], 1)
    assert query.get("max_results") == Number(count)
    assert query.get("obj.type") == Symbol(nouns[:-1])


@FAST
@given(st.sampled_from(sorted(SELECTIONS)), st.integers(1, 50), st.integers(0, 3), st.integers(0, 4))
def test_the_nested_form_names_a_selection_and_a_rank(name: str, rank: int, lines: int, indent: int) -> None:
    text = "detect {" + "\n" * lines + " " * indent + f"obj: {{ type: Box }}, select: {{ by: {name}, rank: {rank} }} }}"
    query = parse_nested(text)
    assert selected(query) == (name, rank)
    short = parse_nested(f"detect {{ obj: {{ type: Box }}, select: {name} }}")
    assert short.get("select") == Symbol(name) and selected(short) == (name, 1)


@FAST
@given(
    st.text("abcdefghijklmnopqrstuvwxyz_", min_size=1, max_size=9).filter(lambda w: w not in SELECTIONS),
    st.integers(0, 3),
    st.integers(0, 6),
)
def test_an_unknown_selection_is_named_at_its_line_and_column(word: str, lines: int, indent: int) -> None:
    text = "detect { obj: { type: Box }," + "\n" * lines + " " * indent + f"select: {word} }}"
    with pytest.raises(QueryError) as caught:
        parse_nested(text)
    line = 1 + lines
    column = (indent + 1) if lines else len("detect { obj: { type: Box },") + indent + 1
    assert (caught.value.line, caught.value.column) == (line, column)
    assert f"unknown selection '{word}'" in caught.value.message
    assert set(caught.value.expected) == set(SELECTIONS)


@pytest.mark.parametrize(
    ("text", "column", "message"),
    [
        ("detect { obj: { type: Box }, select: { by: top, rank: 0 } }", 49, "'rank' must be a whole number"),
        ("detect { obj: { type: Box }, select: { by: top, rank: 1.5 } }", 49, "'rank' must be a whole number"),
        ("detect { obj: { type: Box }, select: { rank: 2 } }", 30, "'select' needs 'by'"),
        ("detect { obj: { type: Box }, select: { by: top, order: up } }", 49, "'select' has no key 'order'"),
        ("detect { obj: { type: Box }, select: 3 }", 30, "'select' takes a selection"),
        ("track { obj: { type: Cup }, select: top }", 29, "'select' belongs to a detect or inspect query"),
        ("find the second cup", 10, "an ordinal counts along a selection"),
        ("find the top biggest box", 14, "expected one selection"),
        ("find the box on the left { ", 26, "expected a word"),
    ],
)
def test_a_malformed_selection_names_line_and_column(text: str, column: int, message: str) -> None:
    with pytest.raises(QueryError) as caught:
        parse_query(text)
    assert (caught.value.line, caught.value.column) == (1, column)
    assert message in caught.value.message


@pytest.mark.parametrize(
    ("phrase", "nested"),
    [
        ("find the top box", "detect { obj: { shape: box }, select: top, max_results: 1 }"),
        ("find the box on the left", "detect { obj: { shape: box }, select: leftmost, max_results: 1 }"),
        ("find the highest box", "detect { obj: { shape: box }, select: top, max_results: 1 }"),
        ("find the lowest box", "detect { obj: { shape: box }, select: bottom, max_results: 1 }"),
        ("find the closest bottle", "detect { obj: { type: bottle }, select: closest, max_results: 1 }"),
        ("find the smallest can", "detect { obj: { type: can }, select: smallest, max_results: 1 }"),
        ("find the biggest one", "detect { obj: { type: object }, select: biggest, max_results: 1 }"),
        ("find the highest", "detect { obj: { type: object }, select: top, max_results: 1 }"),
        ("find the biggest bowls", "detect { obj: { type: bowl }, select: biggest }"),
        (
            "find the second cup from the left",
            "detect { obj: { type: cup }, select: { by: leftmost, rank: 2 }, max_results: 1 }",
        ),
        (
            "find the biggest red bowl on the table",
            "detect { obj: { type: bowl, color: red, location: { on: table } }, select: biggest, max_results: 1 }",
        ),
        ("inspect the top box", "inspect { obj: { shape: box }, select: top }"),
        # a longer place phrase is a place, not a selection
        ("find the box on top of the shelf", "detect { obj: { shape: box, location: { on: shelf } }, max_results: 1 }"),
        (
            "find the cup to the left of the bowl",
            "detect { obj: { type: cup, location: { left_of: bowl } }, max_results: 1 }",
        ),
        (
            "find the cup on the left shelf",
            "detect { obj: { type: cup, location: { on: left_shelf } }, max_results: 1 }",
        ),
        ("find the two cups", "detect { obj: { type: cup }, max_results: 2 }"),
    ],
)
def test_phrases_read_as_a_person_means_them(phrase: str, nested: str) -> None:
    assert format_query(parse_query(phrase)) == nested


def test_the_model_of_a_ranked_selection_is_a_block() -> None:
    query = parse_query("find the third biggest bowl")
    value = query.get("select")
    assert value == Block((Field("by", Symbol("biggest")), Field("rank", Number(3))))


selection_phrase_words = st.sampled_from(
    [
        *sorted(SELECTION_WORDS),
        *sorted(ORDINALS),
        *(" ".join(p) for p in SELECTION_PHRASES),
        *("find", "the", "two", "cup", "cups", "box", "of", "on the table", "on top of", "left of", "and", "one", "3"),
    ]
)


@FAST
@given(st.lists(selection_phrase_words, max_size=12).map(" ".join))
def test_random_selection_phrases_give_a_model_or_a_located_error(text: str) -> None:
    only_query_errors(parse_query, text)


def test_a_long_run_of_selection_phrases_is_read_without_running_out_of_stack() -> None:
    query = parse_query("find the cup" + " on the left" * 800)
    assert selected(query) == ("leftmost", 1)
