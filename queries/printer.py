"""The canonical printer: a :class:`Query` back in the nested form.

``parse_nested(format_query(q)) == q`` for every valid query ``q``: keys and
kinds are printed lower-case, numbers in SI with their unit symbol
(``0.3m``), strings with JSON escapes, fields separated by ``", "`` and
blocks written as ``{ key: value }`` on one line.
"""

from __future__ import annotations

import json

from queries.model import Asked, Block, ListValue, Number, Query, Range, String, Symbol, Value

_EXACT_INTEGER_LIMIT = 1e15
"""Whole numbers below this magnitude are printed without a decimal point."""


def format_number(number: Number) -> str:
    """Print a number so that it parses back to the same float (``0.3m``, ``12``)."""
    value = number.value
    whole = value.is_integer() and abs(value) < _EXACT_INTEGER_LIMIT
    return (str(int(value)) if whole else repr(value)) + (number.unit or "")


def format_string(text: str) -> str:
    """Quote text with JSON escapes (lone surrogates are escaped too)."""
    if any("\ud800" <= char <= "\udfff" for char in text):
        return json.dumps(text)
    return json.dumps(text, ensure_ascii=False)


def format_value(value: Value) -> str:
    """Print one value in the nested form."""
    if isinstance(value, Symbol):
        return value.name
    if isinstance(value, String):
        return format_string(value.text)
    if isinstance(value, Number):
        return format_number(value)
    if isinstance(value, Asked):
        return "?"
    if isinstance(value, ListValue):
        return "[" + ", ".join(format_value(item) for item in value.items) + "]"
    if isinstance(value, Range):
        return f"{format_value(value.low)}..{format_value(value.high)}"
    return format_block(value)


def format_block(block: Block) -> str:
    """Print a block as ``{ key: value, ... }`` (``{}`` when empty)."""
    if not block.fields:
        return "{}"
    inner = ", ".join(f"{item.key}: {format_value(item.value)}" for item in block.fields)
    return "{ " + inner + " }"


def format_query(query: Query) -> str:
    """Print a query in the canonical nested form, e.g. ``detect { obj: { type: Milk } }``."""
    return f"{query.kind} {format_block(query.body)}"
