"""The Common Analysis Structure: the observations and annotations one Pipeline works on."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import TypeVar

from robokudo.core.types import Annotation, ObjectHypothesis, View

V = TypeVar("V", bound=View)
A = TypeVar("A", bound=Annotation)


@dataclass(frozen=True)
class SetView:
    """A pending write that replaces one view."""

    view: View


@dataclass(frozen=True)
class AddAnnotation:
    """A pending write that adds a scene-level annotation."""

    annotation: Annotation


@dataclass(frozen=True)
class AttachAnnotation:
    """A pending write that attaches an annotation to an object hypothesis."""

    hypothesis: ObjectHypothesis
    annotation: Annotation


CasWrite = SetView | AddAnnotation | AttachAnnotation


class CAS:
    """Observations (one view per type) and a list of annotations.

    Values are stored by reference: a CAS never copies images or clouds. Filtering by type honours
    subclasses, so asking for ``Annotation`` returns everything.
    """

    def __init__(self) -> None:
        self._views: dict[type[View], View] = {}
        self._annotations: list[Annotation] = []

    def view(self, view_type: type[V]) -> V | None:
        """The view of exactly this type or of a subtype, or None."""
        found = self._views.get(view_type)
        if found is None:
            found = next((v for t, v in self._views.items() if issubclass(t, view_type)), None)
        return found  # type: ignore[return-value]

    def set_view(self, view: View) -> None:
        """Store ``view``, replacing any earlier view of the same type."""
        self._views[type(view)] = view

    def add(self, annotation: Annotation) -> None:
        """Add a scene-level annotation."""
        self._annotations.append(annotation)

    def annotations(self, annotation_type: type[A]) -> list[A]:
        """Scene-level annotations of this type or a subtype, in insertion order."""
        return [a for a in self._annotations if isinstance(a, annotation_type)]

    def view_types(self) -> set[type[View]]:
        """The types of the views present."""
        return set(self._views)

    def apply(self, writes: Iterable[CasWrite]) -> None:
        """Apply pending writes in order (how an annotator's result is committed)."""
        for write in writes:
            if isinstance(write, SetView):
                self.set_view(write.view)
            elif isinstance(write, AddAnnotation):
                self.add(write.annotation)
            else:
                write.hypothesis.annotations.append(write.annotation)

    def __repr__(self) -> str:
        views = ", ".join(sorted(t.__name__ for t in self._views))
        return f"CAS(views=[{views}], annotations={len(self._annotations)})"
