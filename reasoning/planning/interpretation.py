"""Interpret a parsed query against the knowledge base: resolve words, fill gaps, list required types.

``find milk in fridge`` names a class and a region; ``find milk`` names only the class, and the region comes
from the ontology (Milk is stored in the Fridge) as a hint: it is used only when it can be applied (the input
carries the camera pose and the semantic map has such a region), otherwise the whole view is searched and the
inferences say so. ``location: anywhere`` searches the whole view. A region the query names on an input without
a camera pose is a planning error. A class whose variants differ only by printed text needs text reading, and so
does a one-shot query that names no class but asks what the objects are (``find all objects``, ``scan { region:
table }``; not ``find the red thing``) when there is a colour image and the ontology knows classes that only their
printed text or brand tells apart; ``text: false`` skips the reading, ``text: true`` (or ``text: ?``) asks for it.
Each requirement carries the sentence that explains it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from queries.errors import located_error
from queries.model import (
    ANYWHERE,
    CONTINUOUS_KINDS,
    FREE_SPACE_KEY,
    HUMAN_KEY,
    POINTING_KEY,
    TEXT_KEY,
    Asked,
    Block,
    Field,
    ListValue,
    Number,
    Query,
    String,
    Symbol,
    Value,
    text_switch,
)
from reasoning.errors import TermError
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.plan import Constraint, Task
from reasoning.planning.planner import PlanningError, Requirement
from robokudo.core.regions import RegionBox

_RELATIONS = ("in", "inside", "on", "at", "near")
_STRUCTURAL_KEYS = frozenset({"type", "location", "id", "transparent", "confidence"})
_TRUTH = {"true": True, "yes": True, "false": False, "no": False}
_KINDS_WITH_OBJECTS = ("detect", "inspect", "track")
TRACK_TYPE = "TargetTrack"
"""What a continuous query needs in every frame: the estimate of its one target (a tracker's output)."""

DEFAULT_FOOTPRINT = (0.1, 0.1)
"""The footprint (width, depth in metres) a free-space scan looks for when it names neither a class nor a size."""


@dataclass(frozen=True)
class Interpretation:
    """The task, what it requires, the region box it is restricted to (if any) and whether the object asked for
    is transparent (said by the query or by its class)."""

    task: Task
    requirements: tuple[Requirement, ...]
    region_box: RegionBox | None
    transparent: bool = False


def interpret(
    query: Query,
    kb: KnowledgeBase,
    depth: bool = True,
    camera_pose: bool = True,
    colour: bool = True,
    text_told: tuple[str, ...] | None = None,
) -> Interpretation:
    """Resolve the query's words and list the annotation types its answer needs.

    ``depth`` says whether the sensor measures depth; without it objects are reported by their image region
    and no pose is required. ``camera_pose`` says whether the input's frames carry the camera pose, without
    which no region of the semantic map can be applied. ``colour`` says whether the input has a colour image,
    without which a query that names no class reads no text. ``text_told`` are the ontology's
    :func:`text_told_classes` when the caller keeps them per ontology (None: derived here, linear in the classes).
    """
    if query.kind == "stop":
        raise PlanningError("a stop query cancels a running task; there is no perception tree to plan for it")
    if query.kind == "scan":
        return _interpret_scan(query, kb, camera_pose, colour, text_told)
    pointing = query.get(POINTING_KEY)
    if isinstance(pointing, Block):
        return _interpret_pointing(query, pointing, depth, camera_pose, kb)
    obj = _target(query)
    try:
        object_class = _object_class(obj.get("type"), kb)
    except PlanningError as error:
        raise _located(query, obj.field("type"), error) from None
    hypothesis = kb.hypothesis_type(object_class) if object_class is not None else "ObjectHypothesis"
    if hypothesis != "ObjectHypothesis":
        return _interpret_specialised(query, obj, object_class, hypothesis)
    requirements = [
        Requirement("ObjectHypothesis", None, f"{_article(query.kind)} {query.kind} query needs object hypotheses")
    ]
    constraints: list[Constraint] = []
    inferences: list[str] = []
    if depth or isinstance(obj.get("pose"), Asked):
        requirements.append(
            Requirement("Pose", None, f"{_article(query.kind)} {query.kind} query reports each object's pose")
        )
    else:
        inferences.append("the sensor measures no depth, so objects are reported by image region without a pose")
    if object_class is not None:
        constraints.append(Constraint("type", "Classification", object_class))
        requirements.append(Requirement("Classification", object_class, f"query asks type = {object_class}"))
    elif query.kind == "detect" and all(f.key in _STRUCTURAL_KEYS for f in obj.fields) and obj.get("id") is None:
        why = "the query names no class and no property, so it asks what the objects are: they are classified"
        inferences.append(why)
        requirements.append(Requirement("Classification", None, why))
    switch = text_switch(obj.get(TEXT_KEY))
    for field in obj.fields:
        if field.key in _STRUCTURAL_KEYS or (field.key == TEXT_KEY and switch is not None):
            continue
        try:
            annotation_type = _annotation_type(field.key, kb)
            names = [_value_name(annotation_type, value, kb) for value in _values(field.value)]
        except PlanningError as error:
            raise _located(query, field, error) from None
        names = _reportable(annotation_type, names, kb, inferences)
        for name in names:
            constraints.append(Constraint(field.key, annotation_type, name))
            asked = f"query asks {field.key} = {name}" if name is not None else f"query asks for {field.key}"
            domain_value = name if kb.value_kind(annotation_type) is not None else None
            requirements.append(Requirement(annotation_type, domain_value, asked))
    object_id = _whole(obj.get("id"))
    if query.kind == "inspect" and object_id is not None and all(f.key in _STRUCTURAL_KEYS for f in obj.fields):
        requirements += _inspection(object_id, {r.annotation_type for r in requirements}, kb)
    transparent = _transparency(obj.get("transparent"), object_class, kb, inferences)
    min_confidence = _confidence(obj.get("confidence"), inferences)
    if switch is not None:
        requirements += _switched_text(switch, kb, inferences)
    elif object_class is not None and not obj.get(TEXT_KEY) and not _names_no_class(object_class, kb):
        why = _why_text_matters(object_class, kb)
        if why:
            inferences.append(why)
            requirements.append(Requirement("Text", None, why))
    elif query.kind not in CONTINUOUS_KINDS and not obj.get(TEXT_KEY) and _names_objects(requirements):
        requirements += _text_for_any_class(query.kind, kb, colour, text_told, inferences)
    location = obj.get("location")
    try:
        region_box = _region(location, kb, camera_pose, inferences)
    except PlanningError as error:
        raise _located(query, _place_field(obj), error) from None
    if _is_anywhere(location):
        inferences.append("the query says anywhere, so the search covers the whole view")
    elif region_box is None and object_class is not None:
        region_box, note = _default_region(object_class, kb, camera_pose)
        if note:
            inferences.append(note)
    task = Task(
        kind=query.kind,
        object_class=object_class,
        region=region_box.name if region_box else None,
        constraints=tuple(constraints),
        inferences=tuple(inferences),
        max_results=_whole(query.get("max_results")),
        object_id=object_id,
        min_confidence=min_confidence,
    )
    return Interpretation(task, (*requirements, *_tracking(query)), region_box, transparent)


def _inspection(object_id: int, required: set[str], kb: KnowledgeBase) -> list[Requirement]:
    """What inspecting object ``object_id`` refines when the query asks for no attribute in particular (``inspect
    object 3``; ``inspect { obj: { id: 3, color: ? } }`` refines the colour only): every annotation type the
    ontology marks as refined by inspection."""
    return [
        Requirement(t, None, f"inspecting object {object_id} refines its {kb.label(t)}")
        for t in kb.inspected_types()
        if t not in required
    ]


def _interpret_specialised(query: Query, obj: Block, object_class: str, hypothesis: str) -> Interpretation:
    """A class perceived as its own hypothesis type (a person): its detectors state the class and the position,
    so that type is the one requirement; other keys than the structural ones are not answered for it yet."""
    asked = [f.key for f in obj.fields if f.key not in _STRUCTURAL_KEYS or f.key == "transparent"]
    location = obj.get("location")
    if location is not None and not _is_anywhere(location):
        asked.append("location")
    if asked:
        raise PlanningError(
            f"{', '.join(asked)} cannot be asked of a {object_class} yet (its detectors say only "
            f"where it is and its body keypoints)"
        )
    why = (
        f"{object_class} is perceived as {hypothesis}, so {_article(query.kind)} {query.kind} query needs a "
        "provider of it"
    )
    task = Task(
        kind=query.kind,
        object_class=object_class,
        constraints=(Constraint("type", "Classification", object_class),),
        inferences=(f"{object_class} is found by its own detectors ({hypothesis}), not by table-top segmentation",),
        max_results=_whole(query.get("max_results")),
        object_id=_whole(obj.get("id")),
        min_confidence=_confidence(obj.get("confidence"), []),
    )
    return Interpretation(task, (Requirement(hypothesis, None, why), *_tracking(query)), None)


def _tracking(query: Query) -> tuple[Requirement, ...]:
    """The tracker a continuous query needs (none for a one-shot query)."""
    if query.kind not in CONTINUOUS_KINDS:
        return ()
    why = f"{_article(query.kind)} {query.kind} query follows its target from frame to frame"
    return (Requirement(TRACK_TYPE, None, why),)


def _interpret_pointing(
    query: Query, pointing: Block, depth: bool, camera_pose: bool, kb: KnowledgeBase
) -> Interpretation:
    """``detect { pointing: { target: object | region } }``: a person's pointing target, so its body keypoints,
    its activity and the pointing ray are required; an object target needs the frame's object hypotheses (with
    their poses), a region target the semantic map, which needs the camera pose."""
    if query.kind == "track" and any(isinstance(query.get(key), Block) for key in ("human", "obj")):
        return _interpret_track_and_point(query, pointing, kb, depth, camera_pose)
    if query.kind != "detect":
        raise PlanningError(
            f"pointing is detected (detect {{ {POINTING_KEY}: ... }}) or watched while tracking a person "
            f"(track {{ human: {{}}, {POINTING_KEY}: ... }}), not asked by {query.kind}"
        )
    others = [f.key for f in query.body.fields if f.key != POINTING_KEY]
    if others:
        raise PlanningError(f"a pointing query asks only what is pointed at; {', '.join(others)} cannot be added")
    target_value = pointing.get("target")
    target = target_value.name.lower() if isinstance(target_value, Symbol) else "object"
    if not depth:
        raise PlanningError("a pointing ray needs 3-D body keypoints, and the input has no depth")
    requirements = [
        Requirement("PointingTarget", None, f"the query asks which {target} the person points at"),
    ]
    inferences = ["the pointing person is found with body keypoints; the arm's 3-D ray picks the target"]
    if target == "object":
        requirements.append(Requirement("ObjectHypothesis", None, "the objects the person may point at"))
        requirements.append(Requirement("Pose", None, "the answer reports the pointed object's pose"))
    elif not camera_pose:
        raise PlanningError(
            "a region target needs the camera pose to place the semantic map's regions, and this input has none; "
            "ask for target: object instead"
        )
    else:
        inferences.append("the semantic map's regions are the candidate targets")
    task = Task(kind=query.kind, inferences=tuple(inferences), pointing=target)
    return Interpretation(task, tuple(requirements), None)


def _interpret_track_and_point(
    query: Query, pointing: Block, kb: KnowledgeBase, depth: bool, camera_pose: bool
) -> Interpretation:
    """``track { human: {}, pointing: { target: ... } }`` ("track and detect"): follow the person and watch what
    she points at, so the tracking requirements and the pointing requirements together."""
    others = [f.key for f in query.body.fields if f.key not in ("human", "obj", "max_results", POINTING_KEY)]
    if others:
        raise PlanningError(
            f"track and watch pointing asks for a human and pointing; {', '.join(others)} cannot be added"
        )
    human = Query(query.kind, Block(tuple(f for f in query.body.fields if f.key != POINTING_KEY)), query.source)
    tracked = interpret(human, kb, depth, camera_pose)
    if tracked.task.object_class is None or kb.hypothesis_type(tracked.task.object_class) == "ObjectHypothesis":
        raise PlanningError("pointing is watched while tracking a person (track { human: {}, pointing: ... })")
    asked = Query("detect", Block((Field(POINTING_KEY, pointing),)), query.source)
    watched = _interpret_pointing(asked, pointing, depth, camera_pose, kb)
    task = replace(
        tracked.task,
        pointing=watched.task.pointing,
        inferences=(*tracked.task.inferences, *watched.task.inferences),
    )
    return Interpretation(task, (*tracked.requirements, *watched.requirements), tracked.region_box)


def _target(query: Query) -> Block:
    """The block describing what to find: ``obj``, or ``human`` (an object of the class the word human names)."""
    obj, human = query.get("obj"), query.get("human")
    if obj is not None and human is not None:
        raise PlanningError(f"{_article(query.kind)} {query.kind} query names either an obj or a human, not both")
    if isinstance(human, Block):
        if human.get("type") is not None:
            return human
        return Block((Field("type", Symbol(HUMAN_KEY)), *human.fields))
    if not isinstance(obj, Block):
        raise PlanningError(
            f"{_article(query.kind)} {query.kind} query needs an obj block describing the object (or a human block)"
        )
    return obj


def _transparency(value: Value | None, object_class: str | None, kb: KnowledgeBase, inferences: list[str]) -> bool:
    """Whether the query asks for a transparent object (``transparent: true``), noting a clash with the class."""
    if value is None or isinstance(value, Asked):
        return False
    word = _word(value, "transparent").strip().lower()
    if word not in _TRUTH:
        raise PlanningError(f"transparent must be true or false, not {word!r}")
    wanted = _TRUTH[word]
    typical = kb.object_profile(object_class).transparent if object_class is not None else None
    if typical is not None and typical != wanted:
        said = "transparent" if typical else "opaque"
        inferences.append(f"{object_class} is typically {said}, but the query asks for transparent = {word}")
    if wanted:
        inferences.append("the query asks for a transparent object, so experts that need opaque objects are left out")
    return wanted


def _confidence(value: Value | None, inferences: list[str]) -> float:
    """The least confidence an answered object must have (``confidence: 0.75``), 0 when not asked."""
    if value is None or isinstance(value, Asked):
        return 0.0
    if not isinstance(value, Number) or value.unit is not None or not 0.0 <= value.value <= 1.0:
        raise PlanningError("confidence must be a number between 0 and 1")
    inferences.append(f"the answer keeps only objects believed with confidence at least {value.value:g}")
    return value.value


def _why_text_matters(object_class: str, kb: KnowledgeBase) -> str:
    """Why text must be read to recognise ``object_class`` ("" when it need not be).

    Text matters when the class's variants differ only by printed text, when the class is a branded product (the
    brand printed on it is what tells it from other products of its kind), or when another, unrelated class looks
    the same (same colours, shape and size) and the class carries printed text that tells them apart.
    """
    if kb.variants_differ_by_text(object_class):
        return f"{object_class} differs from its sibling classes only by printed text, so text must be read"
    profile = kb.object_profile(object_class)
    if profile.brand:
        return (
            f"{object_class} is sold under the brand {profile.brand!r}; only the brand printed on it tells it from "
            "other products of its kind, so text must be read"
        )
    if not profile.texts:
        return ""
    for other in kb.look_alikes(object_class):
        if not (kb.is_subclass(other, object_class) or kb.is_subclass(object_class, other)):
            texts = ", ".join(repr(t) for t in profile.texts)
            return (
                f"{object_class} looks like {other} (same colour, shape and size); the text printed on it "
                f"({texts}) tells them apart, so text must be read"
            )
    return ""


def _names_no_class(object_class: str, kb: KnowledgeBase) -> bool:
    """Whether ``object_class`` asks for no class in particular: it is the most general one (``find all objects``
    asks for PhysicalObject, which has no superclass)."""
    return not kb.superclasses(object_class)


def _names_objects(requirements: list[Requirement]) -> bool:
    """Whether the answer says what the objects are (a classification is required): only then can text read on
    them name them (``find all objects`` does; ``find the red thing`` asks only for a colour)."""
    return any(r.annotation_type == "Classification" for r in requirements)


def _switched_text(wanted: bool, kb: KnowledgeBase, inferences: list[str]) -> list[Requirement]:
    """The text requirement ``text: true`` asks for (none for ``text: false``), with the inference saying so."""
    if not wanted:
        inferences.append("the query says text: false, so no text is read (faster; brands stay unread)")
        return []
    why = "the query says text: true, so the text printed on the objects is read"
    inferences.append(why)
    return [Requirement(kb.annotation_type_for_key(TEXT_KEY), None, why)]


def text_told_classes(kb: KnowledgeBase) -> tuple[str, ...]:
    """The object classes that only the text or brand printed on them tells from others (see
    :func:`_why_text_matters`), sorted."""
    return tuple(c for c in kb.names_of_kind("class") if _why_text_matters(c, kb))


def _text_for_any_class(
    kind: str, kb: KnowledgeBase, colour: bool, text_told: tuple[str, ...] | None, inferences: list[str]
) -> list[Requirement]:
    """The text requirement of a one-shot query that names no class: any object may be one of the classes only
    printed text tells apart, so the whole frame is read once (when there is a colour image to read)."""
    if not colour:
        return []
    told = text_told_classes(kb) if text_told is None else text_told
    if not told:
        return []
    shown = ", ".join(told[:3]) + (f" and {len(told) - 3} more" if len(told) > 3 else "")
    why = (
        f"{_article(kind)} {kind} query that names no class may meet any class, and {len(told)} classes ({shown}) "
        "only the text or brand printed on them tells apart, so the text is read once on the whole frame "
        "(text: false skips it)"
    )
    inferences.append(why)
    return [Requirement(kb.annotation_type_for_key(TEXT_KEY), None, why)]


def _article(word: str) -> str:
    """The indefinite article for ``word`` ("an inspect query", "a detect query")."""
    return "an" if word[:1].lower() in "aeiou" else "a"


def _interpret_scan(
    query: Query, kb: KnowledgeBase, camera_pose: bool, colour: bool, text_told: tuple[str, ...] | None
) -> Interpretation:
    """A scan lists the objects on a region's supporting surface; asked for free space (``free_space: {...}``, or
    ``for: free_space``) it also finds where a footprint fits."""
    block = query.get(FREE_SPACE_KEY)
    wanted = query.get("for")
    free_space = isinstance(block, Block) or any(
        isinstance(v, Symbol | String) and _word(v, "for").lower() == FREE_SPACE_KEY for v in _values(wanted or Block())
    )
    inner = block if isinstance(block, Block) else Block()
    try:
        region_box = _region(inner.get("region") or query.get("region"), kb, camera_pose)
    except PlanningError as error:
        raise _located(query, inner.field("region") or query.body.field("region"), error) from None
    requirements = [
        Requirement("Plane", None, "a scan needs the supporting surface"),
        Requirement("ObjectHypothesis", None, "a scan needs the objects occupying the surface"),
    ]
    if not free_space:
        inferences: list[str] = []
        switch = text_switch(query.get(TEXT_KEY))
        if switch is not None:
            requirements += _switched_text(switch, kb, inferences)
        else:
            requirements += _text_for_any_class("scan", kb, colour, text_told, inferences)
        task = Task(kind="scan", region=region_box.name if region_box else None, inferences=tuple(inferences))
        return Interpretation(task, tuple(requirements), region_box)
    footprint, why = _footprint(inner, kb)
    requirements.append(Requirement(kb.annotation_type_for_key(FREE_SPACE_KEY), None, why))
    task = Task(
        kind="scan",
        object_class=None,
        region=region_box.name if region_box else None,
        inferences=(why,),
        max_results=_whole(query.get("max_results")),
        footprint=footprint,
    )
    return Interpretation(task, tuple(requirements), region_box)


def _footprint(block: Block, kb: KnowledgeBase) -> tuple[tuple[float, float], str]:
    """The footprint a free-space block asks room for (given, else its class's size bound, else the default), and
    the sentence saying where it came from."""
    given = block.get("footprint")
    if given is not None:
        lengths = [v.value for v in _values(given) if isinstance(v, Number)]
        width, depth = (lengths[0], lengths[-1]) if lengths else DEFAULT_FOOTPRINT
        return (width, depth), f"the query asks room for a {width:g} m x {depth:g} m footprint"
    target = block.get("for")
    object_class = _object_class(target, kb)
    if object_class is None:
        width, depth = DEFAULT_FOOTPRINT
        return (
            DEFAULT_FOOTPRINT,
            f"the query names no object or footprint, so room for {width:g} m x {depth:g} m is asked",
        )
    bound = kb.largest_extent(object_class)
    if bound is None:
        size_class = kb.object_profile(object_class).size_class
        said = f"its size class {size_class} has no upper bound" if size_class else "it has no size class"
        raise PlanningError(
            f"the ontology gives no size for {object_class} ({said}); give its footprint: "
            f"scan {{ free_space: {{ for: {object_class}, footprint: [30cm, 20cm] }} }}"
        )
    size_class = kb.object_profile(object_class).size_class
    return (bound, bound), (
        f"{object_class} is {size_class} (largest extent below {bound:g} m), so room for a {bound:g} m square is asked"
    )


def _located(query: Query, field: Field | None, error: PlanningError) -> PlanningError:
    """``error`` told where ``field`` was said in the query (line, column and the source line with a caret), so
    a wrong word deep in a nested query is found at once; unchanged for a query without source positions."""
    if field is None or field.span.line <= 0 or not query.source:
        return error
    return PlanningError(str(located_error(query.source, str(error), field.span.line, field.span.column)))


def _place_field(obj: Block) -> Field | None:
    """The field that names the place: the relation inside ``location: { in: fridge }``, else ``location``."""
    location = obj.field("location")
    if location is not None and isinstance(location.value, Block):
        return next((f for f in location.value.fields if f.key in _RELATIONS), location)
    return location


def _word(value: Value, what: str) -> str:
    if isinstance(value, Symbol):
        return value.name
    if isinstance(value, String):
        return value.text
    raise PlanningError(f"{what} must be a word, got {type(value).__name__}")


def _object_class(value: Value | None, kb: KnowledgeBase) -> str | None:
    if value is None or isinstance(value, Asked):
        return None
    word = _word(value, "type")
    try:
        return kb.resolve(word, ("class",)).name
    except TermError as error:
        raise PlanningError(str(error)) from None


def _annotation_type(key: str, kb: KnowledgeBase) -> str:
    try:
        return kb.annotation_type_for_key(key)
    except TermError as error:
        raise PlanningError(f"the query key {key!r} is not answered by any annotation type: {error}") from None


def _values(value: Value) -> list[Value]:
    return list(value.items) if isinstance(value, ListValue) else [value]


def _value_name(annotation_type: str, value: Value, kb: KnowledgeBase) -> str | None:
    """The ontology name of a requested value (of the type's value kind: colour, shape, ...), the text, or None
    when asked."""
    if isinstance(value, Asked):
        return None
    kind = kb.value_kind(annotation_type)
    if isinstance(value, Number):
        return f"{value.value:g}{value.unit or ''}"
    word = _word(value, annotation_type)
    if kind is None:
        return word
    try:
        return kb.resolve(word, (kind,)).name
    except TermError as error:
        raise PlanningError(str(error)) from None


def _reportable(
    annotation_type: str, names: list[str | None], kb: KnowledgeBase, inferences: list[str]
) -> list[str | None]:
    """The asked values with each colour no expert reports replaced by the basic colours a person names it by
    (:meth:`~reasoning.knowledge.knowledge_base.KnowledgeBase.reported_as`: ``teal`` -> blue or green, the colour
    namer says only basic terms), noted in ``inferences``; other values as they are (a value nothing reports and
    that has no basic colours is refused by the planner, saying why)."""
    found: list[str | None] = []
    for name in names:
        reported = (name,) if name is None else kb.reported_as(annotation_type, name)
        if reported != (name,):
            said = " or ".join(kb.label(value) for value in reported)
            inferences.append(
                f"no expert reports the colour {kb.label(name)!r}; it is asked as {said}, the basic colours a person "
                f"names it by"
            )
        found.extend(reported)
    return list(dict.fromkeys(found))


def _is_anywhere(value: Value | None) -> bool:
    return isinstance(value, Symbol | String) and _word(value, "location").strip().lower() == ANYWHERE


def _region(
    value: Value | None, kb: KnowledgeBase, camera_pose: bool, inferences: list[str] | None = None
) -> RegionBox | None:
    """The region box the query names (None for none or anywhere); PlanningError when it cannot be applied.

    Without a camera pose a region cannot be placed in the view; but what stands *on* a supporting surface (the
    table, the counter, the floor) is what the segmentation finds on the support plane it fits, so with
    ``inferences`` given such a place is read as that plane (None, and a note saying so)."""
    box = _named_region(value, kb)
    if box is not None and not camera_pose and inferences is not None and _on_a_surface(value, box, kb):
        inferences.append(
            f"the input gives no camera pose to place {box.name!r} in the semantic map, so the surface the objects "
            f"stand on (the support plane found in the view) is taken for it"
        )
        return None
    if box is not None and not camera_pose:
        raise PlanningError(
            f"region {box.name!r} cannot be searched: the input gives no camera pose, so its points cannot be placed "
            f"in the semantic map; leave the place out (or say 'anywhere', location: anywhere) to search the whole "
            f"view, or use an input with a camera pose (the built-in kitchen)"
        )
    return box


def _on_a_surface(value: Value | None, box: RegionBox, kb: KnowledgeBase) -> bool:
    """Whether the query asks for what stands on ``box`` (``location: { on: table }``) and it is a supporting
    surface."""
    if not isinstance(value, Block) or value.get("on") is None:
        return False
    try:
        return kb.is_subclass(box.region_class, "SupportingRegion")
    except LookupError:
        return False


def _named_region(value: Value | None, kb: KnowledgeBase) -> RegionBox | None:
    if value is None or isinstance(value, Asked) or _is_anywhere(value):
        return None
    if isinstance(value, Block):
        places = [value.get(relation) for relation in _RELATIONS if value.get(relation) is not None]
        if not places:
            raise PlanningError(f"location must say where: one of {', '.join(_RELATIONS)}")
        value = places[0]
    word = _word(value, "location")
    try:
        found = kb.resolve(word, ("region", "region_class"))
    except TermError as error:
        raise PlanningError(_not_a_place(word, kb) or str(error)) from None
    if found.kind == "region":
        return kb.region(found.name)
    boxes = kb.regions_of_class(found.name)
    if not boxes:
        raise PlanningError(f"the semantic map has no region of class {found.name}")
    return boxes[0]


def _not_a_place(word: str, kb: KnowledgeBase) -> str | None:
    """Why an object class named as the place cannot be searched (``the can in the bowl``), None when ``word``
    names no object class (then it is an unknown word)."""
    try:
        found = kb.resolve(word, ("class",))
    except TermError:
        return None
    return (
        f"{word!r} is an object, not a place ({kb.label(found.name)}): a query searches a region of the semantic map "
        f"(the fridge, the table) and cannot place one object relative to another; leave the place out, ask for "
        f"both objects and compare their positions"
    )


def _default_region(object_class: str, kb: KnowledgeBase, camera_pose: bool) -> tuple[RegionBox | None, str]:
    """Where the class is typically stored, as a hint: the region box when it can be applied, and why (not)."""
    stored_in = kb.default_location(object_class)
    if stored_in is None:
        return None, ""
    boxes = kb.regions_of_class(stored_in)
    if not boxes:
        return None, (
            f"{object_class} is typically stored in a {stored_in}, but the semantic map has none, "
            f"so the search covers the whole view"
        )
    box = boxes[0]
    if not camera_pose:
        return None, (
            f"{object_class} is typically stored in the {stored_in} (region {box.name!r}), but the input gives no "
            f"camera pose to place it, so the search covers the whole view"
        )
    return box, f"{object_class} is typically stored in the {stored_in}, so the search covers region {box.name!r}"


def _whole(value: Value | None) -> int | None:
    return int(value.value) if isinstance(value, Number) else None
