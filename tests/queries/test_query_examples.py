"""The examples of the query-language issue, each with the exact model it gives."""

from __future__ import annotations

import pytest

from queries import (
    Asked,
    Block,
    Field,
    ListValue,
    Number,
    Query,
    String,
    Symbol,
    Value,
    format_query,
    parse_json,
    parse_natural,
    parse_nested,
    parse_query,
)


def block(**fields: Value) -> Block:
    """Build a block from keyword arguments, in order (``for_`` -> ``for``)."""
    return Block(tuple(Field(key.rstrip("_"), value) for key, value in fields.items()))


def sym(name: str) -> Symbol:
    """Shorthand for a symbol."""
    return Symbol(name)


NESTED_EXAMPLES: list[tuple[str, Query]] = [
    (
        "detect { obj: { type: Milk, location: Fridge } }",
        Query("detect", block(obj=block(type=sym("Milk"), location=sym("Fridge")))),
    ),
    (
        'detect { obj: { type: Milk, text: "lactose free", color: [white, blue] }, max_results: 1 }',
        Query(
            "detect",
            block(
                obj=block(
                    type=sym("Milk"),
                    text=String("lactose free"),
                    color=ListValue((sym("white"), sym("blue"))),
                ),
                max_results=Number(1.0),
            ),
        ),
    ),
    (
        "detect { obj: { type: Cup, color: red, size: small, location: { on: Table } }, timeout: 2s }",
        Query(
            "detect",
            block(
                obj=block(
                    type=sym("Cup"),
                    color=sym("red"),
                    size=sym("small"),
                    location=block(on=sym("Table")),
                ),
                timeout=Number(2.0, "s"),
            ),
        ),
    ),
    (
        "inspect { obj: { id: 12, pose: ?, color: ? } }",
        Query("inspect", block(obj=block(id=Number(12.0), pose=Asked(), color=Asked()))),
    ),
    (
        "track { obj: { type: Cup, color: blue } }",
        Query("track", block(obj=block(type=sym("Cup"), color=sym("blue")))),
    ),
    (
        "scan { region: CounterTop, for: free_space }",
        Query("scan", block(region=sym("CounterTop"), for_=sym("free_space"))),
    ),
    ("stop { task: 7 }", Query("stop", block(task=Number(7.0)))),
]

NATURAL_EXAMPLES: list[tuple[str, Query]] = [
    (
        "find milk in fridge",
        Query("detect", block(obj=block(type=sym("milk"), location=block(in_=sym("fridge"))))),
    ),
    (
        "find the red cup on the table",
        Query(
            "detect",
            block(
                obj=block(type=sym("cup"), color=sym("red"), location=block(on=sym("table"))),
                max_results=Number(1.0),
            ),
        ),
    ),
    (
        "where is the cereal box?",
        Query("detect", block(obj=block(type=sym("cereal_box")), max_results=Number(1.0))),
    ),
    (
        "is there a lactose free milk in the fridge",
        Query(
            "detect",
            block(
                obj=block(type=sym("lactose_free_milk"), location=block(in_=sym("fridge"))),
                max_results=Number(1.0),
            ),
        ),
    ),
    (
        "track the blue cup",
        Query("track", block(obj=block(type=sym("cup"), color=sym("blue")), max_results=Number(1.0))),
    ),
    (
        "look for free space on the counter",
        Query("scan", block(region=sym("counter"), for_=sym("free_space"))),
    ),
    ("inspect object 12", Query("inspect", block(obj=block(id=Number(12.0))))),
]


@pytest.mark.parametrize(("text", "expected"), NESTED_EXAMPLES)
def test_nested_example_gives_exact_model(text: str, expected: Query) -> None:
    query = parse_nested(text)
    assert query == expected
    assert query.source == text
    assert parse_query(text) == expected


@pytest.mark.parametrize(("text", "expected"), NESTED_EXAMPLES)
def test_nested_example_prints_back_unchanged(text: str, expected: Query) -> None:
    assert format_query(expected) == text


@pytest.mark.parametrize(("text", "expected"), NATURAL_EXAMPLES)
def test_natural_example_gives_exact_model(text: str, expected: Query) -> None:
    assert parse_natural(text) == expected
    assert parse_query(text) == expected


@pytest.mark.parametrize(("text", "expected"), NATURAL_EXAMPLES)
def test_natural_example_equals_its_nested_form(text: str, expected: Query) -> None:
    assert parse_nested(format_query(parse_natural(text))) == expected


def test_json_example_gives_exact_model() -> None:
    text = '{"detect": {"obj": {"type": "milk", "location": "fridge"}}}'
    expected = Query("detect", block(obj=block(type=sym("milk"), location=sym("fridge"))))
    assert parse_json(text) == expected
    assert parse_query(text) == expected


def test_natural_and_nested_forms_meet_in_one_model() -> None:
    nested = parse_nested("detect { obj: { type: milk, location: { in: fridge } } }")
    assert parse_natural("find milk in fridge") == nested
    assert parse_json('{"detect": {"obj": {"type": "milk", "location": {"in": "fridge"}}}}') == nested


def test_comments_and_free_whitespace_are_allowed() -> None:
    text = """
    # a query over several lines
    detect {
        obj: {            // what to look for
            type: Milk,
            location: Fridge
        }
    }
    """
    assert parse_query(text) == NESTED_EXAMPLES[0][1]


def test_keys_and_kind_are_case_insensitive_but_symbols_keep_case() -> None:
    query = parse_nested("Detect { OBJ: { TYPE: Milk } }")
    assert query.kind == "detect"
    assert query.get("obj.type") == Symbol("Milk")
