"""The model, units, the printer, form detection and the word rules."""

from __future__ import annotations

import math

import pytest

from queries import (
    Asked,
    Block,
    Field,
    ListValue,
    Number,
    Query,
    Range,
    Span,
    String,
    Symbol,
    detect_form,
    format_query,
    format_value,
    parse_natural,
    parse_nested,
    parse_query,
)
from queries.natural import singularise
from queries.units import UnitError, parse_quantity


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("30cm", Number(0.3, "m")),
        ("2s", Number(2.0, "s")),
        ("500ms", Number(0.5, "s")),
        ("0.5m", Number(0.5, "m")),
        ("12", Number(12.0)),
        ("-4", Number(-4.0)),
        ("15mm", Number(0.015, "m")),
        ("2km", Number(2000.0, "m")),
        ("3min", Number(180.0, "s")),
        ("1h", Number(3600.0, "s")),
        ("180deg", Number(math.pi, "rad")),
        ("1.5rad", Number(1.5, "rad")),
        ("250g", Number(0.25, "kg")),
        ("2kg", Number(2.0, "kg")),
        ("1e-3m", Number(0.001, "m")),
        ("30CM", Number(0.3, "m")),
    ],
)
def test_units_are_normalised_to_si(text: str, expected: Number) -> None:
    assert parse_quantity(text) == expected


def test_integers_stay_exact_floats() -> None:
    number = parse_nested("stop { task: 7 }").get("task")
    assert number == Number(7.0)
    assert isinstance(number, Number)
    assert isinstance(number.value, float)
    assert Number(3).value == 3.0


@pytest.mark.parametrize("text", ["3zz", "2 m", "abc", "1e999", "1e306km"])
def test_bad_quantities_raise_unit_error(text: str) -> None:
    with pytest.raises(UnitError):
        parse_quantity(text)


def test_model_refuses_values_it_cannot_print() -> None:
    with pytest.raises(ValueError):
        Symbol("two words")
    with pytest.raises(ValueError):
        Number(1.0, "cm")
    with pytest.raises(ValueError):
        Number(math.nan)
    with pytest.raises(ValueError):
        Field("Type", Symbol("x"))


def test_path_lookup_and_block_access() -> None:
    query = parse_nested("detect { obj: { type: Cup, location: { on: Table } }, timeout: 2s }")
    assert query.get("obj.type") == Symbol("Cup")
    assert query.get("obj.location.on") == Symbol("Table")
    assert query.get("OBJ.Location.ON") == Symbol("Table")
    assert query.get("timeout") == Number(2.0, "s")
    assert query.get("obj.colour") is None
    assert query.get("timeout.value") is None
    obj = query.body.get("obj")
    assert isinstance(obj, Block)
    assert obj.keys() == ("type", "location")
    assert obj.field("type") == Field("type", Symbol("Cup"))


def test_spans_and_source_do_not_take_part_in_equality() -> None:
    first = parse_nested("detect { obj: { type: Milk } }")
    second = parse_nested("detect {\n  obj: {\n    type: Milk\n  }\n}")
    assert first == second
    assert first.source != second.source
    assert first.body.fields[0].span != second.body.fields[0].span


def test_field_spans_cover_key_to_value_end() -> None:
    query = parse_nested("detect {\n  obj: { type: Milk },\n  timeout: 2s\n}")
    obj, timeout = query.body.fields
    assert obj.span == Span(2, 3, 2, 22)
    assert timeout.span == Span(3, 3, 3, 14)
    assert query.kind_span == Span(1, 1, 1, 7)


def test_natural_fields_point_at_their_words() -> None:
    query = parse_natural("find the red cup on the table")
    obj = query.body.get("obj")
    assert isinstance(obj, Block)
    color = obj.field("color")
    location = obj.field("location")
    assert color is not None
    assert location is not None
    assert color.span == Span(1, 10, 1, 13)
    assert location.span == Span(1, 18, 1, 30)
    assert query.kind_span == Span(1, 1, 1, 5)


