"""Semantic checks that need no ontology, raising located :class:`QueryError`.

Checked: the kind is known; the body and nested blocks are not empty (but ``human: {}``, any person); no
key is given twice in one block; ``stop`` names a ``task``; sizes,
distances, durations, counts and ids are not negative (counts and ids are
whole numbers, ``max_results`` at least 1) and carry a fitting unit; range
bounds are scalars of one type, numbers share a unit and ``low <= high``;
``confidence`` is a plain number from 0 to 1; ``size`` is a size word (the
answer is filtered by size class, so a metric size or range is refused here
rather than ignored later); a ``free_space`` block of a ``scan`` holds only ``region``, ``for`` and
``footprint`` (one or two positive lengths); a top-level ``select`` of a ``detect`` or ``inspect`` query names a
known selection (:mod:`queries.selection`), alone or in a block with a whole ``rank`` of at least 1; nesting is at
most :data:`MAX_DEPTH` deep.  Whether an object class exists
is left to the reasoning layer.
"""

from __future__ import annotations

from types import MappingProxyType

from queries.errors import QueryError, describe_alternatives, located_error, offset_to_position
from queries.model import (
    FREE_SPACE_KEY,
    FREE_SPACE_KEYS,
    HUMAN_KEY,
    KINDS,
    POINTING_KEY,
    POINTING_TARGETS,
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
from queries.selection import SELECT_KEY, SELECT_KEYS, SELECTIONS

MAX_QUERY_LENGTH = 10_000
"""Longest query text accepted, in characters."""

MAX_DEPTH = 32
"""Deepest nesting of blocks and lists accepted."""

NON_NEGATIVE_KEYS: frozenset[str] = frozenset(
    {
        "min_size",
        "max_size",
        "width",
        "height",
        "depth",
        "length",
        "radius",
        "diameter",
        "distance",
        "timeout",
        "lost_after",
        "duration",
        "max_results",
        "task",
        "id",
    }
)
"""Keys whose numbers must not be negative."""

WHOLE_NUMBER_KEYS: frozenset[str] = frozenset({"max_results", "task", "id"})
"""Keys whose numbers must be whole (and unit-less)."""

KEY_UNITS: MappingProxyType[str, str] = MappingProxyType(
    {
        "min_size": "m",
        "max_size": "m",
        "width": "m",
        "height": "m",
        "depth": "m",
        "length": "m",
        "radius": "m",
        "diameter": "m",
        "distance": "m",
        "timeout": "s",
        "lost_after": "s",
        "duration": "s",
    }
)
"""The SI unit a number under these keys must have, if it has one."""


WORD_ONLY_KEYS: MappingProxyType[str, str] = MappingProxyType(
    {"size": "a size word such as tiny, small, medium or large (metric sizes and ranges are not supported)"}
)
"""Keys whose value must be words (or a list of words), with what to write instead."""

FRACTION_KEYS: frozenset[str] = frozenset({"confidence"})
"""Keys whose number is a plain fraction from 0 to 1."""

NUMBER_ONLY_KEYS: frozenset[str] = (NON_NEGATIVE_KEYS | FRACTION_KEYS) - {"task"}
"""Keys that take numbers (or ranges of them), never a word: ``max_results: two`` would otherwise be ignored.
``task`` is left out: ``stop { task: all }``."""


def check_length(text: str, limit: int = MAX_QUERY_LENGTH) -> None:
    """Raise :class:`QueryError` if ``text`` is longer than ``limit`` characters."""
    if len(text) > limit:
        line, column = offset_to_position(text, limit)
        raise located_error(text, f"query is longer than {limit} characters", line, column)


def validate_query(query: Query) -> None:
    """Raise :class:`QueryError` at the first semantic problem in ``query``."""
    if query.kind not in KINDS:
        raise _error(
            query,
            query.kind_span,
            f"unknown query kind '{query.kind}', expected {describe_alternatives(KINDS)}",
            KINDS,
        )
    if query.kind == "stop" and query.body.field("task") is None:
        raise _error(query, query.kind_span, "'stop' needs a 'task' to stop", ["task"])
    if not query.body.fields:
        raise _error(query, query.kind_span, f"'{query.kind}' needs at least one key")
    free_space = query.body.field(FREE_SPACE_KEY)
    if free_space is not None:
        _check_free_space(query, free_space)
    selection = query.body.field(SELECT_KEY)
    if selection is not None:
        _check_selection(query, selection)
    stack: list[tuple[Block, int]] = [(query.body, 1)]
    while stack:
        block, depth = stack.pop()
        seen: dict[str, Field] = {}
        nested: list[tuple[Block, int]] = []
        for item in block.fields:
            first = seen.get(item.key)
            if first is not None:
                where = ""
                if first.span.line:
                    where = f" (first at line {first.span.line}, column {first.span.column})"
                raise _error(query, item.span, f"key '{item.key}' is given twice{where}")
            seen[item.key] = item
            nested.extend(_check_field(query, item, depth))
        stack.extend(reversed(nested))


def _check_pointing(query: Query, item: Field, block: Block) -> None:
    """A pointing block names its target, ``object`` or ``region``, and nothing else."""
    target = block.field("target")
    if target is None:
        raise _error(query, item.span, f"'{POINTING_KEY}' needs a target: {' or '.join(POINTING_TARGETS)}")
    if not isinstance(target.value, Symbol) or target.value.name.lower() not in POINTING_TARGETS:
        raise _error(
            query, target.span, f"a pointing target is {' or '.join(POINTING_TARGETS)}", list(POINTING_TARGETS)
        )
    others = [f.key for f in block.fields if f.key != "target"]
    if others:
        raise _error(query, item.span, f"'{POINTING_KEY}' takes only a target, not {', '.join(others)}")


def _error(query: Query, span: Span, message: str, expected: tuple[str, ...] | list[str] = ()) -> QueryError:
    """Build an error located at the start of ``span`` in the query's source."""
    return located_error(query.source, message, span.line, span.column, expected)


def _check_field(query: Query, item: Field, depth: int) -> list[tuple[Block, int]]:
    """Check one field's value; return nested blocks to check with their depth."""
    nested: list[tuple[Block, int]] = []
    pending: list[tuple[Value, int]] = [(item.value, depth)]
    while pending:
        value, level = pending.pop()
        if level > MAX_DEPTH:
            raise _error(query, item.span, f"'{item.key}' is nested deeper than {MAX_DEPTH} levels")
        if item.key in WORD_ONLY_KEYS and isinstance(value, Number | Range):
            raise _error(query, item.span, f"'{item.key}' takes {WORD_ONLY_KEYS[item.key]}")
        if isinstance(value, Block):
            if item.key == POINTING_KEY and level == 1:
                _check_pointing(query, item, value)
            if not value.fields and not (item.key == HUMAN_KEY and level == 1):
                raise _error(query, item.span, f"'{item.key}' has an empty block")
            nested.append((value, level + 1))
        elif isinstance(value, ListValue):
            pending.extend((entry, level + 1) for entry in reversed(value.items))
        elif isinstance(value, Range):
            _check_range(query, item, value)
        elif isinstance(value, Number):
            _check_number(query, item, value)
        elif item.key in NUMBER_ONLY_KEYS and isinstance(value, Symbol | String):
            shown = value.name if isinstance(value, Symbol) else value.text
            raise _error(query, item.span, f"'{item.key}' takes a number, not '{shown}'")
    return nested


def _check_free_space(query: Query, item: Field) -> None:
    """Check a ``free_space`` block: a scan's, with known keys, one region and a footprint of positive lengths."""
    if query.kind != "scan":
        raise _error(query, item.span, f"'{FREE_SPACE_KEY}' belongs to a 'scan' query, not '{query.kind}'", ["scan"])
    block = item.value
    if not isinstance(block, Block):
        raise _error(query, item.span, f"'{FREE_SPACE_KEY}' takes a block such as {{ region: shelf, for: Cup }}", ["{"])
    if query.body.field("region") is not None and block.field("region") is not None:
        raise _error(query, item.span, f"the region is given twice: once in '{FREE_SPACE_KEY}', once beside it")
    for entry in block.fields:
        if entry.key not in FREE_SPACE_KEYS:
            expected = ", ".join(FREE_SPACE_KEYS)
            message = f"'{FREE_SPACE_KEY}' has no key '{entry.key}' (expected {expected})"
            raise _error(query, entry.span, message, FREE_SPACE_KEYS)
    target = block.get("for")
    if target is not None and not isinstance(target, Symbol | String):
        raise _error(query, _span(block, "for"), "'for' in 'free_space' names one object class, such as Cup")
    footprint = block.get("footprint")
    if footprint is not None:
        lengths = footprint.items if isinstance(footprint, ListValue) else (footprint,)
        if not 1 <= len(lengths) <= 2 or not all(
            isinstance(v, Number) and v.unit in (None, "m") and v.value > 0 for v in lengths
        ):
            raise _error(
                query,
                _span(block, "footprint"),
                "'footprint' takes one or two positive lengths, width and depth, such as [10cm, 8cm] or 0.1",
            )


SELECTING_KINDS: tuple[str, ...] = ("detect", "inspect")
"""The kinds whose answer may be a selection among the objects found."""


def _check_selection(query: Query, item: Field) -> None:
    """Check a ``select``: a known selection name, or a block of one (``by``) and a whole ``rank`` of at least 1."""
    if query.kind not in SELECTING_KINDS:
        raise _error(
            query, item.span, f"'{SELECT_KEY}' belongs to a {' or '.join(SELECTING_KINDS)} query, not '{query.kind}'"
        )
    names = tuple(SELECTIONS)
    value = item.value
    name_span = item.span
    if isinstance(value, Block):
        for entry in value.fields:
            if entry.key not in SELECT_KEYS:
                message = f"'{SELECT_KEY}' has no key '{entry.key}' (expected {', '.join(SELECT_KEYS)})"
                raise _error(query, entry.span, message, SELECT_KEYS)
        rank = value.field("rank")
        if rank is not None and not (
            isinstance(rank.value, Number)
            and rank.value.unit is None
            and rank.value.value.is_integer()
            and rank.value.value >= 1
        ):
            raise _error(query, rank.span, "'rank' must be a whole number of at least 1 (1 is the first)")
        by = value.field("by")
        if by is None:
            raise _error(query, item.span, f"'{SELECT_KEY}' needs 'by': {describe_alternatives(names)}", names)
        value, name_span = by.value, by.span
    if not isinstance(value, Symbol):
        message = f"'{SELECT_KEY}' takes a selection such as top, leftmost, closest or biggest"
        raise _error(query, name_span, message, names)
    if value.name.lower() not in SELECTIONS:
        message = f"unknown selection '{value.name}', expected {describe_alternatives(names)}"
        raise _error(query, name_span, message, names)


def _span(block: Block, key: str) -> Span:
    """The span of ``key``'s field in ``block`` (no span when absent)."""
    found = block.field(key)
    return found.span if found is not None else Span(0, 0, 0, 0)


def _check_number(query: Query, item: Field, number: Number) -> None:
    """Check a number against what its key allows."""
    key = item.key
    if key in NON_NEGATIVE_KEYS and number.value < 0:
        raise _error(query, item.span, f"'{key}' must not be negative")
    if key in WHOLE_NUMBER_KEYS:
        if number.unit is not None or not number.value.is_integer():
            raise _error(query, item.span, f"'{key}' must be a whole number without a unit")
        if key == "max_results" and number.value < 1:
            raise _error(query, item.span, "'max_results' must be at least 1")
    if key in FRACTION_KEYS and (number.unit is not None or not 0.0 <= number.value <= 1.0):
        raise _error(query, item.span, f"'{key}' must be a number from 0 to 1 without a unit")
    wanted = KEY_UNITS.get(key)
    if wanted is not None and number.unit is not None and number.unit != wanted:
        raise _error(query, item.span, f"'{key}' needs a unit of '{wanted}', not '{number.unit}'")


def _check_range(query: Query, item: Field, bounds: Range) -> None:
    """Check that range bounds are comparable scalars in order."""
    low, high = bounds.low, bounds.high
    scalars = (Symbol, String, Number)
    if not isinstance(low, scalars) or not isinstance(high, scalars):
        raise _error(query, item.span, f"range bounds of '{item.key}' must be symbols, strings or numbers")
    if type(low) is not type(high):
        raise _error(query, item.span, f"range bounds of '{item.key}' must be of one type")
    if isinstance(low, Number) and isinstance(high, Number):
        if low.unit != high.unit:
            raise _error(query, item.span, f"range bounds of '{item.key}' must have the same unit")
        if low.value > high.value:
            raise _error(query, item.span, f"range of '{item.key}' has its low bound above its high bound")
        _check_number(query, item, low)
        _check_number(query, item, high)


__all__ = [
    "FRACTION_KEYS",
    "KEY_UNITS",
    "MAX_DEPTH",
    "MAX_QUERY_LENGTH",
    "NON_NEGATIVE_KEYS",
    "NUMBER_ONLY_KEYS",
    "WHOLE_NUMBER_KEYS",
    "WORD_ONLY_KEYS",
    "check_length",
    "validate_query",
]
