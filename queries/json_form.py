"""Queries written as JSON, and the model as lossless, tagged JSON.

Two shapes are read by :func:`parse_json`:

* the plain form ``{"detect": {"obj": {"type": "milk", "location": "fridge"}}}``:
  one key naming the kind; objects are blocks, arrays lists, JSON numbers
  unit-less numbers, ``null`` or ``"?"`` asks for a value; a string is a
  symbol if it is an identifier, a number with unit if it reads like one
  (``"30cm"``), a range if it reads like ``"0.5m..1m"``, and text otherwise;
* the tagged form written by :func:`query_to_json`:
  ``{"kind": "detect", "body": {"obj": {"block": {"type": {"symbol": "Milk"}}}}}``
  where each value is an object with one tag: ``symbol``, ``string``,
  ``number`` (plus optional ``unit``), ``list``, ``range``, ``block`` or
  ``asked``.  ``query_from_json(query_to_json(q)) == q`` for every query.

JSON text is parsed with lark (``json.lark``) so errors carry line and column.
"""

from __future__ import annotations

import functools
import json
from collections.abc import Callable
from importlib import resources
from typing import Any, NamedTuple, cast

from lark import Lark, Token, Transformer
from lark.exceptions import UnexpectedInput

from queries.errors import QueryError, located_error
from queries.model import (
    IDENTIFIER,
    SI_UNITS,
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
    Value,
)
from queries.syntax_errors import syntax_error
from queries.units import QUANTITY, UnitError, parse_quantity
from queries.validation import MAX_DEPTH, MAX_QUERY_LENGTH, check_length, validate_query

TAGS: tuple[str, ...] = ("symbol", "string", "number", "list", "range", "block", "asked")
"""The value tags of the tagged JSON form."""

EXPECTED_WORDS: tuple[tuple[frozenset[str], str], ...] = (
    (frozenset({"RBRACE"}), "'}'"),
    (frozenset({"RBRACKET"}), "']'"),
    (frozenset({"_COMMA"}), "','"),
    (frozenset({"_COLON"}), "':'"),
    (frozenset({"STRING"}), "a key"),
    (
        frozenset({"LBRACE", "LBRACKET", "STRING", "NUMBER", "TRUE", "FALSE", "NULL"}),
        "a JSON value",
    ),
    (frozenset({"LBRACE"}), "'{'"),
    (frozenset({"$END"}), "end of input"),
)
"""How expected terminals of ``json.lark`` are named in error messages."""


class JsonNode(NamedTuple):
    """A decoded JSON value with its source position (0 when not parsed)."""

    tag: str
    payload: Any
    line: int = 0
    column: int = 0
    end_line: int = 0
    end_column: int = 0


class _ToNodes(Transformer[Token, Any]):
    """Grammar actions building :class:`JsonNode` trees; stateless."""

    def string(self, children: list[Token]) -> JsonNode:
        return _token_node("string", json.loads(children[0]), children[0])

    def number(self, children: list[Token]) -> JsonNode:
        return _token_node("number", float(children[0]), children[0])

    def literal(self, children: list[Token]) -> JsonNode:
        token = children[0]
        payload = {"true": True, "false": False, "null": None}[str(token)]
        return _token_node("literal", payload, token)

    def pair(self, children: list[Any]) -> tuple[JsonNode, JsonNode]:
        key: Token = children[0]
        return _token_node("string", json.loads(key), key), children[1]

    def object(self, children: list[Any]) -> JsonNode:
        pairs = [item for item in children[1:-1] if item is not None]
        return _wrap_node("object", pairs, children[0], children[-1])

    def array(self, children: list[Any]) -> JsonNode:
        items = [item for item in children[1:-1] if item is not None]
        return _wrap_node("array", items, children[0], children[-1])


def _token_node(tag: str, payload: Any, token: Token) -> JsonNode:
    """Make a node positioned at ``token``."""
    return JsonNode(
        tag,
        payload,
        int(token.line or 0),
        int(token.column or 0),
        int(token.end_line or 0),
        int(token.end_column or 0),
    )


def _wrap_node(tag: str, payload: Any, opener: Token, closer: Token) -> JsonNode:
    """Make a node spanning from ``opener`` to ``closer``."""
    return JsonNode(
        tag,
        payload,
        int(opener.line or 0),
        int(opener.column or 0),
        int(closer.end_line or 0),
        int(closer.end_column or 0),
    )


@functools.cache
def json_parser() -> Lark:
    """Return the LALR parser for ``json.lark`` (built once per process)."""
    grammar = resources.files("queries").joinpath("json.lark").read_text(encoding="utf-8")
    return Lark(grammar, parser="lalr", transformer=_ToNodes(), maybe_placeholders=True)


