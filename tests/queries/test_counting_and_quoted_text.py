"""Questions a robot's program asks on a real tabletop frame that the phrase parser refused: a count (``how many
cans are there``, which got "did you mean 'show'?") and a bare quoted text (``find "CHEEZ"``, which got "expected
an object")."""

from __future__ import annotations

import pytest

from queries import QueryError, format_query, parse_query


@pytest.mark.parametrize(
    ("phrase", "expected"),
    [
        ("how many cans are there", "detect { obj: { type: can } }"),
        ("how many cans are there on the table", "detect { obj: { type: can, location: { on: table } } }"),
        ("How many cups do you see?", "detect { obj: { type: cup } }"),
        ("please, how many red bowls are there", "detect { obj: { type: bowl, color: red } }"),
        ("how many milk is there", "detect { obj: { type: milk } }"),
        ("count the bowls", "detect { obj: { type: bowl } }"),
        ("count all the objects on the table", "detect { obj: { location: { on: table } } }"),
    ],
)
def test_a_count_question_asks_for_every_such_object(phrase: str, expected: str) -> None:
    assert format_query(parse_query(phrase)) == expected


@pytest.mark.parametrize(
    ("phrase", "expected"),
    [
        ('find "CHEEZ"', 'detect { obj: { text: "CHEEZ" } }'),
        ('find the "milk"', 'detect { obj: { text: "milk" }, max_results: 1 }'),
        ('look for "Fat Free" on the table', 'detect { obj: { text: "Fat Free", location: { on: table } } }'),
    ],
)
def test_quoted_text_alone_asks_for_whatever_reads_it(phrase: str, expected: str) -> None:
    assert format_query(parse_query(phrase)) == expected


def test_how_without_many_is_not_taken_for_a_misspelt_show() -> None:
    with pytest.raises(QueryError) as caught:
        parse_query("how big is the box")
    assert "did you mean 'show'" not in caught.value.message
    assert "how many cups are there" in caught.value.message
    assert (caught.value.line, caught.value.column) == (1, 1)


def test_how_many_without_an_object_is_located_after_it() -> None:
    with pytest.raises(QueryError) as caught:
        parse_query("how many are there")
    assert "expected an object" in caught.value.message


@pytest.mark.parametrize(
    ("phrase", "counted"),
    [
        ("how many cans are there", True),
        ("How many cups do you see?", True),
        ("count the bowls", True),
        ("count all the objects on the table", True),
        ("find the cans", False),
        ("find all bowls", False),
        ("show me the cups", False),
    ],
)
def test_a_count_question_is_marked_so_its_answer_says_how_many(phrase: str, counted: bool) -> None:
    assert parse_query(phrase).counted is counted


@pytest.mark.parametrize(
    ("phrase", "expected"),
    [
        ("how many cups are on the table", "detect { obj: { type: cup, location: { on: table } } }"),
        ("how many red cups are in the fridge", "detect { obj: { type: cup, color: red, location: { in: fridge } } }"),
        ("how many bowls are there on the shelf", "detect { obj: { type: bowl, location: { on: shelf } } }"),
        ("how many milk is in the fridge", "detect { obj: { type: milk, location: { in: fridge } } }"),
    ],
)
def test_the_copula_of_a_count_question_is_its_verb_not_part_of_the_object(phrase: str, expected: str) -> None:
    assert format_query(parse_query(phrase)) == expected


@pytest.mark.parametrize(
    ("phrase", "column"),
    [("how many cups are on the left", 19), ("how many boxes are at the top", 20), ("how many biggest cups", 10)],
)
def test_a_count_question_that_also_picks_one_object_is_refused_where_it_picks(phrase: str, column: int) -> None:
    with pytest.raises(QueryError) as caught:
        parse_query(phrase)
    assert "a count takes every such object" in caught.value.message
    assert (caught.value.line, caught.value.column) == (1, column)
