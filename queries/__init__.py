"""Perception queries: one typed model, written nested, as a phrase or as JSON.

>>> from queries import parse_query, format_query
>>> format_query(parse_query("find the red cup on the table"))
'detect { obj: { type: cup, color: red, location: { on: table } }, max_results: 1 }'
"""

from queries.dispatch import QueryForm, detect_form, parse_query
from queries.errors import QueryError
from queries.json_form import parse_json, query_from_json, query_to_json
from queries.model import (
    ANYWHERE,
    CONTINUOUS_KINDS,
    KINDS,
    LOST_AFTER_KEY,
    NO_SPAN,
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
from queries.natural import parse_natural
from queries.nested import parse_nested
from queries.printer import format_query, format_value
from queries.validation import MAX_DEPTH, MAX_QUERY_LENGTH, validate_query

__all__ = [
    "ANYWHERE",
    "CONTINUOUS_KINDS",
    "KINDS",
    "LOST_AFTER_KEY",
    "MAX_DEPTH",
    "MAX_QUERY_LENGTH",
    "NO_SPAN",
    "Asked",
    "Block",
    "Field",
    "ListValue",
    "Number",
    "Query",
    "QueryError",
    "QueryForm",
    "Range",
    "Span",
    "String",
    "Symbol",
    "Value",
    "detect_form",
    "format_query",
    "format_value",
    "parse_json",
    "parse_natural",
    "parse_nested",
    "parse_query",
    "query_from_json",
    "query_to_json",
    "validate_query",
]
