"""Selection of objects by a relation among the results: ``the top box``, ``the leftmost cup``, ``the biggest bowl``.

A query selects with the top-level key ``select``: a selection name (``select: top``), or a block naming it and the
rank among the results (``select: { by: biggest, rank: 2 }``, the second biggest). Each selection orders the
objects found by one measure, greatest or least first; the measures are taken by the answer
(:mod:`reasoning.beliefs.selection`). This module is the one place the selections and their measures are declared.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType

from queries.model import Block, Number, Symbol, Value

SELECT_KEY = "select"
"""The top-level key of a selection (``detect { obj: { type: box }, select: top, max_results: 1 }``)."""

SELECT_KEYS: tuple[str, ...] = ("by", "rank")
"""The keys a selection block may hold: the selection's name and the rank (1: the first, 2: the second...)."""


@dataclass(frozen=True, slots=True)
class Measure:
    """What a selection measures of each object: ``name`` (in answers), ``unit`` and ``description``."""

    name: str
    unit: str
    description: str


HEIGHT = Measure("height", "m", "height")
IMAGE_X = Measure("camera_x", "m", "camera x (image left to right)")
DISTANCE = Measure("distance", "m", "distance from the camera")
VOLUME = Measure("volume", "m^3", "volume")

MEASURES: tuple[Measure, ...] = (HEIGHT, IMAGE_X, DISTANCE, VOLUME)
"""Every measure a selection may order by."""


@dataclass(frozen=True, slots=True)
class Selection:
    """A named selection: the ``measure`` it orders by and whether the ``greatest`` value comes first."""

    name: str
    measure: Measure
    greatest: bool

    @property
    def description(self) -> str:
        """In words: ``greatest height``."""
        return f"{'greatest' if self.greatest else 'least'} {self.measure.description}"


SELECTIONS: MappingProxyType[str, Selection] = MappingProxyType(
    {
        selection.name: selection
        for selection in (
            Selection("top", HEIGHT, True),
            Selection("bottom", HEIGHT, False),
            Selection("leftmost", IMAGE_X, False),
            Selection("rightmost", IMAGE_X, True),
            Selection("closest", DISTANCE, False),
            Selection("farthest", DISTANCE, True),
            Selection("biggest", VOLUME, True),
            Selection("smallest", VOLUME, False),
        )
    }
)
"""The selections by name, in the order they are documented."""


@dataclass(frozen=True, slots=True)
class SelectionRequest:
    """A query's selection: which one and the rank of the first object answered (1: the extreme one)."""

    selection: Selection
    rank: int = 1


def selection_request(value: Value | None) -> SelectionRequest | None:
    """The selection a ``select`` value asks for (None when absent or not a known selection; validation reports
    a bad value with its position)."""
    if isinstance(value, Symbol):
        found = SELECTIONS.get(value.name.lower())
        return None if found is None else SelectionRequest(found)
    if isinstance(value, Block):
        by, rank = value.get("by"), value.get("rank")
        if not isinstance(by, Symbol) or by.name.lower() not in SELECTIONS:
            return None
        if rank is None:
            return SelectionRequest(SELECTIONS[by.name.lower()])
        if isinstance(rank, Number) and rank.unit is None and rank.value.is_integer() and rank.value >= 1:
            return SelectionRequest(SELECTIONS[by.name.lower()], int(rank.value))
    return None


__all__ = [
    "MEASURES",
    "SELECTIONS",
    "SELECT_KEY",
    "SELECT_KEYS",
    "Measure",
    "Selection",
    "SelectionRequest",
    "selection_request",
]
