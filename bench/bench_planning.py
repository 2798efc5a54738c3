"""Planning latency (parse -> plan -> tree), median and p99, on the shipped ontology and on a generated one.

The generated ontology (from bench_ontology.generate: ~1,000 extra object classes, ~200 generated annotator
classes with random ports over the real CAS types) has no real implementations, so its trees are built with plain
port-declaring nodes; the shipped one instantiates the real annotator classes from the catalog.
"""

from __future__ import annotations

import importlib.util
import random
import statistics
import sys
import tempfile
import time
from functools import partial
from pathlib import Path
from types import ModuleType

from annotators.catalog import AnnotatorCatalog
from queries import parse_query
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.plan import Step
from reasoning.planning.planner import PlanningError, SensorSource
from reasoning.planning.query_planner import QueryPlanner
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.sensor_sources import sensor_source
from robokudo.core.annotator import Annotator
from robokudo.core.types import type_by_name
from trees.synthesis import NodeFactory, build_tree, instantiate

QUERIES = [
    "detect { obj: { color: red } }",
    "find the red thing on the table",
    "detect { obj: { color: [yellow, blue] } }",
    "detect { obj: { color: white, location: { in: fridge } } }",
    "find milk in fridge",
    "find the cereal box",
    "is there a lactose free milk in the fridge",
    "detect { obj: { shape: cylinder } }",
    "detect { obj: { type: Cup, color: red, size: small } }",
    "track the blue bowl",
]
REPEATS = 200


def generic_node(step: Step) -> Annotator:
    ports = {"inputs": tuple(map(type_by_name, step.inputs)), "outputs": tuple(map(type_by_name, step.outputs))}
    return type(step.annotator, (Annotator,), ports)()


def measure(label: str, kb: KnowledgeBase, texts: list[str], source: SensorSource | None, generic: bool) -> None:
    """Median and p99 of parse -> plan -> tree, and of the plan step alone."""
    totals: list[float] = []
    plans: list[float] = []
    planned = failed = 0
    planner = QueryPlanner(kb)
    make: NodeFactory = generic_node if generic else partial(instantiate, catalog=AnnotatorCatalog.discover())
    for _ in range(REPEATS):
        for text in texts:
            start = time.perf_counter()
            try:
                query = parse_query(text)
                chosen = source if source is not None else sensor_source(kb, None)
                before_plan = time.perf_counter()
                result = planner.plan(query, chosen)
                plans.append(time.perf_counter() - before_plan)
                build_tree(result.plan, make=make)
                planned += 1
            except PlanningError:
                failed += 1
            totals.append(time.perf_counter() - start)
    print(f"{label} ({planned} planned, {failed} unsatisfiable)")
    for name, samples in (("parse -> plan -> tree", totals), ("plan only", plans)):
        samples.sort()
        p99 = samples[int(0.99 * (len(samples) - 1))]
        print(f"  {name:22s} median {statistics.median(samples) * 1e3:7.3f} ms   p99 {p99 * 1e3:7.3f} ms")


def load_generator() -> ModuleType:
    path = Path(__file__).with_name("bench_ontology.py")
    spec = importlib.util.spec_from_file_location("bench_ontology", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_ontology"] = module
    spec.loader.exec_module(module)
    return module


def main() -> None:
    kb = load_knowledge_base(Path(tempfile.mkdtemp()) / "user.ttl")
    shipped = [q for q in QUERIES]
    measure("shipped ontology, real annotators", kb, shipped, None, generic=False)
    generator = load_generator()
    with tempfile.TemporaryDirectory() as folder:
        files, declarations = generator.generate(Path(folder), random.Random(7))
        classes = generator.annotator_classes(declarations)
        big = KnowledgeBase.load(Path(folder) / "user.ttl", files=files, annotators=classes)
        print(f"generated ontology: {len(big.names_of_kind('class'))} classes, {len(big.annotators())} annotators")
        rng = random.Random(3)
        classes = [c for c in big.names_of_kind("class") if c.startswith("GenObject")]
        texts = [f"detect {{ obj: {{ type: {rng.choice(classes)}, color: red }} }}" for _ in range(10)]
        texts += [f"find {rng.choice(classes)} in the fridge" for _ in range(5)]
        reader = big.annotator("KitchenSceneReader")
        source = SensorSource(
            Step(reader.name, reader.implemented_by, (), reader.outputs, (("view", "table"),), "reads")
        )
        measure("generated ontology, generic nodes", big, texts, source, generic=True)


if __name__ == "__main__":
    main()
