"""From a parsed query to a Plan: interpretation, then synthesis against the sensor source."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace

from queries.model import CONTINUOUS_KINDS, FREE_SPACE_KEY, Query
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.model import AnnotatorSpec, Conditions
from reasoning.planning.interpretation import TRACK_TYPE, Interpretation, interpret, text_told_classes
from reasoning.planning.plan import Plan, Task
from reasoning.planning.planner import SensorSource, plan_requirements
from robokudo.core.regions import RegionBox
from robokudo.core.types import type_by_name

DEPTH_TYPES = frozenset({"DepthImage", "PointCloud"})
COLOUR_TYPE = "ColorImage"
"""The sensor type text is read on."""
REGION_PRECONDITION = "NeedsRegion"
ROOT_CLASS = "PhysicalObject"


@dataclass(frozen=True)
class QueryPlan:
    """A plan together with the interpretation it was made from."""

    plan: Plan
    interpretation: Interpretation


def region_parameters(box: RegionBox) -> dict[str, object]:
    """Constructor arguments that hand a region box to an annotator needing one (plain data, no ontology types)."""
    return {
        "region": box.name,
        "box_pose": tuple(float(v) for v in box.pose.reshape(-1)),
        "box_size": tuple(float(v) for v in box.size),
    }


def class_profiles(kb: KnowledgeBase) -> tuple[dict[str, object], ...]:
    """What every object class typically looks like, as plain data for a knowledge-based classifier.

    Colours, shape and size are the ontology's lower-case labels; classes that say nothing visible are left out.
    The ancestors come the most specific first (a classifier names the nearest one the cues leave no doubt about);
    ``packaged_in`` is the container class the objects are typically packaged in with its ancestors (what a query
    for that container also asks for), or (); ``brand`` the product's brand, ``kind_texts`` the printed texts it
    inherits from its ancestors (what kind of product it is: reading the brand says that too); ``kind_handles``,
    for a class that does not say whether it has a handle, what its kinds say (:func:`kind_handles`).
    """
    profiles = []
    for name in kb.names_of_kind("class"):
        profile = kb.object_profile(name)
        if not (
            profile.colors
            or profile.shape
            or profile.size_class
            or profile.texts
            or profile.brand
            or profile.height_to_width
        ):
            continue
        inherited = {text for parent in kb.superclasses(name) for text in kb.object_profile(parent).texts}
        profiles.append(
            {
                "class": name,
                "colors": tuple(kb.label(c) for c in profile.colors),
                "shape": kb.label(profile.shape) if profile.shape else None,
                "size": kb.label(profile.size_class) if profile.size_class else None,
                "texts": profile.texts,
                "brand": profile.brand,
                "kind_texts": tuple(t for t in profile.texts if t in inherited),
                "handle": profile.handle,
                "kind_handles": kind_handles(kb, name) if profile.handle is None else (),
                "open_top": profile.open_top,
                "printed": profile.printed,
                "waisted": profile.waisted,
                "height_to_width": profile.height_to_width,
                "elongation": profile.elongation,
                "ancestors": (name, *sorted(kb.superclasses(name), key=lambda a: -len(kb.superclasses(a)))),
                "packaged_in": (profile.packaged_in, *sorted(kb.superclasses(profile.packaged_in)))
                if profile.packaged_in
                else (),
            }
        )
    return tuple(profiles)


def kind_handles(kb: KnowledgeBase, name: str) -> tuple[bool, ...]:
    """Whether the kinds of class ``name`` have a handle, each value its subclasses state once (False first): a
    bottle is a plain bottle or a jug, so it may have a handle or not."""
    return tuple(
        sorted({handle for kind in kb.subclasses(name) if (handle := kb.object_profile(kind).handle) is not None})
    )


def annotator_parameters(
    kb: KnowledgeBase,
    box: RegionBox | None,
    profiles: tuple[dict[str, object], ...] | None = None,
    expected: str | None = None,
    task: Task | None = None,
    annotators: Iterable[AnnotatorSpec] | None = None,
    region: Mapping[str, object] | None = None,
) -> dict[str, dict[str, object]]:
    """Constructor arguments the plan hands to annotators, from the ontology and the task.

    An annotator that needs a region gets the region box; one that can report any object class (its class
    domain is the root class) is a classifier by knowledge and gets the profiles of the classes and the class
    the query asks for (``expected``). A provider of free placements gets the task's footprint, the region box
    when there is one and the task's result limit. ``annotators`` limits the search (default: all; see
    :func:`parameterised_annotators`); ``region``: :func:`region_parameters` of ``box`` when known.
    """
    parameters: dict[str, dict[str, object]] = {}
    if region is None:
        region = region_parameters(box) if box is not None else {}
    free_space_type = kb.annotation_type_for_key(FREE_SPACE_KEY)
    for spec in kb.annotators() if annotators is None else annotators:
        if task is not None and task.footprint is not None and free_space_type in spec.outputs:
            parameters[spec.name] = {"footprint": task.footprint, **region}
            if task.max_results is not None:
                parameters[spec.name]["max_placements"] = task.max_results
        if box is not None and REGION_PRECONDITION in spec.preconditions:
            parameters.setdefault(spec.name, {}).update(region)
        if "Classification" in spec.outputs and ROOT_CLASS in spec.classes:
            profiles = profiles if profiles is not None else class_profiles(kb)
            parameters.setdefault(spec.name, {})["profiles"] = profiles
            if expected is not None:
                parameters[spec.name]["expected"] = expected
    return parameters


def parameterised_annotators(kb: KnowledgeBase) -> tuple[AnnotatorSpec, ...]:
    """The annotators :func:`annotator_parameters` may give arguments to (those needing a region, classifiers by
    knowledge, providers of free placements), sorted by name."""
    free_space_type = kb.annotation_type_for_key(FREE_SPACE_KEY)
    return tuple(
        spec
        for spec in kb.annotators()
        if REGION_PRECONDITION in spec.preconditions
        or ("Classification" in spec.outputs and ROOT_CLASS in spec.classes)
        or free_space_type in spec.outputs
    )


def target_parameters(kb: KnowledgeBase, task: Task) -> dict[str, object]:
    """Constructor arguments telling an object tracker which object to follow: the asked class and its subclasses,
    and the asked attribute values (``{"color": ("blue",)}``), as plain names."""
    classes: tuple[str, ...] = ()
    if task.object_class is not None:
        classes = (task.object_class, *kb.subclasses(task.object_class))
    values: dict[str, list[str]] = {}
    for constraint in task.constraints:
        if constraint.annotation_type == "Classification" or constraint.value is None:
            continue
        attribute = getattr(type_by_name(constraint.annotation_type), "attribute", "")
        if attribute:
            values.setdefault(attribute, []).append(constraint.value)
    return {"target_classes": classes, "target_values": tuple((k, tuple(v)) for k, v in sorted(values.items()))}


POINTING_OUTPUT = "PointingTarget"


def pointing_parameters(kb: KnowledgeBase, target: str) -> dict[str, dict[str, object]]:
    """Constructor arguments of the annotators that say what a person points at: the kind of target and, for
    regions, every region box of the semantic map (plain data)."""
    regions = tuple(region_parameters(box) for box in kb.regions()) if target == "region" else ()
    return {
        spec.name: {"target": target, "regions": regions} for spec in kb.annotators() if POINTING_OUTPUT in spec.outputs
    }


KEYPOINT_OUTPUT = "BodyKeypoints"


def follow_parameters(kb: KnowledgeBase, task: Task) -> dict[str, dict[str, object]]:
    """Constructor arguments of the body keypoint detectors in a continuous task: its tracker follows one target,
    so they follow only that person between frames (``follow_target``) instead of everyone in view."""
    if task.kind not in CONTINUOUS_KINDS:
        return {}
    return {spec.name: {"follow_target": True} for spec in kb.annotators() if KEYPOINT_OUTPUT in spec.outputs}


class QueryPlanner:
    """Plans queries against one knowledge base, keeping what only changes with the ontology (class profiles, the
    annotators that take parameters, the trackers).

    With ``keep_catalogs`` (the default) the requirement-independent work of a plan (providers and fixpoints per
    object class, conditions and sensor types) is kept for later queries; without it every plan starts cold.
    """

    def __init__(self, kb: KnowledgeBase, keep_catalogs: bool = True) -> None:
        self.kb = kb
        self.keep_catalogs = keep_catalogs
        self._index: object | None = None
        self._profiles: tuple[dict[str, object], ...] = ()
        self._parameterised: tuple[AnnotatorSpec, ...] = ()
        self._trackers: tuple[AnnotatorSpec, ...] = ()
        self._text_told: tuple[str, ...] = ()
        self._catalogs: dict[tuple[object, ...], object] = {}
        self._regions: dict[str, tuple[RegionBox, dict[str, object]]] = {}

    def _refresh(self) -> None:
        """Drop what was derived from an older ontology (after the knowledge base reloaded)."""
        if self._index is not self.kb.index:
            self._index = self.kb.index
            self._profiles = class_profiles(self.kb)
            self._parameterised = parameterised_annotators(self.kb)
            self._trackers = tuple(spec for spec in self.kb.annotators() if TRACK_TYPE in spec.outputs)
            self._text_told = text_told_classes(self.kb)
            # the semantic map's region boxes as annotator arguments (a focus box is converted when planned)
            self._regions = {box.name: (box, region_parameters(box)) for box in self.kb.regions()}
            self._catalogs = {}

    def profiles(self) -> tuple[dict[str, object], ...]:
        """The class profiles of the current ontology."""
        self._refresh()
        return self._profiles

    def plan(self, query: Query, source: SensorSource, focus: RegionBox | None = None) -> QueryPlan:
        """Interpret ``query`` and synthesize the plan that answers it from ``source``'s sensor types; ``focus`` is
        the box around the object an ``inspect`` query names by id (:func:`reasoning.planning.focus.object_focus`),
        which then takes the place of a region."""
        depth = bool(source.types & DEPTH_TYPES)
        self._refresh()
        colour = COLOUR_TYPE in source.types
        interpretation = interpret(query, self.kb, depth, source.camera_pose, colour, self._text_told)
        if focus is not None and query.kind == "inspect":
            interpretation = focused(interpretation, focus, depth and source.camera_pose)
        box = interpretation.region_box
        conditions = Conditions(depth=depth, region=box is not None, transparent=interpretation.transparent)
        task = interpretation.task
        region = None
        if box is not None:
            known = self._regions.get(box.name)
            region = known[1] if known is not None and known[0] is box else region_parameters(box)
        parameters = annotator_parameters(
            self.kb, box, self.profiles(), task.object_class, task, self._parameterised, region
        )
        if self._trackers:  # a tracker of any object: told which one to follow
            target = target_parameters(self.kb, task)
            for spec in self._trackers:
                parameters.setdefault(spec.name, {}).update(target)
        if task.pointing is not None:
            parameters.update(pointing_parameters(self.kb, task.pointing))
        for name, arguments in follow_parameters(self.kb, task).items():
            parameters.setdefault(name, {}).update(arguments)
        plan = plan_requirements(
            interpretation.task,
            interpretation.requirements,
            self.kb,
            source,
            conditions=conditions,
            parameters=parameters,
            catalogs=self._catalogs if self.keep_catalogs else None,
        )
        return QueryPlan(plan, interpretation)


def focused(interpretation: Interpretation, focus: RegionBox, applicable: bool) -> Interpretation:
    """An inspection's interpretation narrowed to the box around its object (``applicable``: the input has depth
    and the camera pose, which the region filter needs; else the note says the whole view is searched)."""
    task = interpretation.task
    if not applicable:
        note = f"the input has no depth or camera pose to look only at {focus.label}, so the whole view is searched"
        return replace(interpretation, task=replace(task, inferences=(*task.inferences, note)))
    note = f"only the points {focus.label} are searched: the box where the belief store holds it"
    return replace(interpretation, region_box=focus, task=replace(task, inferences=(*task.inferences, note)))


def plan_query(query: Query, kb: KnowledgeBase, source: SensorSource) -> QueryPlan:
    """Interpret ``query`` and synthesize the plan that answers it (one-off; see QueryPlanner to plan many)."""
    return QueryPlanner(kb).plan(query, source)
