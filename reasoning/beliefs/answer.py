"""Answers to perception queries: object designators with provenance, drawn from the belief store.

An :class:`ObjectDesignator` is what the robot acts on: id, class (IRI and label), pose (position, quaternion
x-y-z-w, frame), size, region, attributes with confidence (and the alternatives experts also proposed), the
image ROI when the object was seen in this frame's image, and the experts that contributed; when the query asked
for a class, also the probability that the object answers to it (``class.answers`` in the JSON, only then): the
fused class distribution's mass on the classes the query's class test accepts
(:func:`~reasoning.fusion.rule.answer_probability`; a mustard answers "find all bottles", as it is packaged in
one). :class:`Answer` is a list of them; both turn into JSON-ready dicts. The tree leaf that answers from a frame
is :class:`trees.answer_step.AnswerStep`.
"""

from __future__ import annotations

import functools
import json
import re
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

from reasoning.beliefs.ranking import answer_order
from reasoning.beliefs.seen_together import SEEN_TOGETHER, last_stated
from reasoning.beliefs.selection import SelectionNote, Viewpoint, select
from reasoning.beliefs.store import BeliefFilter, BeliefStore
from reasoning.fusion.rule import (
    CLASS_ATTRIBUTE,
    AttributeBelief,
    ClassTest,
    Evidence,
    FusedAttribute,
    ValueSupport,
    answer_probability,
    fuse_values,
)
from reasoning.fusion.tracking import ObjectBelief
from reasoning.knowledge.index import ROOTS
from robokudo.core.types import ONTOLOGY_NAMESPACE, SemanticColor, Size

UNKNOWN_LABEL = "unknown object"
"""The label of an object of no known class: unclassified, or only the root class (no class profile fitted)."""


def class_iri(class_name: str) -> str:
    """The ontology IRI of a class name (IRIs are kept as they are)."""
    return class_name if "://" in class_name or class_name.startswith("urn:") else ONTOLOGY_NAMESPACE + class_name


@functools.lru_cache(maxsize=1024)
def class_label(class_name: str) -> str:
    """A readable label: the IRI's local name split at case changes, lower case (``lactose free milk``); the
    labels of the few classes answers name are made once."""
    local = re.split(r"[#/]", class_name)[-1]
    words = re.findall(r"[A-Z]+(?=[A-Z][a-z])|[A-Z]?[a-z]+|[A-Z]+|\d+", local)
    return " ".join(words).lower() if words else local


@dataclass(frozen=True, slots=True)
class PoseDesignator:
    """Position (metres) and unit quaternion (x, y, z, w) in ``frame``."""

    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]
    frame: str


@dataclass(frozen=True, slots=True)
class Alternative:
    """A value some expert proposed, with its fused probability and who proposed it."""

    value: str
    confidence: float
    experts: tuple[str, ...]


@dataclass(frozen=True, slots=True)
class AttributeDesignator:
    """A fused attribute: value, confidence, supporting experts, and every value proposed (conflicts kept)."""

    value: str
    confidence: float
    experts: tuple[str, ...]
    alternatives: tuple[Alternative, ...] = ()
    conflict: bool = False
    seen_with: tuple[str, ...] = ()
    """The other values stated with the fused one when the attribute was last stated, for an attribute whose values
    an object holds at once (:mod:`reasoning.beliefs.seen_together`: the red of a white-and-red can)."""


