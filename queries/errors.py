"""The one error type of the query language, with its source location."""

from __future__ import annotations

from collections.abc import Iterable

_EXCERPT_WIDTH = 72
"""Longest source line shown in an excerpt before it is cut around the caret."""


class QueryError(Exception):
    """A malformed or invalid query, located at a line and column.

    ``message`` says what was wrong or expected, ``line`` and ``column`` are
    1-based, ``excerpt`` is the source line plus a caret line, and
    ``expected`` lists what would have been accepted at that point.
    """

    def __init__(
        self,
        message: str,
        line: int,
        column: int,
        excerpt: str = "",
        expected: Iterable[str] = (),
    ) -> None:
        self.message = message
        self.line = line
        self.column = column
        self.excerpt = excerpt
        self.expected: list[str] = list(expected)
        super().__init__(message, line, column)

    def __str__(self) -> str:
        if self.line <= 0:
            return self.message
        where = f"{self.message} at line {self.line}, column {self.column}"
        return f"{where}\n{self.excerpt}" if self.excerpt else where


def offset_to_position(source: str, offset: int) -> tuple[int, int]:
    """Return the 1-based (line, column) of a character offset in ``source``."""
    offset = max(0, min(offset, len(source)))
    line = source.count("\n", 0, offset) + 1
    column = offset - (source.rfind("\n", 0, offset) + 1) + 1
    return line, column


def make_excerpt(source: str, line: int, column: int) -> str:
    """Return the source line and a caret under ``column``, both indented."""
    lines = source.split("\n")
    if not 1 <= line <= len(lines):
        return ""
    text = lines[line - 1].rstrip("\r")
    index = max(0, min(column - 1, len(text)))
    start = 0
    if len(text) > _EXCERPT_WIDTH:
        start = max(0, min(index - _EXCERPT_WIDTH // 2, len(text) - _EXCERPT_WIDTH))
        text = text[start : start + _EXCERPT_WIDTH]
    padding = "".join("\t" if char == "\t" else " " for char in text[: index - start])
    shown = "".join(char if char.isprintable() or char == "\t" else "?" for char in text)
    return f"  {shown}\n  {padding}^"


def located_error(
    source: str,
    message: str,
    line: int,
    column: int,
    expected: Iterable[str] = (),
) -> QueryError:
    """Build a :class:`QueryError` with an excerpt of ``source`` at line/column."""
    return QueryError(message, line, column, make_excerpt(source, line, column), expected)


def describe_alternatives(items: Iterable[str]) -> str:
    """Join ``["'}'", "a key"]`` as ``"'}' or a key"``."""
    words = list(dict.fromkeys(items))
    if not words:
        return "nothing"
    if len(words) == 1:
        return words[0]
    return ", ".join(words[:-1]) + " or " + words[-1]
