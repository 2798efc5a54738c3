"""The automatic PPT synthesis tests: queries -> expected experts, order constraints and tree structure."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import py_trees
import pytest

from queries import parse_query
from reasoning.beliefs.store import BeliefStore
from reasoning.knowledge.editing import OntologyEditor
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.interpretation import interpret, text_told_classes
from reasoning.planning.plan import Alternatives, Plan, Step
from reasoning.planning.planner import PlanningError, SensorSource
from reasoning.planning.query_planner import plan_query
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.sensor_sources import sensor_source
from robokudo.application.service import AnsweringService
from robokudo.core.dataflow import validate_data_flow
from robokudo.core.parallel import ThresholdParallel
from robokudo.core.render import unicode_tree
from trees.synthesis import build_tree


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    return load_knowledge_base(tmp_path_factory.mktemp("kb") / "user.ttl")


@dataclass(frozen=True)
class Case:
    """A query and what its tree must (not) contain; ``before`` pairs must run in that order."""

    query: str
    contains: frozenset[str] = frozenset()
    excludes: frozenset[str] = frozenset()
    before: tuple[tuple[str, str], ...] = ()
    fallback_for: tuple[str, ...] = ()
    side_by_side: tuple[frozenset[str], ...] = ()
    source: str = "kitchen"
    inference: str = ""
    region: str | None = None
    marks: tuple = field(default=())


def case(query: str, contains: str = "", excludes: str = "", **options: object) -> Case:
    return Case(query, frozenset(contains.split()), frozenset(excludes.split()), **options)  # type: ignore[arg-type]


CORE = "PointCloudGenerator RangeFilter SupportPlaneSegmenter ClusterExtractor PoseAnnotator"
CLASSIFY = "KnowledgeClassifier SemanticColorAnnotator ShapeAnnotator SizeAnnotator"

CASES = [
    case(
        "find milk in fridge",
        f"{CORE} RegionFilter {CLASSIFY} TextReader",
        before=(("RegionFilter", "SupportPlaneSegmenter"), ("TextReader", "KnowledgeClassifier")),
        region="fridge",
    ),
    case("find milk", "RegionFilter KnowledgeClassifier", inference="stored in the Fridge", region="fridge"),
    case("detect { obj: { type: Milk, location: Fridge } }", "RegionFilter KnowledgeClassifier TextReader"),
    case(
        "is there a lactose free milk in the fridge",
        "TextReader KnowledgeClassifier RegionFilter",
        inference="printed text",
    ),
    case('detect { obj: { type: Milk, text: "lactose free" } }', "TextReader KnowledgeClassifier"),
    case(
        "detect { obj: { shape: cylinder } }",
        "NormalEstimator ShapeAnnotator",
        "KnowledgeClassifier RegionFilter TextReader SemanticColorAnnotator",
        before=(("NormalEstimator", "ShapeAnnotator"), ("ClusterExtractor", "ShapeAnnotator")),
    ),
    case(
        "detect { obj: { color: red } }",
        f"{CORE} SemanticColorAnnotator",
        "ShapeAnnotator NormalEstimator KnowledgeClassifier TextReader RegionFilter",
        side_by_side=(frozenset({"SemanticColorAnnotator", "PoseAnnotator"}),),
    ),
    case("find the red cup on the table", f"RegionFilter {CLASSIFY}", region="table"),
    case("track the blue cup", CLASSIFY, "RegionFilter"),
    case("where is the cereal box?", "KnowledgeClassifier", "RegionFilter", inference="Cupboard"),
    case(
        "inspect { obj: { id: 12, pose: ?, color: ? } }", "PoseAnnotator SemanticColorAnnotator", "KnowledgeClassifier"
    ),
    case("detect { obj: { size: small } }", "SizeAnnotator", "ShapeAnnotator KnowledgeClassifier"),
    case("detect { obj: { type: Bowl } }", CLASSIFY),
    case("detect { obj: { color: [white, blue] } }", "SemanticColorAnnotator"),
    case("scan { region: table, for: free_space }", "RegionFilter SupportPlaneSegmenter ClusterExtractor"),
    case(
        "detect { obj: { type: Cup, color: red, size: small, location: { on: Table } } }",
        f"RegionFilter {CLASSIFY}",
    ),
    case("find a glass", "ImageRegionSegmenter", "ClusterExtractor", inference=""),
    case(
        "detect { obj: { color: red } }",
        "ImageRegionSegmenter SemanticColorAnnotator",
        "PointCloudGenerator PoseAnnotator ClusterExtractor",
        source="rgb",
        inference="no depth",
    ),
    case(
        "detect { obj: { color: red } }", "SemanticColorAnnotator ClusterExtractor", "PointCloudGenerator", source="pcd"
    ),
    case(
        "find the red thing",
        "SemanticColorAnnotator ClusterExtractor ImageRegionSegmenter",
        fallback_for=("ObjectHypothesis",),
    ),
    case("detect { obj: { type: Milk, color: white, shape: box } }", f"{CLASSIFY} NormalEstimator"),
    case("find cups", "KnowledgeClassifier"),
    case("track { obj: { type: Cup, color: blue } }", "KnowledgeClassifier SemanticColorAnnotator"),
    case(
        "look for free space on the table",
        "RegionFilter SupportPlaneSegmenter",
        "KnowledgeClassifier SemanticColorAnnotator",
    ),
    case('{"detect": {"obj": {"type": "milk", "location": "fridge"}}}', "RegionFilter KnowledgeClassifier TextReader"),
    case("find the toffifee", "TextReader KnowledgeClassifier", inference="brand 'Toffifee'"),
    case("find the cheez-it box", "TextReader KnowledgeClassifier", inference="brand 'Cheez-It'"),
    case("find the sweets", "KnowledgeClassifier", "TextReader"),
    # a one-shot query that asks what the objects are, naming no class, reads the text that alone names some
    case("find all objects", "TextReader KnowledgeClassifier", inference="only the text or brand printed on them"),
    case("inspect object 3", "TextReader KnowledgeClassifier", inference="only the text or brand printed on them"),
    case("scan { region: table }", "TextReader", "KnowledgeClassifier", inference="names no class", region="table"),
    case("track { obj: { type: object } }", "KnowledgeClassifier", "TextReader"),
    case("detect { obj: { type: object, text: false } }", "KnowledgeClassifier", "TextReader", inference="text: false"),
    case("scan { region: table, text: false }", "", "TextReader", inference="text: false", region="table"),
    case('{"detect": {"obj": {"type": "object", "text": false}}}', "KnowledgeClassifier", "TextReader"),  # JSON false
    case("detect { obj: { type: CheezIt, text: false } }", "KnowledgeClassifier", "TextReader"),
    case("detect { obj: { color: red, text: true } }", "TextReader SemanticColorAnnotator", "KnowledgeClassifier"),
]

FAILURES = [
    ("detect { obj: { color: silver } }", "SemanticColor with value 'Silver'.*SemanticColorAnnotator can report only"),
    ("stop { task: 7 }", "cancels a running task"),
    ("find the flux capacitor", "unknown object class 'flux_capacitor'"),
    ("detect { obj: { flavour: sweet } }", "query key 'flavour'"),
    ("scan { region: CounterTop, for: free_space }", "no region of class CounterTop"),
]


def source_for(kind: str, kb: KnowledgeBase, region: str | None) -> SensorSource:
    if kind == "kitchen":
        return sensor_source(kb, None, region=region)
    reader = kb.annotator("PcdReader" if kind == "pcd" else "TumPairReader")
    outputs = reader.outputs if kind == "pcd" else ("ColorImage", "CameraInfo")
    return SensorSource(Step(reader.name, reader.implemented_by, (), outputs, reason="test source"))


def order(plan: Plan) -> list[str]:
    return [step.annotator for step in plan.steps()]


@pytest.mark.parametrize("expected", CASES, ids=[f"{c.source}: {c.query}" for c in CASES])
def test_synthesized_tree(expected: Case, kb: KnowledgeBase) -> None:
    query = parse_query(expected.query)
    result = plan_query(query, kb, source_for(expected.source, kb, expected.region))
    names = set(order(result.plan))
    assert expected.contains <= names, f"missing {expected.contains - names}"
    assert not expected.excludes & names, f"unexpected {expected.excludes & names}"
    sequence = order(result.plan)
    for first, second in expected.before:
        assert sequence.index(first) < sequence.index(second), (first, second, sequence)
    alternatives = [u for u in result.plan.units() if isinstance(u, Alternatives)]
    for provided in expected.fallback_for:
        assert provided in {a.provides for a in alternatives}, f"no Fallback for {provided}"
    if expected.inference:
        assert any(expected.inference in note for note in result.interpretation.task.inferences)
    if expected.region:
        assert result.interpretation.task.region == expected.region
    if expected.source != "kitchen":
        return  # the test sources have no reader implementation to build
    tree = build_tree(result.plan, query=query)
    validate_data_flow(tree)
    for group in expected.side_by_side:
        parallels = [n for n in tree.iterate() if isinstance(n, ThresholdParallel)]
        assert any(group <= {c.name for c in p.children} for p in parallels), f"{group} not in one Parallel"
    for node in tree.iterate():
        assert getattr(node, "reason", ""), f"{node.name} has no reason"
    again = build_tree(plan_query(query, kb, source_for(expected.source, kb, expected.region)).plan, query=query)
    assert unicode_tree(again) == unicode_tree(tree)  # deterministic


def test_fallback_branches_are_in_rank_order_with_their_own_steps(kb: KnowledgeBase) -> None:
    result = plan_query(parse_query("find the red thing"), kb, sensor_source(kb, None))
    (segmenters,) = [u for u in result.plan.units() if isinstance(u, Alternatives)]
    providers = [branch[-1].annotator for branch in segmenters.branches]
    assert providers == ["ClutterSegmenter", "ClusterExtractor", "ImageRegionSegmenter"]  # reliability first
    # the plane only the depth segmenters need (size and shape read it if there is one) is in each of their
    # branches: when it is not found, the next branch (in the end the image segmenter) still runs
    depth_branches = [[s.annotator for s in branch] for branch in segmenters.branches[:2]]
    assert depth_branches == [
        ["SupportPlaneSegmenter", "ClutterSegmenter"],
        ["SupportPlaneSegmenter", "ClusterExtractor"],
    ]
    assert [s.annotator for s in segmenters.branches[2]] == ["ImageRegionSegmenter"]
    assert not any(
        getattr(u, "annotator", "") == "SupportPlaneSegmenter" for stage in result.plan.stages for u in stage
    )
    tree = build_tree(result.plan)
    fallback = next(n for n in tree.iterate() if isinstance(n, py_trees.composites.Selector))
    assert "ObjectHypothesis" in fallback.name and "rank order" in fallback.reason


@pytest.mark.parametrize(("query", "message"), FAILURES)
def test_unplannable_queries_fail_with_a_clear_reason(query: str, message: str, kb: KnowledgeBase) -> None:
    with pytest.raises(PlanningError, match=message):
        plan_query(parse_query(query), kb, sensor_source(kb, None))


def test_explanations_name_the_query_and_the_producers(kb: KnowledgeBase) -> None:
    result = plan_query(parse_query("detect { obj: { color: red } }"), kb, sensor_source(kb, None))
    color = next(s for s in result.plan.steps() if s.annotator == "SemanticColorAnnotator")
    assert "query asks color = Red" in color.reason
    assert "needs ColorImage from KitchenSceneReader" in color.reason and "ObjectHypothesis from" in color.reason


def test_a_new_object_class_plans_and_runs_at_once(tmp_path: Path) -> None:
    kb = load_knowledge_base(tmp_path / "user.ttl")
    with pytest.raises(PlanningError, match="unknown object class 'picnic_cup'"):
        plan_query(parse_query("find the picnic cup"), kb, sensor_source(kb, None))
    editor = OntologyEditor(kb, user_file=tmp_path / "user.ttl", use_reasoner=False)
    editor.add_object("PicnicCup", ["Cup"], colors=["red"], shape="cylinder", size="small")
    result = plan_query(parse_query("find the picnic cup"), kb, sensor_source(kb, None))
    assert "KnowledgeClassifier" in order(result.plan)
    with AnsweringService(kb, BeliefStore(tmp_path / "beliefs.sqlite")) as service:
        answer = service.answer("find the picnic cup").answer
    assert answer.objects, "the new class was not found in the kitchen"
    assert answer.objects[0].class_iri.endswith("PicnicCup")


def test_a_query_naming_no_class_reads_text_only_with_a_colour_image_and_text_told_classes(kb: KnowledgeBase) -> None:
    """The text is read for ``find all objects`` because the ontology holds classes only their printed text or
    brand tells apart, and there is a colour image to read it on; without either, no text is read."""
    query = parse_query("find all objects")
    assert text_told_classes(kb) and {"CheezIt", "CampbellsTomatoSoup"} <= set(text_told_classes(kb))
    texts = [r for r in interpret(query, kb).requirements if r.annotation_type == "Text"]
    assert len(texts) == 1 and "only the text or brand printed on them" in texts[0].reason
    assert not [r for r in interpret(query, kb, colour=False).requirements if r.annotation_type == "Text"]
    assert not [r for r in interpret(query, _no_text_told(kb)).requirements if r.annotation_type == "Text"]


def _no_text_told(kb: KnowledgeBase) -> KnowledgeBase:
    """A stand-in knowledge base in which no class is told apart by text (every other answer is ``kb``'s)."""

    class Plain:
        def __getattr__(self, name: str) -> object:
            return getattr(kb, name)

        def variants_differ_by_text(self, name: str) -> bool:
            return False

        def object_profile(self, name: str) -> object:
            return replace(kb.object_profile(name), brand=None, texts=())

    return Plain()  # type: ignore[return-value]
