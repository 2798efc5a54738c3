"""Located errors: a table of bad queries with the line and column they report."""

from __future__ import annotations

from collections.abc import Callable

import pytest

from queries import Query, QueryError, parse_json, parse_natural, parse_nested, parse_query

Parser = Callable[[str], Query]

# (parser, text, line, column, words the message must contain)
BAD_QUERIES: list[tuple[Parser, str, int, int, str]] = [
    # nested syntax
    (parse_query, "detect { obj: { type: Milk, } }", 1, 29, "expected a key after 'type: Milk,'"),
    (parse_query, "detect { obj: { type: Milk }", 1, 29, "expected '}' or ','"),
    (parse_query, "detect { obj: @ }", 1, 15, "expected a value after 'obj:'"),
    (parse_query, "detect { a: [ }", 1, 15, "expected ']' or a value"),
    (parse_query, "detect { obj: { type: Milk } } extra", 1, 32, "expected end of input"),
    (parse_query, 'detect { obj: { type: "milk } }', 1, 23, "expected a closing '\"'"),
    (parse_query, 'detect { text: "a\tb" }', 1, 16, "expected a closing '\"'"),
    (parse_query, "detect {\n  obj: {\n    type: Milk\n    color: red\n  }\n}", 4, 5, "expected '}', ','"),
    (parse_query, "detect { obj: { type Milk } }", 1, 22, "expected ':' after 'type'"),
    (parse_nested, "", 1, 1, "expected a query kind"),
    (parse_nested, "{ obj: Milk }", 1, 1, "expected a query kind"),
    # nested values
    (parse_query, "detect { a: 3zz }", 1, 13, "unknown unit 'zz'"),
    (parse_query, "detect { a: 1e999 }", 1, 13, "out of range"),
    # semantic checks
    (parse_query, "fetch { a: b }", 1, 1, "unknown query kind 'fetch'"),
    (parse_query, "stop { a: 1 }", 1, 1, "'stop' needs a 'task'"),
    (parse_query, "detect {}", 1, 1, "needs at least one key"),
    (parse_query, "detect { obj: {} }", 1, 10, "'obj' has an empty block"),
    (parse_query, "detect { obj: [{}] }", 1, 10, "'obj' has an empty block"),
    (parse_query, "detect { a: 1, A: 2 }", 1, 16, "key 'a' is given twice (first at line 1, column 10)"),
    (parse_query, "detect { obj: { type: Cup,\n  type: Mug } }", 2, 3, "key 'type' is given twice"),
    (parse_query, "detect { obj: { width: -1cm } }", 1, 17, "'width' must not be negative"),
    (parse_query, "detect { obj: { width: -2cm..1cm } }", 1, 17, "'width' must not be negative"),
    (parse_query, "detect { obj: { size: 5cm..12cm } }", 1, 17, "'size' takes a size word"),
    (parse_query, '{"type": "detect", "obj": {"type": "Milk"}}', 1, 20, 'write it as {"detect": {"obj": {...}}}'),
    (parse_query, "detect { obj: { type: Milk }, max_results: two }", 1, 31, "'max_results' takes a number, not 'two'"),
    (parse_query, "detect {\n  obj: { type: Milk },\n  timeout: soon\n}", 3, 3, "'timeout' takes a number"),
    (parse_query, 'inspect { obj: { id: "three" } }', 1, 18, "'id' takes a number, not 'three'"),
    (parse_query, "detect { obj: { type: Cup, confidence: high } }", 1, 28, "'confidence' takes a number"),
    (parse_query, "detect { obj: { size: 0.1m } }", 1, 17, "'size' takes a size word"),
    (parse_query, '{"detect": {"obj": {"size": "10cm..30cm"}}}', 1, 21, "'size' takes a size word"),
    (parse_query, "detect { obj: { confidence: 1.5 } }", 1, 17, "'confidence' must be a number from 0 to 1"),
    (parse_query, "detect { obj: { confidence: 0.5s } }", 1, 17, "'confidence' must be a number from 0 to 1"),
    (parse_query, "find milk anywhere in the fridge", 1, 20, "expected one place"),
    (parse_query, "detect { timeout: -2s }", 1, 10, "'timeout' must not be negative"),
    (parse_query, "detect { timeout: 2m }", 1, 10, "'timeout' needs a unit of 's'"),
    (parse_query, "detect { a: 2m..1m }", 1, 10, "low bound above its high bound"),
    (parse_query, "detect { a: 1m..2s }", 1, 10, "same unit"),
    (parse_query, "detect { a: 1..b }", 1, 10, "of one type"),
    (parse_query, "detect { max_results: 0 }", 1, 10, "at least 1"),
    (parse_query, "detect { max_results: 1.5 }", 1, 10, "whole number"),
    (parse_query, "inspect { obj: { id: -3 } }", 1, 18, "'id' must not be negative"),
    # JSON
    (parse_query, '{"detect": {"obj": {"type": "milk",}}}', 1, 36, "expected a key"),
    (parse_query, '{"detect": 1}', 1, 12, "expected an object as the body"),
    (parse_query, '{"fetch": {"a": 1}}', 1, 2, "unknown query kind 'fetch'"),
    (parse_query, '{"detect": {"a b": 1}}', 1, 13, "expected an identifier as a key"),
    (parse_query, '{"detect": {"max_results": true}}', 1, 13, "'max_results' takes a number, not 'true'"),
    (parse_query, '{"detect": {}, "track": {}}', 1, 16, "expected exactly one key"),
    (parse_query, '{\n "detect": {\n  "obj": {"type": "milk"},\n  "obj": {"type": "cup"}\n }\n}', 4, 3, "twice"),
    (parse_json, "[1, 2]", 1, 1, "expected a JSON object"),
    (parse_json, "", 1, 1, "expected a JSON value"),
    (parse_query, '{"kind": "detect", "body": {"a": {"symbol": "x y"}}}', 1, 45, "identifier as a symbol"),
    (parse_query, '{"kind": "detect", "body": {"a": {"colour": "red"}}}', 1, 34, "expected one tag"),
    # natural phrases
    (parse_query, "hello world", 1, 1, "expected a verb such as find"),
    (parse_query, "   ", 1, 1, "expected a phrase"),
    (parse_query, "find", 1, 5, "expected an object after 'find'"),
    (parse_query, "find milk and cereal", 1, 11, "'and' can only join colours"),
    (parse_query, "find milk in", 1, 13, "expected a place after 'find milk in'"),
    (parse_query, "find the cup on the table on the shelf", 1, 27, "key 'on' is given twice"),
    (parse_query, "find the cup\non the table\non the shelf", 3, 1, "key 'on' is given twice"),
    (parse_query, "stop tracking", 1, 6, "could not place 'tracking'"),
    (parse_query, "stop", 1, 1, "'stop' needs a 'task'"),
    (parse_query, 'find the "cup', 1, 10, "closing quote"),
    (parse_query, "find the cup @ home", 1, 14, "expected a word"),
    (parse_query, "find milk 2m", 1, 11, "whole number"),
    (parse_natural, "detect { obj: Milk }", 1, 8, "expected a word"),
]


