"""Determiners a person chains before a noun ('all the cups', 'both of the mugs', 'find me a cup') never
become part of the class name."""

from __future__ import annotations

import pytest

from queries import format_query, parse_query


@pytest.mark.parametrize(
    ("phrase", "expected"),
    [
        ("find all the cups", "detect { obj: { type: cup } }"),
        ("find all of the cups", "detect { obj: { type: cup } }"),
        ("find each of the cups", "detect { obj: { type: cup } }"),
        ("find any of the mugs", "detect { obj: { type: mug } }"),
        ("find all my cups", "detect { obj: { type: cup } }"),
        ("find some of my red cups", "detect { obj: { type: cup, color: red } }"),
        ("find these cups", "detect { obj: { type: cup } }"),
        ("find those cups on the table", "detect { obj: { type: cup, location: { on: table } } }"),
        ("find this cup", "detect { obj: { type: cup }, max_results: 1 }"),
        ("find both cups", "detect { obj: { type: cup }, max_results: 2 }"),
        ("find both of the cups", "detect { obj: { type: cup }, max_results: 2 }"),
        ("find two of the cups", "detect { obj: { type: cup }, max_results: 2 }"),
        ("find 3 of the red cups", "detect { obj: { type: cup, color: red }, max_results: 3 }"),
        ("find one of the mugs", "detect { obj: { type: mug }, max_results: 1 }"),
        ("find me the cup", "detect { obj: { type: cup }, max_results: 1 }"),
        ("get me a cup", "detect { obj: { type: cup }, max_results: 1 }"),
        ("find the red one", "detect { obj: { color: red }, max_results: 1 }"),
        ("find the red ones", "detect { obj: { color: red } }"),
    ],
)
def test_chained_determiners_are_not_part_of_the_noun(phrase: str, expected: str) -> None:
    assert format_query(parse_query(phrase)) == expected
