"""Plans on a large generated ontology (bench_ontology: random annotators over the real CAS types, whose type
hierarchy the small random capability ontologies lack) build trees whose data flow is valid.

A refiner of a by-product (an annotator reading and writing a supertype of what some unit makes) once read a type
whose unit had moved into one branch of a Fallback: the tree read it where only that branch makes it. Without depth
and camera pose, two track queries once planned an alternative reading PersonTrack after its unit had been re-chosen
(the type was pinned to a unit that was then committed to another provider): no unit made it outside one branch.
"""

from __future__ import annotations

import importlib.util
import random
import sys
from pathlib import Path
from types import ModuleType

import pytest

from queries import parse_query
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.plan import Step
from reasoning.planning.planner import PlanningError, SensorSource
from reasoning.planning.query_planner import QueryPlanner
from robokudo.core.annotator import Annotator
from robokudo.core.types import type_by_name
from tests.planning.plan_digests import sources
from trees.synthesis import build_tree

BENCH = Path(__file__).resolve().parents[2] / "bench"


def generator() -> ModuleType:
    """bench/bench_ontology.py, which generates large ontologies."""
    spec = importlib.util.spec_from_file_location("bench_ontology", BENCH / "bench_ontology.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_ontology"] = module
    spec.loader.exec_module(module)
    return module


def load_generated(folder: Path, seed: int, classes: int, annotators: int) -> KnowledgeBase:
    """A generated ontology with ``classes`` extra object classes and ``annotators`` extra annotators."""
    module = generator()
    files, declarations = module.generate(folder, random.Random(seed), classes, annotators)
    return KnowledgeBase.load(folder / "user.ttl", files=files, annotators=module.annotator_classes(declarations))


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    return load_generated(tmp_path_factory.mktemp("generated"), 7, 1000, 200)


def node(step: Step) -> Annotator:
    """A port-declaring node for a generated annotator (which has no implementation)."""
    ports = {"inputs": tuple(map(type_by_name, step.inputs)), "outputs": tuple(map(type_by_name, step.outputs))}
    return type(step.annotator, (Annotator,), ports)()


def test_plans_on_a_generated_ontology_have_valid_data_flow(kb: KnowledgeBase) -> None:
    rng = random.Random(3)
    names = [c for c in kb.names_of_kind("class") if c.startswith("GenObject")]
    texts = [f"detect {{ obj: {{ type: {rng.choice(names)}, color: red }} }}" for _ in range(10)]
    texts += [f"find {rng.choice(names)} in the fridge" for _ in range(5)]
    texts += [
        f"{verb} {{ obj: {{ type: {rng.choice(names)}, color: red }} }}"
        for verb in ("track", "inspect")
        for _ in range(10)
    ]
    assert "detect { obj: { type: GenObject0133, color: red } }" in texts  # the query whose plan was invalid
    assert "track { obj: { type: GenObject0239, color: red } }" in texts  # invalid without depth and pose
    assert planned_validly(kb, texts) >= len(texts)


def test_plans_on_a_smaller_generated_ontology_have_valid_data_flow(tmp_path: Path) -> None:
    # 20 of its plans were invalid: an alternative read a type whose unit had been re-chosen, or the greedy choice of
    # all alternatives made a plan whose units depend on each other in a cycle
    small = load_generated(tmp_path, 9, 300, 60)
    rng = random.Random(3)
    names = [c for c in small.names_of_kind("class") if c.startswith("GenObject")]
    texts = [
        f"{verb} {{ obj: {{ type: {rng.choice(names)}, color: {rng.choice(['red', 'blue'])} }} }}"
        for verb in ("detect", "track", "inspect")
        for _ in range(15)
    ]
    texts += [f"find {rng.choice(names)} in the fridge" for _ in range(10)]
    assert planned_validly(small, texts) >= len(texts)


def planned_validly(kb: KnowledgeBase, texts: list[str]) -> int:
    """Plan every text from the kitchen reader (table view, as it is, without depth and pose), build each plan's tree
    (whose data-flow validator raises on a violation) and return how many planned."""
    reader = kb.annotator("KitchenSceneReader")
    chosen = SensorSource(Step(reader.name, reader.implemented_by, (), reader.outputs, (("view", "table"),), "reads"))
    planner = QueryPlanner(kb)
    planned = 0
    for source in (chosen, *sources(kb).values()):
        for text in texts:
            try:
                result = planner.plan(parse_query(text), source)
            except PlanningError:
                continue
            build_tree(result.plan, make=node)
            planned += 1
    return planned