def test_printer_writes_every_value_type() -> None:
    query = Query(
        "detect",
        Block(
            (
                Field("a", Symbol("Milk")),
                Field("b", String('say "hi"\n')),
                Field("c", Number(0.3, "m")),
                Field("d", Number(1e20)),
                Field("e", Number(-0.5)),
                Field("f", ListValue((Symbol("x"), Asked()))),
                Field("g", Range(Number(1.0, "s"), Number(2.5, "s"))),
                Field("h", Block((Field("on", Symbol("Table")),))),
            )
        ),
    )
    text = format_query(query)
    assert text == (
        'detect { a: Milk, b: "say \\"hi\\"\\n", c: 0.3m, d: 1e+20, e: -0.5, f: [x, ?], g: 1s..2.5s, h: { on: Table } }'
    )
    assert parse_nested(text) == query
    assert format_value(Block()) == "{}"


@pytest.mark.parametrize(
    ("text", "form"),
    [
        ('{"detect": {}}', "json"),
        ('  \n {"detect": {}}', "json"),
        ("detect { a: b }", "nested"),
        ("detect\n{ a: b }", "nested"),
        ("fetch { a: b }", "nested"),
        ("# comment\ndetect { a: b }", "nested"),
        ("detect milk", "natural"),
        ("find the milk", "natural"),
        ("", "natural"),
    ],
)
def test_form_detection(text: str, form: str) -> None:
    assert detect_form(text) == form


@pytest.mark.parametrize(
    ("word", "singular", "plural"),
    [
        ("cups", "cup", True),
        ("boxes", "box", True),
        ("glasses", "glass", True),
        ("knives", "knife", True),
        ("berries", "berry", True),
        ("dishes", "dish", True),
        ("shelves", "shelf", True),
        ("cookies", "cookie", True),
        ("tomatoes", "tomato", True),
        ("scissors", "scissors", True),
        ("glass", "glass", False),
        ("bus", "bus", False),
        ("milk", "milk", False),
        ("lens", "lens", False),
        ("box", "box", False),
    ],
)
def test_plural_rules(word: str, singular: str, plural: bool) -> None:
    assert singularise(word) == (singular, plural)


@pytest.mark.parametrize(
    ("phrase", "canonical"),
    [
        ("find the cups", "detect { obj: { type: cup } }"),
        ("find a cup", "detect { obj: { type: cup }, max_results: 1 }"),
        ("find cup", "detect { obj: { type: cup } }"),
        ("find five spoons", "detect { obj: { type: spoon }, max_results: 5 }"),
        ("track big red balls", "track { obj: { type: ball, color: red, size: large } }"),
        (
            "find the light blue and white flat plate",
            "detect { obj: { type: plate, color: [light_blue, white], shape: flat }, max_results: 1 }",
        ),
        ("find the spoon near the cup", "detect { obj: { type: spoon, location: { near: cup } }, max_results: 1 }"),
        ("inspect cup 3", "inspect { obj: { type: cup, id: 3 } }"),
        (
            'find the jar reading "sugar" on the shelf',
            'detect { obj: { type: jar, text: "sugar", location: { on: shelf } }, max_results: 1 }',
        ),
        ("find a Tasse in der Küche", None),
        ("keep track of the kitten", "track { obj: { type: kitten }, max_results: 1 }"),
        ("find free space", "scan { for: free_space }"),
    ],
)
def test_natural_mapping_rules(phrase: str, canonical: str | None) -> None:
    if canonical is None:
        with pytest.raises(Exception, match="expected a word"):
            parse_query(phrase)
        return
    assert format_query(parse_query(phrase)) == canonical


def test_unknown_words_stay_as_they_are() -> None:
    query = parse_query("find the zorblax gadget on the quux")
    assert query.get("obj.type") == Symbol("zorblax_gadget")
    assert query.get("obj.location.on") == Symbol("quux")


def test_nested_form_is_not_rewritten() -> None:
    assert parse_query("detect { obj: { location: Fridge } }").get("obj.location") == Symbol("Fridge")
    block_form = parse_query("detect { obj: { location: { on: Table } } }").get("obj.location")
    assert block_form == Block((Field("on", Symbol("Table")),))


def test_json_true_and_false_are_the_nested_forms_bare_words() -> None:
    for word in ("true", "false"):
        written = parse_query(f'{{"detect": {{"obj": {{"type": "Cup", "text": {word}}}}}}}')
        assert written == parse_nested(f"detect {{ obj: {{ type: Cup, text: {word} }} }}")
        assert written.body.get("obj").get("text") == Symbol(word)