@dataclass(frozen=True, slots=True)
class ObjectDesignator:
    """One object in an answer (see the module docstring); ``roi`` is ``(x0, y0, x1, y1)`` pixels or None;
    ``answers`` is the probability that the object answers to the class the query asked for (None: it asked for
    none)."""

    id: int
    class_iri: str | None
    class_label: str | None
    pose: PoseDesignator
    size: tuple[float, float, float] | None
    size_class: str | None
    region: str | None
    attributes: dict[str, AttributeDesignator]
    experts: tuple[str, ...]
    confidence: float
    roi: tuple[int, int, int, int] | None = None
    first_seen: float = 0.0
    last_seen: float = 0.0
    status: str = "present"
    answers: float | None = None

    def class_probability(self) -> float | None:
        """The class probability shown to people: that the object answers to the asked class when the query asked
        for one, else that its fused class is right (None when no class was stated)."""
        if self.answers is not None:
            return self.answers
        stated = self.attributes.get(CLASS_ATTRIBUTE)
        return stated.confidence if stated is not None else None

    def shown_label(self) -> str:
        """The class label for people: ``?`` marks a class more likely wrong than right (for a query asking for a
        class: an object more likely not of that class)."""
        probability = self.class_probability()
        doubtful = self.class_label is not None and probability is not None and probability < 0.5
        return f"{self.class_label or UNKNOWN_LABEL}{'?' if doubtful else ''}"

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (numbers rounded to 6 decimals); ``class.answers`` is :attr:`answers`, only when the
        query asked for a class."""
        shown_class: dict[str, Any] = {"iri": self.class_iri, "label": self.class_label}
        if self.answers is not None:
            shown_class["answers"] = round(self.answers, 6)
        return {
            "id": self.id,
            "class": shown_class,
            "pose": {
                "position": _rounded(self.pose.position),
                "orientation": _rounded(self.pose.orientation),
                "frame": self.pose.frame,
            },
            "size": None if self.size is None else {"dimensions": _rounded(self.size), "class": self.size_class},
            "region": self.region,
            "attributes": {
                name: {
                    "value": a.value,
                    "confidence": round(a.confidence, 6),
                    "experts": list(a.experts),
                    "conflict": a.conflict,
                    **({"seen_with": list(a.seen_with)} if a.seen_with else {}),
                    "alternatives": [
                        {"value": alt.value, "confidence": round(alt.confidence, 6), "experts": list(alt.experts)}
                        for alt in a.alternatives
                    ],
                }
                for name, a in self.attributes.items()
            },
            "roi": None if self.roi is None else list(self.roi),
            "experts": list(self.experts),
            "confidence": round(self.confidence, 6),
            "first_seen": self.first_seen,
            "last_seen": self.last_seen,
            "status": self.status,
        }


@dataclass(frozen=True, slots=True)
class TrackDesignator:
    """A continuous task's target in this frame: the tracked class, whether it was seen, the filtered position and
    velocity in ``frame`` (None before it was first seen), its image position, the estimate's spread (metres),
    the seconds since it was last seen, the belief it was associated with (None when not seen) and the tracker."""

    target: str
    seen: bool
    position: tuple[float, float, float] | None
    velocity: tuple[float, float, float] | None
    frame: str
    pixel: tuple[float, float] | None
    spread: float | None
    unseen_for: float
    object_id: int | None
    tracker: str

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (numbers rounded to 6 decimals)."""
        return {
            "target": self.target,
            "seen": self.seen,
            "position": None if self.position is None else _rounded(self.position),
            "velocity": None if self.velocity is None else _rounded(self.velocity),
            "frame": self.frame,
            "pixel": None if self.pixel is None else _rounded(self.pixel),
            "spread": None if self.spread is None else round(self.spread, 6),
            "unseen_for": round(self.unseen_for, 6),
            "object_id": self.object_id,
            "tracker": self.tracker,
        }


