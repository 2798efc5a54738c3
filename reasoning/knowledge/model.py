"""Typed answers of the knowledge base: resolved words, object profiles, annotator specs (region boxes are
:class:`robokudo.core.regions.RegionBox`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

Kind = Literal["class", "region", "region_class", "color", "shape", "size", "material"]
"""What a word can resolve to: an object class, a named region of the semantic map, a region class, or a
colour / shape / size class / material value class."""

KINDS: tuple[Kind, ...] = ("class", "region", "region_class", "color", "shape", "size", "material")
"""All kinds, in the order :meth:`KnowledgeBase.resolve` prefers them when a word names several."""

KIND_WORDS: dict[Kind, str] = {
    "class": "object class",
    "region": "region",
    "region_class": "region class",
    "color": "colour",
    "shape": "shape",
    "size": "size class",
    "material": "material",
}
"""How messages name each kind."""


@dataclass(frozen=True, slots=True)
class Resolved:
    """A word resolved to an ontology term: its kind and its name (the ``rk:`` local name)."""

    kind: Kind
    name: str


@dataclass(frozen=True, slots=True)
class ObjectProfile:
    """What an object class typically looks like and where it is kept (inherited values included).

    Values are ontology names (``"White"``, ``"Box"``, ``"Fridge"``); ``origins`` maps each inherited or
    own field to the class that declares it.
    """

    name: str
    label: str
    synonyms: tuple[str, ...]
    colors: tuple[str, ...]
    shape: str | None
    size_class: str | None
    material: str | None
    transparent: bool | None
    stored_in: str | None
    texts: tuple[str, ...]
    brand: str | None
    origins: tuple[tuple[str, str], ...] = ()
    handle: bool | None = None
    open_top: bool | None = None
    height_to_width: tuple[float, float] | None = None
    """Form features: a handle on the side, open at the top, the (min, max) of height over width; None: any."""
    elongation: tuple[float, float] | None = None
    """The (min, max) of the longest extent over the second longest (a banana's footprint is long and narrow, a
    tin's round); None: any."""
    printed: bool | None = None
    """A label printed in several colours (a can's), False: a plain one-coloured surface; None: either."""
    waisted: bool | None = None
    """Narrower across the middle of its height than across its top and bottom, standing as it typically stands (a
    drill on its battery), False: never; None: either."""
    packaged_in: str | None = None
    """The container class objects of the class are typically sold and kept in (a mustard's bottle), or None."""

    def origin(self, field: str) -> str | None:
        """The class that declares ``field`` for this profile (None when the field is unset)."""
        for name, source in self.origins:
            if name == field:
                return source
        return None


@dataclass(frozen=True, slots=True)
class AnnotatorSpec:
    """An annotator's capabilities as its class declares them (ports and its Capability), read from the ontology.

    ``name`` is the class name and ``implemented_by`` the class's ``<module>.<qualname>``; port and value names
    are ontology names; an empty value domain means "any value of that kind".
    """

    name: str
    implemented_by: str
    inputs: tuple[str, ...]
    optional_inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    colors: frozenset[str]
    shapes: frozenset[str]
    sizes: frozenset[str]
    materials: frozenset[str]
    classes: frozenset[str]
    preconditions: tuple[str, ...]
    cost_ms: float
    reliability: float
    label: str = ""

    def domain(self, kind: Kind) -> frozenset[str]:
        """The declared values of one kind this annotator can report (empty: any value, or not that kind)."""
        return _DOMAINS[kind](self) if kind in _DOMAINS else frozenset()


_DOMAINS: dict[Kind, Callable[[AnnotatorSpec], frozenset[str]]] = {
    "class": lambda spec: spec.classes,
    "color": lambda spec: spec.colors,
    "shape": lambda spec: spec.shapes,
    "size": lambda spec: spec.sizes,
    "material": lambda spec: spec.materials,
}
"""Which field of an :class:`AnnotatorSpec` holds its domain of each value kind."""


@dataclass(frozen=True, slots=True)
class Conditions:
    """What holds where the planner plans: is a depth image available, is a region known, is a detector model
    configured (False by default, so plans include model-based detectors only when one is), does the query ask
    for a transparent object (then experts for opaque objects only are left out, whatever the class)."""

    depth: bool = True
    region: bool = True
    model: bool = False
    transparent: bool = False