@pytest.mark.parametrize(
    ("parse", "text", "line", "column", "words"),
    BAD_QUERIES,
    ids=[repr(entry[1])[:40] for entry in BAD_QUERIES],
)
def test_bad_query_reports_line_and_column(parse: Parser, text: str, line: int, column: int, words: str) -> None:
    with pytest.raises(QueryError) as caught:
        parse(text)
    error = caught.value
    assert (error.line, error.column) == (line, column), str(error)
    assert words in error.message
    assert error.excerpt.endswith("^")
    assert str(error).startswith(f"{error.message} at line {line}, column {column}\n")


def test_error_text_has_message_location_and_caret() -> None:
    with pytest.raises(QueryError) as caught:
        parse_query("detect { obj: { type: Milk, } }")
    assert str(caught.value) == (
        "expected a key after 'type: Milk,' at line 1, column 29\n"
        "  detect { obj: { type: Milk, } }\n"
        "                              ^"
    )
    assert caught.value.expected == ["a key"]


def test_error_lists_what_was_expected() -> None:
    with pytest.raises(QueryError) as caught:
        parse_query("detect { obj: { type: Milk }")
    assert caught.value.expected == ["'}'", "','"]
    with pytest.raises(QueryError) as caught:
        parse_query("fetch { a: b }")
    assert caught.value.expected == ["detect", "inspect", "track", "scan", "stop"]


def test_caret_points_into_the_right_line_of_a_multiline_query() -> None:
    with pytest.raises(QueryError) as caught:
        parse_query("detect {\n  obj: { type: Milk, width: -1cm }\n}")
    error = caught.value
    assert (error.line, error.column) == (2, 22)
    assert error.excerpt == "  " + "  obj: { type: Milk, width: -1cm }" + "\n  " + " " * 21 + "^"


def test_long_lines_are_cut_around_the_caret() -> None:
    text = "detect { obj: { " + ", ".join(f"k{i}: v" for i in range(60)) + ", } }"
    with pytest.raises(QueryError) as caught:
        parse_query(text)
    source_line, caret_line = caught.value.excerpt.split("\n")
    assert len(source_line) <= 2 + 72
    assert source_line[caret_line.index("^")] == "}"


def test_overlong_input_is_rejected_with_a_located_error() -> None:
    with pytest.raises(QueryError) as caught:
        parse_query("detect { a: b }" + " " * 20_000)
    assert "longer than" in caught.value.message


def test_deep_nesting_is_rejected_with_a_located_error() -> None:
    text = "detect { a: " + "[" * 40 + "]" * 40 + " }"
    with pytest.raises(QueryError) as caught:
        parse_query(text)
    assert "deeper than" in caught.value.message
    assert (caught.value.line, caught.value.column) == (1, 10)