@dataclass(frozen=True, slots=True)
class PlacementDesignator:
    """A free place on a surface: its centre ``pose`` on the surface (x along ``size[0]``, z the surface normal),
    the free ``size`` (metres), the ``footprint`` asked for, how many such footprints ``fits``, the ``region`` and
    how much of it was measured (``confidence``: the share of its surface the sensor saw)."""

    pose: PoseDesignator
    size: tuple[float, float]
    footprint: tuple[float, float]
    fits: int
    region: str | None
    confidence: float
    experts: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (numbers rounded to 6 decimals)."""
        return {
            "pose": {
                "position": _rounded(self.pose.position),
                "orientation": _rounded(self.pose.orientation),
                "frame": self.pose.frame,
            },
            "size": _rounded(self.size),
            "footprint": _rounded(self.footprint),
            "fits": self.fits,
            "region": self.region,
            "confidence": round(self.confidence, 6),
            "experts": list(self.experts),
        }

    def summary(self) -> str:
        """One line for people."""
        p = self.pose.position
        where = f"({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}) [{self.pose.frame}]"
        return (
            f"free {self.size[0]:.2f} x {self.size[1]:.2f} m at {where}"
            + (f" in {self.region}" if self.region else "")
            + f", fits {self.fits} x {self.footprint[0]:.2f} x {self.footprint[1]:.2f} m, seen {self.confidence:.2f}"
        )


def _has_class(found: ObjectDesignator) -> bool:
    """Whether a class probability means something to people: a query asked for a class, or the object has one
    (an unknown object's probability is that no class fits, which reads as confidence in a class)."""
    return found.answers is not None or (found.class_label is not None and found.class_label != UNKNOWN_LABEL)


def _local(class_name: str) -> str:
    return class_name.replace("#", "/").rsplit("/", 1)[-1]


def _rounded(values: tuple[float, ...]) -> list[float]:
    return [round(float(v), 6) for v in values]


@dataclass(frozen=True, slots=True)
class PointingAnswer:
    """What a person points at: ``kind`` (``object`` or ``region``), the object's belief id or the region's name,
    the angle between the arm's ray and the target, the angle between the ray's two estimates (shoulder-wrist,
    elbow-wrist), both in degrees, the confidence, and the ray (``origin``, unit ``direction``) in ``frame``."""

    kind: str
    object_id: int | None
    region: str
    angular_error_degrees: float
    spread_degrees: float
    confidence: float
    origin: tuple[float, float, float]
    direction: tuple[float, float, float]
    frame: str

    @property
    def target(self) -> str:
        """The target in words: ``object #12`` or ``region fridge``."""
        return f"object #{self.object_id}" if self.kind == "object" else f"region {self.region}"

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict."""
        return {
            "kind": self.kind,
            "object_id": self.object_id,
            "region": self.region or None,
            "angular_error_degrees": round(self.angular_error_degrees, 3),
            "spread_degrees": round(self.spread_degrees, 3),
            "confidence": round(self.confidence, 6),
            "ray": {"origin": _rounded(self.origin), "direction": _rounded(self.direction), "frame": self.frame},
        }


@dataclass(frozen=True, slots=True)
class Answer:
    """The answer to one query: the matching objects, best first (for a pointing query: the pointed object, and
    ``pointing`` says what is pointed at)."""

    query: str
    objects: tuple[ObjectDesignator, ...] = ()
    from_memory: bool = False
    observed: tuple[int, ...] = ()
    """The belief id of each object seen in this frame, in the order perception found them (not in the JSON)."""
    timed_out: bool = False
    """True when the query's timeout passed before perception finished (the objects then come from memory)."""
    track: TrackDesignator | None = None
    """A continuous task's target in this frame (None for other answers; ``track`` in the JSON only when set)."""
    pointing: PointingAnswer | None = None
    """The pointing target of a pointing query (None for other queries, and then absent from the JSON)."""
    placements: tuple[PlacementDesignator, ...] | None = None
    """Free places, largest first, when the query asked for free space (None when it did not)."""
    counted: bool = False
    """The query asked how many (``how many cans are there``): the summary starts with the number and the JSON
    has ``count``."""
    selection: SelectionNote | None = None
    """How the objects were selected when the query asked for a selection (``the top box``; ``selection`` in the
    JSON only then)."""

    def to_dict(self) -> dict[str, Any]:
        """A JSON-ready dict (``placements`` only when the query asked for free space)."""
        found: dict[str, Any] = {
            "query": self.query,
            "from_memory": self.from_memory,
            "timed_out": self.timed_out,
            "objects": [o.to_dict() for o in self.objects],
        }
        if self.track is not None:
            found["track"] = self.track.to_dict()
        if self.pointing is not None:
            found["pointing"] = self.pointing.to_dict()
        if self.placements is not None:
            found["placements"] = [p.to_dict() for p in self.placements]
        if self.counted:
            found["count"] = len(self.objects)
        if self.selection is not None:
            found["selection"] = self.selection.to_dict()
        return found

    def to_json(self, indent: int | None = 2) -> str:
        """The answer as JSON text."""
        return json.dumps(self.to_dict(), indent=indent)

    def summary(self) -> str:
        """One line per object, for people: a class more likely wrong than right is marked ``?``; ``class`` is the
        probability that the object answers to the class the query asked for (without one: that its class is
        right), ``exists`` the confidence that the object is there; then the free places
        when the query asked for free space."""
        lines = self._object_lines()
        if self.selection is not None and (self.objects or self.selection.unmeasured):
            lines.append(self.selection.summary())
        if self.counted:
            lines.insert(0, f"count: {len(self.objects)}")
        if self.placements is not None:
            lines += [p.summary() for p in self.placements] or ["no free place for the footprint"]
        return "\n".join(lines)

    def _object_lines(self) -> list[str]:
        lines: list[str] = []
        if self.pointing is not None:
            p = self.pointing
            lines.append(
                f"pointing at {p.target}: {p.angular_error_degrees:.1f}° off the arm's ray, "
                f"confidence {p.confidence:.2f}"
            )
        if not self.objects:
            return lines or ["no matching object"]
        for o in self.objects:
            p = o.pose.position
            colour = o.attributes.get(SemanticColor.attribute)
            probability = o.class_probability()
            lines.append(
                f"#{o.id} {o.shown_label()}"
                + (f" ({' and '.join((colour.value, *colour.seen_with))})" if colour else "")
                + f" at ({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}) [{o.pose.frame}]"
                + (f" in {o.region}" if o.region else "")
                + (f", class {probability:.2f}" if probability is not None and _has_class(o) else "")
                + f", exists {o.confidence:.2f}, by {', '.join(o.experts) or 'nobody'}"
            )
        return lines


@dataclass(frozen=True, slots=True)
class _BeliefView:
    """What a designator takes from one belief that no class test or naming changes: the belief (read only), its
    pose, size, experts and confidence, and each attribute's designator in the belief's order (None for a class
    attribute of several values, which is fused with the caller's class test)."""

    belief: ObjectBelief
    pose: PoseDesignator
    size: tuple[float, float, float] | None
    experts: tuple[str, ...]
    confidence: float
    attributes: tuple[tuple[str, AttributeDesignator | None], ...]
    fused_once: bool
    """True when no attribute waits for the class test (``attributes`` holds every designator)."""
    supported_class: str | None
    """The fused class when evidence supports it and no class test is needed to fuse it."""


def _attribute_designator(fused: FusedAttribute, seen_with: tuple[str, ...] = ()) -> AttributeDesignator:
    return AttributeDesignator(
        value=fused.value,
        confidence=fused.confidence,
        experts=fused.sources,
        alternatives=tuple(Alternative(s.value, s.confidence, s.sources) for s in fused.support),
        conflict=fused.conflict,
        seen_with=seen_with,
    )


def _belief_view(belief: ObjectBelief) -> _BeliefView:
    """The class-test-free part of a belief's designator (what :meth:`BeliefStore.query_views` remembers)."""
    attributes: list[tuple[str, AttributeDesignator | None]] = []
    supported_class = None
    for name, attribute in belief.attributes.items():
        if not attribute.values:
            continue
        if name == CLASS_ATTRIBUTE and len(attribute.values) > 1:  # subsumption: fused with the caller's test
            attributes.append((name, None))
            continue
        fused = fuse_values(name, attribute.values)  # one class value: the class test changes nothing
        together = last_stated(attribute.values) if name in SEEN_TOGETHER and len(attribute.values) > 1 else []
        attributes.append((name, _attribute_designator(fused, tuple(v for v in together if v != fused.value))))
        if name == CLASS_ATTRIBUTE and fused.supported:
            supported_class = fused.value
    x, y, z = belief.position.tolist()
    qx, qy, qz, qw = belief.orientation.tolist()
    return _BeliefView(
        belief=belief,
        pose=PoseDesignator(position=(x, y, z), orientation=(qx, qy, qz, qw), frame=belief.frame),
        size=None if belief.dimensions is None else tuple(belief.dimensions.tolist()),  # type: ignore[arg-type]
        experts=tuple(sorted(belief.sources)),
        confidence=belief.confidence,
        attributes=tuple(attributes),
        fused_once=all(made is not None for _, made in attributes),
        supported_class=supported_class,
    )


def designator(
    belief: ObjectBelief,
    *,
    class_test: ClassTest | None = None,
    roi: tuple[int, int, int, int] | None = None,
    iri_of: Callable[[str], str] = class_iri,
    label_of: Callable[[str], str] = class_label,
    guessed_class: str | None = None,
    asked_class: str | None = None,
    answering: Sequence[Evidence] = (),
) -> ObjectDesignator:
    """The designator of a belief; ``roi`` is given when the object was seen in the current image.

    ``guessed_class`` names the object when this answer offers it as a candidate of that class without evidence
    the belief keeps (its class attribute still shows what the evidence says). ``asked_class`` is the class the
    query asked for: the designator then carries the probability that the object answers to it (``class_test``
    is the query's: a class packaged in the asked one answers to it), counting with the belief's class evidence
    this frame's ``answering`` statements (that the object answers to the asked class as a whole), which the
    belief does not keep.
    """
    return _designate(
        _belief_view(belief), class_test=class_test, roi=roi, iri_of=iri_of, label_of=label_of,
        guessed_class=guessed_class, asked_class=asked_class, answering=answering,
    )  # fmt: skip


def _designate(
    view: _BeliefView,
    *,
    class_test: ClassTest | None = None,
    roi: tuple[int, int, int, int] | None = None,
    iri_of: Callable[[str], str] = class_iri,
    label_of: Callable[[str], str] = class_label,
    guessed_class: str | None = None,
    asked_class: str | None = None,
    answering: Sequence[Evidence] = (),
) -> ObjectDesignator:
    """The designator of a belief's view (see :func:`designator`)."""
    belief = view.belief
    supported_class = view.supported_class
    attributes: dict[str, AttributeDesignator]
    if view.fused_once:
        attributes = dict(view.attributes)  # type: ignore[arg-type]
    else:
        attributes = {}
        for name, made in view.attributes:
            if made is None:
                fused = fuse_values(name, belief.attributes[name].values, class_test)
                made = _attribute_designator(fused)
                supported_class = fused.value if fused.supported else None
            attributes[name] = made
    class_name = guessed_class or belief.class_name
    if class_name is None:
        class_name = supported_class
    if class_name is None and asked_class and CLASS_ATTRIBUTE in attributes:
        # a candidate by its leading class, a guess (reasoning.beliefs.class_candidates): named by it, shown with "?"
        class_name = attributes[CLASS_ATTRIBUTE].value
    if class_name is not None and asked_class and class_test is not None and not class_test(class_name, asked_class):
        # a candidate by its leading refinement (food, perhaps canned food, for "find the can"): named by the stated
        # class that answers the query best
        class_name = _answering_alternative(attributes.get(CLASS_ATTRIBUTE), asked_class, class_test) or class_name
    size_attribute = attributes.get(Size.attribute)
    answers = None
    if asked_class and _local(asked_class) != ROOTS["class"]:  # asking for any object asks for no class
        values = _with_answering(belief.attributes.get(CLASS_ATTRIBUTE), answering)
        answers = answer_probability(values, asked_class, class_test) if values else 0.0
    return ObjectDesignator(
        id=belief.id,
        class_iri=iri_of(class_name) if class_name else None,
        class_label=label_of(class_name) if class_name and _local(class_name) != ROOTS["class"] else UNKNOWN_LABEL,
        pose=view.pose,
        size=view.size,
        size_class=size_attribute.value if size_attribute else None,
        region=belief.region or None,
        attributes=attributes,
        experts=view.experts,
        confidence=view.confidence,
        roi=roi,
        first_seen=belief.first_seen,
        last_seen=belief.last_seen,
        status=belief.status,
        answers=answers,
    )


def _answering_alternative(stated: AttributeDesignator | None, asked_class: str, class_test: ClassTest) -> str | None:
    """The most probable stated class that answers a query for ``asked_class``, or None."""
    if stated is None:
        return None
    answering = [a for a in stated.alternatives if class_test(a.value, asked_class)]
    return max(answering, key=lambda a: a.confidence).value if answering else None


def _with_answering(classes: AttributeBelief | None, answering: Sequence[Evidence]) -> Mapping[str, ValueSupport]:
    """The class values of a belief with this frame's answering statements added to a copy (the belief is left
    as it is)."""
    if not answering:
        return classes.values if classes is not None else {}
    merged = AttributeBelief(CLASS_ATTRIBUTE)
    if classes is not None:
        merged.merge(classes)
    for statement in answering:
        merged.add(statement)
    return merged.values


def answer_from_memory(
    store: BeliefStore, belief_filter: BeliefFilter, query: str = "", *, counted: bool = False, **options: Any
) -> Answer:
    """Answer a query from the store alone (no perception): the matching known objects, most confident first; with
    a ``limit``, the ones most likely to be what was asked (:func:`~reasoning.beliefs.ranking.answer_order`);
    with a selection, the ones it selects (each measured from the last view the store keeps of its recording and
    frame: the camera pose and support plane, as the frame measured it); ``counted``: the query asked how many."""
    note = None
    if belief_filter.selection is not None:
        views = store.query_views(replace(belief_filter, limit=None), _belief_view)
        views.sort(key=lambda v: answer_order(v.belief, belief_filter))
        by_id = {v.belief.id: v for v in views}
        kept = store.viewpoints((v.belief.recording, v.belief.frame) for v in views)
        chosen, note = select(
            [v.belief for v in views],
            belief_filter.selection,
            Viewpoint(),
            belief_filter.limit,
            viewpoints=lambda b: kept.get((b.recording, b.frame), Viewpoint()),
        )
        views = [by_id[b.id] for b in chosen]
    elif belief_filter.limit is not None:
        views = store.query_views(replace(belief_filter, limit=None), _belief_view)
        views.sort(key=lambda v: answer_order(v.belief, belief_filter))
        views = views[: belief_filter.limit]
    else:
        views = store.query_views(belief_filter, _belief_view)
        views.sort(key=lambda v: (-v.confidence, v.belief.id))
    designators = tuple(
        _designate(v, class_test=belief_filter.class_test, asked_class=belief_filter.object_class, **options)
        for v in views
    )
    return Answer(query=query, objects=designators, from_memory=True, counted=counted, selection=note)
