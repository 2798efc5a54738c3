"""Choosing the front end for a query text: JSON, nested form or a phrase."""

from __future__ import annotations

from typing import Literal

from queries.json_form import parse_json
from queries.model import IDENTIFIER, Query
from queries.natural import parse_natural
from queries.nested import parse_nested

QueryForm = Literal["json", "nested", "natural"]
"""The three ways a query can be written."""


def _skip_blank(text: str, index: int) -> int:
    """Return the index of the first non-whitespace character from ``index``."""
    while index < len(text) and text[index].isspace():
        index += 1
    return index


def detect_form(text: str) -> QueryForm:
    """Tell how ``text`` is written.

    ``{`` first (after whitespace) means JSON; a comment, or an identifier
    followed by ``{``, means the nested form; anything else is a phrase.
    """
    index = _skip_blank(text, 0)
    if text.startswith("{", index):
        return "json"
    if text.startswith(("#", "//"), index):
        return "nested"
    word = IDENTIFIER.match(text, index)
    if word is not None and text.startswith("{", _skip_blank(text, word.end())):
        return "nested"
    return "natural"


def parse_query(text: str) -> Query:
    """Parse a query written in any form; raise :class:`~queries.errors.QueryError`."""
    form = detect_form(text)
    if form == "json":
        return parse_json(text)
    if form == "nested":
        return parse_nested(text)
    return parse_natural(text)