class _Converter:
    """Turns :class:`JsonNode` trees into the model, raising located errors."""

    def __init__(self, source: str) -> None:
        self.source = source

    def error(self, node: JsonNode, message: str, expected: tuple[str, ...] = ()) -> QueryError:
        return located_error(self.source, message, node.line, node.column, expected)

    def query(self, node: JsonNode) -> Query:
        if node.tag != "object":
            raise self.error(node, 'expected a JSON object such as {"detect": {...}}')
        pairs: list[tuple[JsonNode, JsonNode]] = node.payload
        keys = {key.payload for key, _ in pairs}
        if keys == {"kind", "body"} and len(pairs) == 2:
            return self.tagged_query(pairs)
        if len(pairs) != 1:
            where = pairs[1][0] if len(pairs) > 1 else node
            message = "expected exactly one key, the query kind"
            if "type" in keys:  # the object designator of a served goal's "obj" field, given as a query
                message += (
                    ' (a "type" key is the served goal\'s designator form): write it as {"detect": {"obj": {...}}}'
                )
            raise self.error(where, message)
        key, body = pairs[0]
        if body.tag != "object":
            raise self.error(body, f"expected an object as the body of '{key.payload}'")
        kind = self.key(key)
        return self.make_query(kind, key, self.block(body, self.plain_value, 1))

    def tagged_query(self, pairs: list[tuple[JsonNode, JsonNode]]) -> Query:
        parts = {key.payload: (key, value) for key, value in pairs}
        _, kind = parts["kind"]
        if kind.tag != "string":
            raise self.error(kind, "expected the query kind as a string")
        body = parts["body"][1]
        if body.tag != "object":
            raise self.error(body, "expected an object as the query body")
        kind_name = self.key(kind)
        return self.make_query(kind_name, kind, self.block(body, self.tagged_value, 1))

    def make_query(self, kind: str, where: JsonNode, body: Block) -> Query:
        span = Span(where.line, where.column, where.end_line, where.end_column)
        return Query(kind, body, self.source, span)

    def key(self, node: JsonNode) -> str:
        text: str = node.payload
        if IDENTIFIER.fullmatch(text) is None:
            raise self.error(node, f"expected an identifier as a key, not {json.dumps(text)}")
        return text.lower()

    def block(self, node: JsonNode, convert: Callable[[JsonNode, int], Value], depth: int) -> Block:
        if depth > MAX_DEPTH:
            raise self.error(node, f"nested deeper than {MAX_DEPTH} levels")
        fields: list[Field] = []
        for key, value in node.payload:
            span = Span(key.line, key.column, value.end_line, value.end_column)
            fields.append(Field(self.key(key), convert(value, depth + 1), span))
        return Block(tuple(fields))

    def plain_value(self, node: JsonNode, depth: int) -> Value:
        if depth > MAX_DEPTH:
            raise self.error(node, f"nested deeper than {MAX_DEPTH} levels")
        if node.tag == "object":
            return self.block(node, self.plain_value, depth)
        if node.tag == "array":
            return ListValue(tuple(self.plain_value(item, depth + 1) for item in node.payload))
        if node.tag == "number":
            return self.number(node, node.payload, None)
        if node.tag == "string":
            return scalar_from_text(node.payload)
        if node.payload is None:
            return Asked()
        return Symbol("true" if node.payload else "false")  # JSON true / false: the nested form's bare words

    def number(self, node: JsonNode, value: object, unit: object) -> Number:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise self.error(node, "expected a JSON number")
        if unit is not None and unit not in SI_UNITS:
            known = ", ".join(sorted(SI_UNITS))
            raise self.error(node, f"expected an SI unit ({known}) or null as the unit")
        try:
            return Number(float(value), unit if isinstance(unit, str) else None)
        except ValueError:
            raise self.error(node, "number is out of range") from None

    def tagged_value(self, node: JsonNode, depth: int) -> Value:
        if depth > MAX_DEPTH:
            raise self.error(node, f"nested deeper than {MAX_DEPTH} levels")
        if node.tag != "object" or not node.payload:
            raise self.error(node, 'expected a tagged value such as {"symbol": "Milk"}', TAGS)
        parts = {key.payload: value for key, value in node.payload}
        tags = [key for key in parts if key in TAGS]
        tag = tags[0] if len(tags) == 1 else ""
        allowed = {"number", "unit"} if tag == "number" else {tag}
        if not tag or not set(parts) <= allowed or len(parts) != len(node.payload):
            raise self.error(node, f"expected one tag: {', '.join(TAGS)}", TAGS)
        content = parts[tag]
        if tag == "symbol":
            text = self.string(content)
            if IDENTIFIER.fullmatch(text) is None:
                raise self.error(content, "expected an identifier as a symbol")
            return Symbol(text)
        if tag == "string":
            return String(self.string(content))
        if tag == "number":
            unit_node = parts.get("unit")
            unit = None if unit_node is None else unit_node.payload
            return self.number(content, content.payload, unit)
        if tag == "asked":
            if content.payload is not True:
                raise self.error(content, "expected true")
            return Asked()
        if tag == "block":
            if content.tag != "object":
                raise self.error(content, "expected an object of fields")
            return self.block(content, self.tagged_value, depth)
        if content.tag != "array":
            raise self.error(content, "expected an array")
        items = tuple(self.tagged_value(item, depth + 1) for item in content.payload)
        if tag == "list":
            return ListValue(items)
        if len(items) != 2:
            raise self.error(content, "expected two range bounds")
        return Range(items[0], items[1])

    def string(self, node: JsonNode) -> str:
        if node.tag != "string":
            raise self.error(node, "expected a string")
        text: str = node.payload
        return text


