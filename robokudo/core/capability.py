"""What an annotator can do beyond its ports: the values it reports, what it needs, its cost and reliability.

An annotator class is the one place its capability is declared: ``inputs`` / ``optional_inputs`` / ``outputs``
(CAS types) and a :class:`Capability` in its ``capability`` ClassVar. The knowledge base turns these into
ontology triples when it loads (``reasoning.knowledge.capabilities``); no Turtle file describes annotators.
Names in a Capability are ontology local names (``"Red"``, ``"Box"``, ``"PhysicalObject"``, ``"NeedsDepth"``);
the knowledge base rejects a name the ontology does not define, naming the class.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

DEFAULT_COST_MS = 10.0
"""The expected cost of an annotator that declares none."""

DEFAULT_RELIABILITY = 0.5
"""The reliability of an annotator that declares none (it ranks below the declared experts)."""


@dataclass(frozen=True, slots=True)
class Capability:
    """An annotator's declared capability (everything but its ports).

    ``label`` defaults to the words of the class name and ``description`` to the first paragraph of the class
    docstring; ``synonyms`` are other words for it. The value domains (``colors``, ``shapes``, ``sizes``,
    ``materials``, ``classes``) list the value classes it can report; an empty domain means any value of
    that kind. ``preconditions`` name ``rk:Precondition`` individuals (``NeedsDepth``, ``NeedsRegion``,
    ``NotForTransparentObjects``, ``NeedsDetectorModel``). ``cost_ms`` is the expected run time per frame and
    ``reliability`` (0..1) ranks providers of the same output, best first.
    """

    label: str = ""
    synonyms: tuple[str, ...] = ()
    description: str = ""
    colors: tuple[str, ...] = ()
    shapes: tuple[str, ...] = ()
    sizes: tuple[str, ...] = ()
    materials: tuple[str, ...] = ()
    classes: tuple[str, ...] = ()
    preconditions: tuple[str, ...] = ()
    cost_ms: float = DEFAULT_COST_MS
    reliability: float = DEFAULT_RELIABILITY

    def __post_init__(self) -> None:
        for field in fields(self):
            value = getattr(self, field.name)
            if field.type == "str" and not isinstance(value, str):
                raise TypeError(f"Capability.{field.name} must be a str, not {value!r}")
            if field.type == "tuple[str, ...]" and (
                not isinstance(value, tuple) or not all(isinstance(v, str) and v for v in value)
            ):
                raise TypeError(f"Capability.{field.name} must be a tuple of names, not {value!r}")
        if isinstance(self.cost_ms, bool) or not isinstance(self.cost_ms, int | float) or self.cost_ms < 0:
            raise ValueError(f"Capability.cost_ms must be a number >= 0, not {self.cost_ms!r}")
        if isinstance(self.reliability, bool) or not isinstance(self.reliability, int | float):
            raise ValueError(f"Capability.reliability must be a number within 0..1, not {self.reliability!r}")
        if not 0.0 <= self.reliability <= 1.0:
            raise ValueError(f"Capability.reliability must be within 0..1, not {self.reliability!r}")
