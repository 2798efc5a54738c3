"""The nested key-value form: ``detect { obj: { type: Milk } }`` -> :class:`Query`.

The grammar is ``nested.lark``; lark's LALR parser calls the actions of
:class:`_ToModel` while parsing, so no parse tree is built.  Each action
returns the value with its source position so fields get spans.
"""

from __future__ import annotations

import functools
import json
from importlib import resources
from typing import Any, TypeAlias, cast

from lark import Lark, Token, Transformer
from lark.exceptions import UnexpectedInput

from queries.model import Asked, Block, Field, ListValue, Query, Range, Span, String, Symbol, Value
from queries.syntax_errors import ActionError, action_error_to_query_error, syntax_error
from queries.units import UnitError, parse_quantity
from queries.validation import MAX_QUERY_LENGTH, check_length, validate_query

Located: TypeAlias = tuple[Value, int, int, int, int]
"""A value with its start line, start column, end line and end column."""

_VALUE_STARTERS = frozenset({"IDENT", "STRING", "QUANTITY", "LBRACE", "LBRACKET", "ASKED"})

EXPECTED_WORDS: tuple[tuple[frozenset[str], str], ...] = (
    (frozenset({"RBRACE"}), "'}'"),
    (frozenset({"RBRACKET"}), "']'"),
    (frozenset({"_COMMA"}), "','"),
    (frozenset({"_COLON"}), "':'"),
    (frozenset({"_DOTDOT"}), "'..'"),
    (frozenset({"LBRACE"}), "'{'"),
    (frozenset({"LBRACKET"}), "'['"),
    (frozenset({"ASKED"}), "'?'"),
    (frozenset({"IDENT"}), "a key"),
    (frozenset({"IDENT", "STRING", "QUANTITY"}), "a symbol, string or number"),
    (_VALUE_STARTERS, "a value"),
    (frozenset({"STRING"}), "a string"),
    (frozenset({"QUANTITY"}), "a number"),
    (frozenset({"$END"}), "end of input"),
)
"""How expected terminals of ``nested.lark`` are named in error messages."""


def _token_start(token: Token) -> tuple[int, int]:
    """Return a token's 1-based line and column."""
    return int(token.line or 0), int(token.column or 0)


def _token_located(value: Value, token: Token) -> Located:
    """Pair a value with the position of the token it came from."""
    return (
        value,
        int(token.line or 0),
        int(token.column or 0),
        int(token.end_line or 0),
        int(token.end_column or 0),
    )


class _ToModel(Transformer[Token, Any]):
    """Grammar actions building model values; stateless, so safe to share."""

    def symbol(self, children: list[Token]) -> Located:
        token = children[0]
        return _token_located(Symbol(str(token)), token)

    def string(self, children: list[Token]) -> Located:
        token = children[0]
        return _token_located(String(json.loads(token)), token)

    def number(self, children: list[Token]) -> Located:
        token = children[0]
        try:
            value = parse_quantity(str(token))
        except UnitError as error:
            raise ActionError(str(error), *_token_start(token)) from error
        return _token_located(value, token)

    def asked(self, children: list[Token]) -> Located:
        return _token_located(Asked(), children[0])

    def range_value(self, children: list[Located]) -> Located:
        low, high = children
        return (Range(low[0], high[0]), low[1], low[2], high[3], high[4])

    def list_value(self, children: list[Any]) -> Located:
        opener: Token = children[0]
        closer: Token = children[-1]
        items = tuple(item[0] for item in children[1:-1] if item is not None)
        return (
            ListValue(items),
            int(opener.line or 0),
            int(opener.column or 0),
            int(closer.end_line or 0),
            int(closer.end_column or 0),
        )

    def field(self, children: list[Any]) -> Field:
        key: Token = children[0]
        value: Located = children[1]
        span = Span(int(key.line or 0), int(key.column or 0), value[3], value[4])
        return Field(str(key).lower(), value[0], span)

    def block(self, children: list[Any]) -> Located:
        opener: Token = children[0]
        closer: Token = children[-1]
        fields = tuple(item for item in children[1:-1] if item is not None)
        return (
            Block(fields),
            int(opener.line or 0),
            int(opener.column or 0),
            int(closer.end_line or 0),
            int(closer.end_column or 0),
        )

    def query(self, children: list[Any]) -> tuple[Token, Located]:
        return children[0], children[1]


@functools.cache
def nested_parser() -> Lark:
    """Return the LALR parser for ``nested.lark`` (built once per process)."""
    grammar = resources.files("queries").joinpath("nested.lark").read_text(encoding="utf-8")
    return Lark(
        grammar,
        start="query",
        parser="lalr",
        transformer=_ToModel(),
        maybe_placeholders=True,
    )


def parse_nested(text: str) -> Query:
    """Parse and validate a nested query; raise :class:`~queries.errors.QueryError` if bad.

    Input longer than :data:`~queries.validation.MAX_QUERY_LENGTH` characters
    is rejected.
    """
    check_length(text, MAX_QUERY_LENGTH)
    try:
        kind_token, located = cast(tuple[Token, Located], nested_parser().parse(text))
    except UnexpectedInput as error:
        raise syntax_error(text, error, EXPECTED_WORDS, "a query kind such as 'detect'") from None
    except ActionError as error:
        raise action_error_to_query_error(text, error) from None
    body = cast(Block, located[0])
    kind_span = Span(
        int(kind_token.line or 0),
        int(kind_token.column or 0),
        int(kind_token.end_line or 0),
        int(kind_token.end_column or 0),
    )
    query = Query(str(kind_token).lower(), body, text, kind_span)
    validate_query(query)
    return query


__all__ = ["EXPECTED_WORDS", "nested_parser", "parse_nested"]