def scalar_from_text(text: str) -> Value:
    """Read a plain-JSON string: ``?``, a symbol, ``30cm``, ``0.5m..1m`` or text."""
    if text == "?":
        return Asked()
    single = _single_scalar(text)
    if single is not None:
        return single
    low_text, dots, high_text = text.partition("..")
    if dots:
        low, high = _single_scalar(low_text), _single_scalar(high_text)
        if low is not None and high is not None:
            return Range(low, high)
    return String(text)


def _single_scalar(text: str) -> Symbol | Number | None:
    """Return the symbol or number ``text`` spells, if it spells one."""
    if IDENTIFIER.fullmatch(text) is not None:
        return Symbol(text)
    if QUANTITY.fullmatch(text) is not None:
        try:
            return parse_quantity(text)
        except UnitError:
            return None
    return None


def parse_json(text: str) -> Query:
    """Parse and validate a query written as JSON (plain or tagged form)."""
    check_length(text, MAX_QUERY_LENGTH)
    try:
        node = cast(JsonNode, json_parser().parse(text))
    except UnexpectedInput as error:
        raise syntax_error(text, error, EXPECTED_WORDS, "a JSON object") from None
    query = _Converter(text).query(node)
    validate_query(query)
    return query


def _node_from_data(data: object, depth: int) -> JsonNode:
    """Wrap decoded JSON data as position-less nodes."""
    if depth > MAX_DEPTH + 2:
        raise QueryError(f"nested deeper than {MAX_DEPTH} levels", 0, 0)
    if isinstance(data, dict):
        pairs = [(_node_from_data(key, depth + 1), _node_from_data(value, depth + 1)) for key, value in data.items()]
        if any(key.tag != "string" for key, _ in pairs):
            raise QueryError("expected string keys", 0, 0)
        return JsonNode("object", pairs)
    if isinstance(data, (list, tuple)):
        return JsonNode("array", [_node_from_data(item, depth + 1) for item in data])
    if isinstance(data, str):
        return JsonNode("string", data)
    if isinstance(data, bool) or data is None:
        return JsonNode("literal", data)
    if isinstance(data, (int, float)):
        return JsonNode("number", data)
    raise QueryError(f"expected JSON data, not {type(data).__name__}", 0, 0)


def query_from_json(data: object) -> Query:
    """Build and validate a query from decoded JSON data (plain or tagged form)."""
    query = _Converter("").query(_node_from_data(data, 0))
    validate_query(query)
    return query


def value_to_json(value: Value) -> dict[str, Any]:
    """Return the tagged JSON form of one value."""
    if isinstance(value, Symbol):
        return {"symbol": value.name}
    if isinstance(value, String):
        return {"string": value.text}
    if isinstance(value, Number):
        if value.unit is None:
            return {"number": value.value}
        return {"number": value.value, "unit": value.unit}
    if isinstance(value, Asked):
        return {"asked": True}
    if isinstance(value, ListValue):
        return {"list": [value_to_json(item) for item in value.items]}
    if isinstance(value, Range):
        return {"range": [value_to_json(value.low), value_to_json(value.high)]}
    return {"block": _block_to_json(value)}


def _block_to_json(block: Block) -> dict[str, Any]:
    """Return a block's fields as a key -> tagged value mapping."""
    return {item.key: value_to_json(item.value) for item in block.fields}


def query_to_json(query: Query) -> dict[str, Any]:
    """Return the lossless tagged JSON form: ``{"kind": ..., "body": {...}}``."""
    return {"kind": query.kind, "body": _block_to_json(query.body)}
