"""ObjectTracker: follows one object (the one the query describes) with a particle filter over the hypotheses."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import ClassVar

from annotators.tracking.particle_filter import FilterSettings
from annotators.tracking.tracker import Candidate, TargetTracker
from robokudo.core.capability import Capability
from robokudo.core.types import (
    ATTRIBUTE_TYPES,
    CameraInfo,
    CasType,
    Classification,
    ObjectHypothesis,
    PointCloud,
    Pose,
    SemanticColor,
    Shape,
    Size,
    TargetTrack,
    Text,
)

OBJECT_CATEGORIES = ("FoodOrDrink", "Tableware", "Cookware", "KitchenUtensil", "CleaningSupply")
"""The object classes it follows (everything but people, whom the HumanTracker follows)."""


class ObjectTracker(TargetTracker):
    """Follows one object: among the hypotheses that match the query's description (class, colour, ...) the one
    nearest the tracked object's estimate, filtered by a particle filter; its 3-D and image position per frame."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis,)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (
        Pose, Classification, SemanticColor, Shape, Size, Text, PointCloud, CameraInfo,
    )  # fmt: skip
    outputs: ClassVar[tuple[type[CasType], ...]] = (TargetTrack,)
    capability: ClassVar[Capability] = Capability(
        label="object tracker",
        synonyms=("object follower",),
        classes=OBJECT_CATEGORIES,
        cost_ms=2.0,
        reliability=0.8,
    )

    def __init__(
        self,
        target_classes: Sequence[str] = (),
        target_values: Mapping[str, Sequence[str]] | Sequence[tuple[str, Sequence[str]]] = (),
        settings: FilterSettings | None = None,
        seed: int = 0,
        name: str | None = None,
    ) -> None:
        """``target_classes``: the class asked for and its subclasses (empty: any class); ``target_values``:
        attribute -> accepted values (``{"color": ["blue"]}``), every attribute given must match."""
        super().__init__(settings=settings, seed=seed, name=name)
        self.target_classes = frozenset(target_classes)
        values = dict(target_values.items() if isinstance(target_values, Mapping) else target_values)
        known = {t.attribute for t in ATTRIBUTE_TYPES}
        unknown = sorted(set(values) - known)
        if unknown:
            raise ValueError(f"ObjectTracker cannot match {', '.join(unknown)}; attributes: {', '.join(sorted(known))}")
        self.target_values = {key: frozenset(v.strip().lower() for v in vs) for key, vs in values.items()}

    def target_name(self) -> str:
        """The class asked for when there is one."""
        return min(self.target_classes, key=len) if self.target_classes else ""

    def accepts(self, hypothesis: ObjectHypothesis) -> bool:
        """True when the hypothesis states the asked class (if any) and every asked attribute value."""
        if self.target_classes and not any(
            c.class_name in self.target_classes for c in hypothesis.find(Classification)
        ):
            return False
        for attribute, accepted in self.target_values.items():
            stated = {a.attribute_value().lower() for a in hypothesis.annotations if a.attribute == attribute}
            if not stated & accepted:
                return False
        return True

    def lock_score(self, candidate: Candidate) -> float:
        """The confidence of the class stated for it (or of the hypothesis)."""
        stated = [
            c.confidence for c in candidate.hypothesis.find(Classification) if c.class_name in self.target_classes
        ]
        return max(stated, default=candidate.hypothesis.confidence)
