"""The typed query model shared by the nested, natural and JSON front ends.

A :class:`Query` has a kind (``detect``, ``inspect``, ``track``, ``scan``,
``stop``) and a :class:`Block` body.  A block is an ordered tuple of
:class:`Field` objects; each field has a lower-case key and a typed value:

* :class:`Symbol` -- a bare identifier (``Milk``, ``free_space``),
* :class:`String` -- quoted text (``"lactose free"``),
* :class:`Number` -- a number normalised to SI with the SI unit symbol
  (``30cm`` -> ``Number(0.3, "m")``; a plain number has unit ``None``),
* :class:`ListValue` -- ``[white, blue]``,
* :class:`Range` -- ``0.5m..1m``,
* :class:`Block` -- a nested key-value block,
* :class:`Asked` -- ``?``, the value is asked for.

Source positions (:class:`Span`) and the source text are kept for error
messages but never take part in equality, so a model parsed from the
nested form, a phrase or JSON compares equal when it means the same.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import TypeAlias

IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
"""What a key or a symbol looks like (ASCII identifier)."""

SI_UNITS: frozenset[str] = frozenset({"m", "s", "rad", "kg"})
"""The unit symbols a :class:`Number` may carry (its value is in these units)."""


@dataclass(frozen=True, slots=True)
class Span:
    """A source region: 1-based line and column; the end is exclusive."""

    line: int
    column: int
    end_line: int
    end_column: int


NO_SPAN = Span(0, 0, 0, 0)
"""The span of a model built in code rather than parsed from text."""


@dataclass(frozen=True, slots=True)
class Symbol:
    """A bare identifier value, e.g. ``Milk``; case is kept."""

    name: str

    def __post_init__(self) -> None:
        if IDENTIFIER.fullmatch(self.name) is None:
            raise ValueError(f"symbol name is not an identifier: {self.name!r}")


@dataclass(frozen=True, slots=True)
class String:
    """A quoted text value, e.g. ``"lactose free"``."""

    text: str


@dataclass(frozen=True, slots=True)
class Number:
    """A number in SI units; ``unit`` is the SI symbol or ``None``."""

    value: float
    unit: str | None = None

    def __post_init__(self) -> None:
        value = float(self.value)
        if not math.isfinite(value):
            raise ValueError(f"number is not finite: {self.value!r}")
        if self.unit is not None and self.unit not in SI_UNITS:
            raise ValueError(f"unit is not an SI unit symbol: {self.unit!r}")
        object.__setattr__(self, "value", value)


@dataclass(frozen=True, slots=True)
class ListValue:
    """A list of values, e.g. ``[white, blue]``."""

    items: tuple[Value, ...]


@dataclass(frozen=True, slots=True)
class Range:
    """An inclusive range between two scalar values, e.g. ``0.5m..1m``."""

    low: Value
    high: Value


@dataclass(frozen=True, slots=True)
class Asked:
    """The value ``?``: the query asks for it."""


@dataclass(frozen=True, slots=True)
class Field:
    """One ``key: value`` pair; the key is a lower-case identifier."""

    key: str
    value: Value
    span: Span = field(default=NO_SPAN, compare=False)

    def __post_init__(self) -> None:
        if IDENTIFIER.fullmatch(self.key) is None or self.key != self.key.lower():
            raise ValueError(f"key is not a lower-case identifier: {self.key!r}")


@dataclass(frozen=True, slots=True)
class Block:
    """An ordered block of fields, e.g. ``{ type: Milk, location: Fridge }``."""

    fields: tuple[Field, ...] = ()

    def field(self, key: str) -> Field | None:
        """Return the first field with ``key`` (case-insensitive), if any."""
        wanted = key.lower()
        for item in self.fields:
            if item.key == wanted:
                return item
        return None

    def get(self, key: str) -> Value | None:
        """Return the value of ``key`` (case-insensitive), or ``None``."""
        found = self.field(key)
        return None if found is None else found.value

    def keys(self) -> tuple[str, ...]:
        """Return the keys in source order."""
        return tuple(item.key for item in self.fields)


Value: TypeAlias = Symbol | String | Number | ListValue | Range | Block | Asked
"""Any typed query value."""

ANYWHERE = "anywhere"
"""The ``location`` value that restricts the search to no region (``location: anywhere``)."""

HUMAN_KEY = "human"
"""The key whose block describes a person to find (``detect { human: {} }``); its block may be empty."""

POINTING_KEY = "pointing"
"""The key whose block asks what a person points at (``detect { pointing: { target: object } }``)."""

POINTING_TARGETS: tuple[str, ...] = ("object", "region")
"""What a pointing query may ask for: the object pointed at, or the region (a place of the semantic map)."""

FREE_SPACE_KEY = "free_space"
"""The key of a scan's free-space block (``scan { free_space: { region: shelf, for: Cup } }``), and the value of
``for`` in the short form ``scan { region: shelf, for: free_space }``."""

FREE_SPACE_KEYS: tuple[str, ...] = ("region", "for", "footprint")
"""The keys a free-space block may hold: where, what is to be put there (a class), and its footprint
(``footprint: [10cm, 8cm]``, width and depth; one length for a square)."""

TEXT_KEY = "text"
"""The key of the text printed on an object: ``text: "lactose free"`` looks for it, ``text: ?`` asks for it, and
an unquoted truth value switches text reading on or off (``text: true``, ``text: false``; see :func:`text_switch`)."""

_SWITCHES = {"true": True, "yes": True, "false": False, "no": False}


def text_switch(value: Value | None) -> bool | None:
    """Whether an unquoted ``true``/``false`` (``yes``/``no``) asks for text reading or skips it; None for any other
    value (a quoted ``"false"`` is text to look for)."""
    if isinstance(value, Symbol):
        return _SWITCHES.get(value.name.strip().lower())
    return None


KINDS: tuple[str, ...] = ("detect", "inspect", "track", "scan", "stop")
"""The known query kinds, in canonical order."""

CONTINUOUS_KINDS: frozenset[str] = frozenset({"track"})
"""The kinds that run until cancelled (one answer per frame) rather than ending with one answer."""

LOST_AFTER_KEY = "lost_after"
"""The key of a continuous query saying how long its target may go unseen before the task ends (a duration)."""


@dataclass(frozen=True, slots=True)
class Query:
    """A perception query: a kind and a body of fields."""

    kind: str
    body: Block
    source: str = field(default="", compare=False)
    kind_span: Span = field(default=NO_SPAN, compare=False)
    counted: bool = field(default=False, compare=False)
    """A how-many question (``how many cans are there``): the same detection, and the answer says how many."""

    def get(self, path: str) -> Value | None:
        """Return the value at a dotted key path such as ``"obj.type"``."""
        current: Value = self.body
        for key in path.split("."):
            if not isinstance(current, Block):
                return None
            found = current.get(key)
            if found is None:
                return None
            current = found
        return current
