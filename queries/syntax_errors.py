"""Turning lark's parse exceptions into located :class:`QueryError` messages."""

from __future__ import annotations

from collections.abc import Collection, Sequence

from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken

from queries.errors import QueryError, describe_alternatives, located_error, offset_to_position

_CONTEXT_CHARS = 24
"""How much of the text before an error is quoted in ``after '...'``."""


class ActionError(Exception):
    """A problem found while building the model from a token (e.g. a bad unit).

    Raised inside grammar actions, which do not know the source text; the
    parse function turns it into a :class:`QueryError`.
    """

    def __init__(self, message: str, line: int, column: int) -> None:
        super().__init__(message)
        self.message = message
        self.line = line
        self.column = column


def action_error_to_query_error(source: str, error: ActionError) -> QueryError:
    """Locate an :class:`ActionError` in ``source``."""
    return located_error(source, error.message, error.line, error.column)


def context_before(source: str, offset: int) -> str:
    """Return the text just before ``offset``, from the last open bracket, trimmed."""
    before = " ".join(source[:offset].split())
    cut = max(before.rfind("{"), before.rfind("["))
    tail = before[cut + 1 :].strip() if cut >= 0 else before
    if not tail:
        tail = before
    if len(tail) > _CONTEXT_CHARS:
        tail = "..." + tail[-_CONTEXT_CHARS:].lstrip()
    return tail


def _end_offset(source: str) -> int:
    """Return the offset just after the last non-blank character."""
    return len(source.rstrip())


def _position_offset(source: str, line: int, column: int) -> int:
    """Return the character offset of a 1-based line and column."""
    offset = 0
    for _ in range(line - 1):
        found = source.find("\n", offset)
        if found < 0:
            return len(source)
        offset = found + 1
    return min(len(source), offset + column - 1)


def syntax_error(
    source: str,
    error: UnexpectedInput,
    groups: Sequence[tuple[frozenset[str], str]],
    start_description: str,
) -> QueryError:
    """Translate a lark ``UnexpectedInput`` into a located :class:`QueryError`.

    ``groups`` names sets of terminals in the order they are listed in the
    message (``{RBRACE}`` -> ``"'}'"``, all value-starting terminals ->
    ``"a value"``); larger sets are matched first.  ``start_description``
    replaces ``"a key"`` when the error is at the very beginning.
    """
    expected_terminals: set[str] = set()
    if isinstance(error, UnexpectedToken):
        try:
            expected_terminals = set(error.interactive_parser.accepts())  # type: ignore[no-untyped-call]
        except Exception:
            expected_terminals = set(error.expected)
        if error.token.type == "$END":
            offset = _end_offset(source)
        else:
            offset = _position_offset(source, error.line, error.column)
    elif isinstance(error, UnexpectedCharacters):
        expected_terminals = set(error.allowed or ())
        offset = _position_offset(source, error.line, error.column)
    else:
        offset = _end_offset(source)
    line, column = offset_to_position(source, offset)
    if isinstance(error, UnexpectedCharacters) and error.char == '"':
        message = "expected a closing '\"' for this string (escape newlines and control characters)"
        return located_error(source, message, line, column, ["'\"'"])
    expected = describe_terminals(expected_terminals, groups)
    context = context_before(source, offset)
    if not context:
        expected = [start_description if word == "a key" else word for word in expected]
    message = f"expected {describe_alternatives(expected)}"
    if context:
        message += f" after '{context}'"
    return located_error(source, message, line, column, expected)


def describe_terminals(terminals: Collection[str], groups: Sequence[tuple[frozenset[str], str]]) -> list[str]:
    """Describe expected terminal names with the words of ``groups``."""
    remaining = set(terminals)
    matched: list[tuple[int, str]] = []
    by_size = sorted(enumerate(groups), key=lambda item: -len(item[1][0]))
    for index, (names, word) in by_size:
        if names and names <= remaining:
            matched.append((index, word))
            remaining -= names
    words = [word for _, word in sorted(matched)]
    words.extend(sorted(remaining))
    return words
