"""Typed answers of the knowledge base: resolved words, object profiles, region boxes, annotator specs."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

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

    def origin(self, field: str) -> str | None:
        """The class that declares ``field`` for this profile (None when the field is unset)."""
        for name, source in self.origins:
            if name == field:
                return source
        return None


@dataclass(frozen=True, slots=True)
class RegionBox:
    """A named region of a semantic map: a box with its centre pose in ``frame`` and its size in metres."""

    name: str
    region_class: str
    frame: str
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]
    size: tuple[float, float, float]
    label: str = ""
    semantic_map: str = ""

    @property
    def pose(self) -> np.ndarray:
        """The 4x4 homogeneous transform of the box centre in ``frame``."""
        x, y, z, w = self.orientation
        transform = np.eye(4)
        transform[:3, :3] = [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
        transform[:3, 3] = self.position
        return transform

    def contains(self, point: np.ndarray | tuple[float, float, float]) -> bool:
        """True when ``point`` (in ``frame``) lies inside the box."""
        pose = self.pose
        local = pose[:3, :3].T @ (np.asarray(point, dtype=np.float64).reshape(3) - pose[:3, 3])
        return bool(np.all(np.abs(local) <= np.asarray(self.size) / 2.0 + 1e-9))


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


@dataclass(frozen=True, slots=True)
class Conditions:
    """What holds where the planner plans: is a depth image available, is a region known, is a detector model
    configured (False by default, so plans include model-based detectors only when one is)."""

    depth: bool = True
    region: bool = True
    model: bool = False
