"""Slips a person makes when typing a phrase: a misspelt verb gets a suggestion, a contraction is read as the two
words it stands for, and a superlative (which would need comparing objects) is refused with what to say instead,
all located."""

from __future__ import annotations

import pytest

from queries import QueryError, format_query, parse_query


@pytest.mark.parametrize(
    ("phrase", "suggestion"),
    [
        ("fnd the milk", "find"),
        ("trak the blue cup", "track"),
        ("inspekt object 3", "inspect"),
        ("scna the table", "scan"),
    ],
)
def test_a_misspelt_verb_is_named_with_the_verb_meant(phrase: str, suggestion: str) -> None:
    with pytest.raises(QueryError) as caught:
        parse_query(phrase)
    assert (caught.value.line, caught.value.column) == (1, 1)
    assert f"did you mean '{suggestion}'?" in caught.value.message


def test_a_word_far_from_any_verb_gets_no_guess() -> None:
    with pytest.raises(QueryError) as caught:
        parse_query("milk")
    assert "did you mean" not in caught.value.message


@pytest.mark.parametrize(
    ("phrase", "expected"),
    [
        ("find the cup that's red", "detect { obj: { type: cup, color: red }, max_results: 1 }"),
        ("find the cups that're blue", "detect { obj: { type: cup, color: blue } }"),
    ],
)
def test_a_contracted_relative_clause_reads_as_its_words(phrase: str, expected: str) -> None:
    assert format_query(parse_query(phrase)) == expected


@pytest.mark.parametrize(
    ("phrase", "expected"),
    [
        ("follow me", "track { obj: { type: person }, max_results: 1 }"),
        ("track her", "track { obj: { type: person }, max_results: 1 }"),
        ("find them", "detect { obj: { type: person } }"),
        ("find us in the kitchen", "detect { obj: { type: person, location: { in: kitchen } } }"),
        ("track her cup", "track { obj: { type: cup }, max_results: 1 }"),
    ],
)
def test_a_personal_pronoun_as_the_object_is_a_person(phrase: str, expected: str) -> None:
    assert format_query(parse_query(phrase)) == expected


@pytest.mark.parametrize(
    ("phrase", "expected"),
    [
        ("do you see a cup", "detect { obj: { type: cup }, max_results: 1 }"),
        ("can you see the milk", "detect { obj: { type: milk }, max_results: 1 }"),
        ("list all objects", "detect { obj: { type: object } }"),
        ("show the red cups", "detect { obj: { type: cup, color: red } }"),
        ("what is on the table", "detect { obj: { location: { on: table } } }"),
        ("what's in the fridge", "detect { obj: { location: { in: fridge } } }"),
        ("what are the objects on the table", "detect { obj: { location: { on: table } } }"),
    ],
)
def test_everyday_ways_of_asking_what_is_seen_are_detect_queries(phrase: str, expected: str) -> None:
    assert format_query(parse_query(phrase)) == expected


def test_what_is_without_a_place_is_still_refused_at_the_start() -> None:
    with pytest.raises(QueryError) as caught:
        parse_query("what is the colour of the mug")
    assert (caught.value.line, caught.value.column) == (1, 1)
