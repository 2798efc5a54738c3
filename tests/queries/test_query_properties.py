"""Property tests: printer round trips, and no crash on random or mutated input.

Random inputs are capped at 200 characters (``MAX_TEXT``) and each property
runs ``EXAMPLES`` examples so the suite stays fast; the parsers themselves
accept up to ``MAX_QUERY_LENGTH`` characters and ``MAX_DEPTH`` nesting.
"""

from __future__ import annotations

import json
import string
from collections.abc import Callable
from importlib import resources

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from queries import (
    KINDS,
    Asked,
    Block,
    Field,
    ListValue,
    Number,
    Query,
    QueryError,
    Range,
    String,
    Symbol,
    Value,
    format_query,
    parse_json,
    parse_natural,
    parse_nested,
    parse_query,
    query_from_json,
    query_to_json,
)
from queries.lexicon import COLORS, COUNT_WORDS, LIMITING_DETERMINERS, PREPOSITIONS, SIZES, VERBS
from queries.validation import KEY_UNITS, NON_NEGATIVE_KEYS

MAX_TEXT = 200
EXAMPLES = 200
FAST = settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])

RESERVED_KEYS = NON_NEGATIVE_KEYS | set(KEY_UNITS)

LOWER = string.ascii_lowercase + "_"
LETTERS = string.ascii_letters + "_"


def identifiers(first: str, rest: str, max_size: int) -> st.SearchStrategy[str]:
    """Identifiers: one character of ``first``, then up to ``max_size`` of ``rest``."""
    return st.builds(str.__add__, st.sampled_from(first), st.text(rest, max_size=max_size))


keys = identifiers(LOWER, LOWER + string.digits, 7).filter(lambda key: key not in RESERVED_KEYS)
symbols = identifiers(LETTERS, LETTERS + string.digits, 9).map(Symbol)
strings = st.text(st.characters(codec="utf-8"), max_size=12).map(String)
units = st.sampled_from([None, "m", "s", "rad", "kg"])
finite = st.floats(allow_nan=False, allow_infinity=False)
numbers = st.builds(Number, finite, units)


@st.composite
def number_ranges(draw: st.DrawFn) -> Range:
    """A valid numeric range: one unit, low <= high."""
    unit = draw(units)
    low, high = sorted((draw(finite), draw(finite)))
    return Range(Number(low, unit), Number(high, unit))


symbol_ranges = st.tuples(symbols, symbols).map(lambda pair: Range(*pair))
scalars: st.SearchStrategy[Value] = st.one_of(
    symbols, strings, numbers, st.just(Asked()), number_ranges(), symbol_ranges
)


def blocks(children: st.SearchStrategy[Value]) -> st.SearchStrategy[Block]:
    """Non-empty blocks with unique keys."""
    return st.dictionaries(keys, children, min_size=1, max_size=4).map(
        lambda fields: Block(tuple(Field(key, value) for key, value in fields.items()))
    )


values: st.SearchStrategy[Value] = st.recursive(
    scalars,
    lambda children: st.one_of(
        st.lists(children, max_size=4).map(lambda items: ListValue(tuple(items))), blocks(children)
    ),
    max_leaves=10,
)


@st.composite
def queries(draw: st.DrawFn) -> Query:
    """A valid query of any kind (``stop`` always gets a task)."""
    kind = draw(st.sampled_from(KINDS))
    body = draw(blocks(values))
    if kind == "stop":
        task = draw(st.one_of(st.integers(0, 10**6).map(lambda n: Number(float(n))), symbols))
        body = Block((Field("task", task), *body.fields))
    return Query(kind, body)


@FAST
@given(queries())
def test_nested_printer_round_trips(query: Query) -> None:
    text = format_query(query)
    parsed = parse_nested(text)
    assert parsed == query
    assert format_query(parsed) == text


@FAST
@given(queries())
def test_tagged_json_round_trips(query: Query) -> None:
    data = query_to_json(query)
    assert query_from_json(data) == query
    assert parse_json(json.dumps(data)) == query
    assert parse_query(json.dumps(data, indent=2)) == query


def only_query_errors(parse: Callable[[str], Query], text: str) -> None:
    """Parse ``text``; a failure must be a QueryError located inside the text."""
    try:
        query = parse(text)
    except QueryError as error:
        lines = text.split("\n")
        assert 1 <= error.line <= len(lines)
        assert 1 <= error.column <= len(lines[error.line - 1]) + 1
        assert error.message
    else:
        assert parse_nested(format_query(query)) == query


@FAST
@given(st.text(max_size=MAX_TEXT))
def test_random_text_raises_only_query_errors(text: str) -> None:
    for parse in (parse_query, parse_nested, parse_natural, parse_json):
        only_query_errors(parse, text)


STRUCTURE = st.sampled_from([*'{}[]:,?."#/\n -0123456789eE.mcs', "..", "detect", "stop", "obj", "find", "the", "on"])


def corpus_inputs() -> list[str]:
    """The valid inputs of the corpus, to mutate."""
    text = resources.files("queries").joinpath("corpus.jsonl").read_text(encoding="utf-8")
    return [json.loads(line)["input"] for line in text.splitlines() if line.strip()]


@st.composite
def mutated(draw: st.DrawFn) -> str:
    """A corpus query with up to six random edits, capped at MAX_TEXT characters."""
    text = draw(st.sampled_from(corpus_inputs()))[:MAX_TEXT]
    for _ in range(draw(st.integers(1, 6))):
        position = draw(st.integers(0, len(text)))
        action = draw(st.sampled_from(["insert", "delete", "replace"]))
        piece = draw(st.one_of(STRUCTURE, st.characters()))
        if action == "insert":
            text = text[:position] + piece + text[position:]
        elif action == "delete":
            text = text[:position] + text[position + 1 :]
        else:
            text = text[:position] + piece + text[position + 1 :]
    return text[:MAX_TEXT]


@FAST
@given(mutated())
def test_mutated_queries_raise_only_query_errors(text: str) -> None:
    only_query_errors(parse_query, text)


phrase_words = st.sampled_from(
    [" ".join(words) for words in VERBS]
    + [" ".join(words) for words in PREPOSITIONS]
    + sorted(LIMITING_DETERMINERS | set(COLORS) | set(SIZES) | set(COUNT_WORDS))
    + [
        "cup",
        "cups",
        "milk",
        "cereal box",
        "object",
        "12",
        "2m",
        '"lactose free"',
        "and",
        "with",
        "for",
        "free space",
        "that is",
        "what color",
    ]
)


@FAST
@given(st.lists(phrase_words, max_size=10).map(" ".join))
def test_random_phrases_give_a_model_or_a_located_error(text: str) -> None:
    only_query_errors(parse_natural, text[:MAX_TEXT])
