"""Planning latency (query -> Plan), p50 and p99, on the shipped ontology and on generated large ones.

Times are the process's CPU time per plan (``time.process_time``): the machine is shared, and time spent waiting for
a core is not planning; the wall-clock p50 / p99 of the same plans are printed beside them.

Goals (issue 19), with the plan cache cold (every plan builds its providers and fixpoints anew, so the cache is not
what makes it fast): on the large ontology (shipped + 1,000 generated object classes, + 200 generated annotators)
p50 <= 1 ms and p99 <= 10 ms; on the shipped ontology p50 <= 0.6 ms. Beside them, in the same run: the same
queries with the cache warm, and parse -> plan -> tree.

Growth: planning p50 over ontologies from ~100 to ~10,000 object classes (200 generated annotators) and from 20 to
2,000 generated annotators (1,000 generated classes); the slope of log(p50) over log(size) is fitted by least
squares (goal: near-linear, slope <= 1.2) and plotted log-log to ``bench/output/planning_scaling.png``.

The generated ontologies (bench_ontology.generate: random classes and annotators with random ports over the real
CAS types) have no real implementations, so their trees are built with plain port-declaring nodes; the shipped
one instantiates the real annotator classes from the catalog.

    python bench/bench_planning.py [--repeats N] [--no-scaling] [--profile NAME]

``--profile NAME`` writes the top entries of a cProfile of cold planning on the large ontology to
``bench/profiles/planning_NAME.txt`` (and prints them).
"""

from __future__ import annotations

import argparse
import cProfile
import importlib.util
import io
import math
import os
import pstats
import random
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from types import ModuleType

from annotators.catalog import AnnotatorCatalog
from queries import parse_query
from queries.model import Query
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
LARGE_GOAL_P50_MS = 1.0
LARGE_GOAL_P99_MS = 10.0
SHIPPED_GOAL_P50_MS = 0.6
SLOPE_GOAL = 1.2
CLASS_SWEEP = (3, 300, 1_000, 3_000, 10_000)  # generated classes on top of the shipped ~97: ~100 .. ~10,000
ANNOTATOR_SWEEP = (20, 60, 200, 600, 2_000)  # generated annotators (on top of the shipped ones)
OUTPUT = Path(__file__).with_name("output")
PROFILES = Path(__file__).with_name("profiles")


@dataclass(frozen=True)
class Timings:
    """Seconds per planned query (cold and warm plan cache) and per parse -> plan -> tree, and the outcome counts."""

    cold: list[float]
    warm: list[float]
    total: list[float]
    cold_wall: list[float]
    planned: int
    failed: int


def generic_node(step: Step) -> Annotator:
    """A port-declaring node for a generated annotator (which has no implementation)."""
    ports = {"inputs": tuple(map(type_by_name, step.inputs)), "outputs": tuple(map(type_by_name, step.outputs))}
    return type(step.annotator, (Annotator,), ports)()


def p50(samples: list[float]) -> float:
    """The median."""
    return statistics.median(samples)


def p99(samples: list[float]) -> float:
    """The 99th percentile (nearest rank below)."""
    ordered = sorted(samples)
    return ordered[int(0.99 * (len(ordered) - 1))]


def time_plans(
    kb: KnowledgeBase,
    queries: list[Query],
    source: SensorSource,
    repeats: int,
    cold: bool,
    wall: list[float] | None = None,
) -> list[float]:
    """CPU seconds per successful plan of each query, ``repeats`` rounds, query by query (``wall``: gets the
    wall-clock seconds of the same plans)."""
    planner = QueryPlanner(kb, keep_catalogs=not cold)
    planner.profiles()  # derived once per ontology (like the index), not per plan
    samples: list[float] = []
    walls = wall if wall is not None else []
    cpu, clock = time.process_time, time.perf_counter
    for _ in range(repeats):
        for query in queries:
            start, start_wall = cpu(), clock()
            try:
                planner.plan(query, source)
            except PlanningError:
                continue
            walls.append(clock() - start_wall)
            samples.append(cpu() - start)
    return samples


def measure(
    kb: KnowledgeBase, texts: list[str], source: SensorSource | None, repeats: int, make: NodeFactory
) -> Timings:
    """Cold and warm plan-only timings side by side, then parse -> plan -> tree (cold)."""
    chosen = source if source is not None else sensor_source(kb, None)
    queries = [parse_query(text) for text in texts]
    cold: list[float] = []
    warm: list[float] = []
    cold_wall: list[float] = []
    for _ in range(max(1, repeats // 20)):  # alternate the two in blocks so that load changes hit both alike
        cold += time_plans(kb, queries, chosen, 20, cold=True, wall=cold_wall)
        warm += time_plans(kb, queries, chosen, 20, cold=False)
    planner = QueryPlanner(kb, keep_catalogs=False)
    totals: list[float] = []
    planned = failed = 0
    for _ in range(max(1, repeats // 4)):
        for text in texts:
            start = time.process_time()
            try:
                query = parse_query(text)
                result = planner.plan(query, source if source is not None else sensor_source(kb, None))
                build_tree(result.plan, make=make)
                planned += 1
            except PlanningError:
                failed += 1
            totals.append(time.process_time() - start)
    return Timings(cold, warm, totals, cold_wall, planned, failed)


def report(label: str, timings: Timings) -> None:
    """Print p50 / p99 of each measurement."""
    print(f"{label} ({timings.planned} planned, {timings.failed} unsatisfiable per parse -> plan -> tree round)")
    rows = (
        ("plan, cache cold", timings.cold),
        ("plan, cache warm", timings.warm),
        ("plan, cache cold, wall", timings.cold_wall),
        ("parse -> plan -> tree", timings.total),
    )
    for name, samples in rows:
        print(f"  {name:23s} p50 {p50(samples) * 1e3:7.3f} ms   p99 {p99(samples) * 1e3:7.3f} ms   n={len(samples)}")


def goal(text: str, met: bool) -> bool:
    """Print one goal line and return whether it is met."""
    print(f"goal: {text}: {'met' if met else 'NOT met'}")
    return met


def load_generator() -> ModuleType:
    """bench_ontology (beside this file), which generates large ontologies."""
    path = Path(__file__).with_name("bench_ontology.py")
    spec = importlib.util.spec_from_file_location("bench_ontology", path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules["bench_ontology"] = module
    spec.loader.exec_module(module)
    return module


@dataclass(frozen=True)
class Generated:
    """A generated ontology loaded, with its queries and sensor source."""

    kb: KnowledgeBase
    texts: list[str]
    source: SensorSource

    @property
    def size(self) -> tuple[int, int]:
        """Object classes and annotators."""
        return len(self.kb.names_of_kind("class")), len(self.kb.annotators())


def generated(generator: ModuleType, classes: int, annotators: int) -> Generated:
    """Generate and load an ontology with ``classes`` extra object classes and ``annotators`` extra annotators."""
    with tempfile.TemporaryDirectory() as folder:
        files, declarations = generator.generate(Path(folder), random.Random(7), classes, annotators)
        kb = KnowledgeBase.load(
            Path(folder) / "user.ttl", files=files, annotators=generator.annotator_classes(declarations)
        )
    rng = random.Random(3)
    names = [c for c in kb.names_of_kind("class") if c.startswith("GenObject")]
    texts = [f"detect {{ obj: {{ type: {rng.choice(names)}, color: red }} }}" for _ in range(10)]
    texts += [f"find {rng.choice(names)} in the fridge" for _ in range(5)]
    reader = kb.annotator("KitchenSceneReader")
    source = SensorSource(Step(reader.name, reader.implemented_by, (), reader.outputs, (("view", "table"),), "reads"))
    return Generated(kb, texts, source)


def slope(points: list[tuple[float, float]]) -> float:
    """Least-squares slope of log(y) over log(x)."""
    xs = [math.log(x) for x, _ in points]
    ys = [math.log(y) for _, y in points]
    mx, my = statistics.fmean(xs), statistics.fmean(ys)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ys, strict=True)) / sum((x - mx) ** 2 for x in xs)


def sweep(generator: ModuleType, repeats: int) -> dict[str, list[tuple[float, float]]]:
    """Cold plan p50 (seconds) over ontology sizes: by object classes, and by annotators."""
    series: dict[str, list[tuple[float, float]]] = {"object classes": [], "annotators": []}
    configurations = [("object classes", c, 200) for c in CLASS_SWEEP]
    configurations += [("annotators", 1_000, a) for a in ANNOTATOR_SWEEP]
    print(f"\ngrowth: cold plan p50 per ontology size ({repeats} rounds of 15 queries each)")
    print(f"  {'varied':15s} {'classes':>8s} {'annotators':>10s} {'planned':>8s} {'p50 ms':>8s} {'p99 ms':>8s}")
    for varied, classes, annotators in configurations:
        made = generated(generator, classes, annotators)
        samples = time_plans(made.kb, [parse_query(t) for t in made.texts], made.source, repeats, cold=True)
        n_classes, n_annotators = made.size
        if not samples:
            print(f"  {varied:15s} {n_classes:8d} {n_annotators:10d} {0:8d}  (nothing plannable)")
            continue
        print(
            f"  {varied:15s} {n_classes:8d} {n_annotators:10d} {len(samples):8d} "
            f"{p50(samples) * 1e3:8.3f} {p99(samples) * 1e3:8.3f}"
        )
        series[varied].append((n_classes if varied == "object classes" else n_annotators, p50(samples)))
    return series


def plot(series: dict[str, list[tuple[float, float]]], slopes: dict[str, float], path: Path) -> None:
    """Log-log plot of cold plan p50 over ontology size, one line per varied quantity."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(figsize=(6.4, 4.4))
    for varied, points in series.items():
        xs, ys = zip(*points, strict=True)
        axes.loglog(xs, [y * 1e3 for y in ys], "o-", label=f"{varied} (slope {slopes[varied]:.2f})")
    axes.set_xlabel("ontology size (object classes, or annotators)")
    axes.set_ylabel("plan p50, cache cold [ms]")
    axes.set_title("planning time growth (log-log)")
    axes.grid(True, which="both", alpha=0.3)
    axes.legend()
    figure.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=120)
    plt.close(figure)


def profile(kb: KnowledgeBase, texts: list[str], source: SensorSource, name: str, top: int = 25) -> None:
    """cProfile cold planning on ``kb``; print and write the top entries (internal and cumulative time)."""
    queries = [parse_query(t) for t in texts]
    profiler = cProfile.Profile()
    profiler.enable()
    time_plans(kb, queries, source, 10, cold=True)
    profiler.disable()
    text = io.StringIO()
    root = str(Path(__file__).resolve().parents[1]) + os.sep
    for order in ("tottime", "cumulative"):
        stats = pstats.Stats(profiler, stream=text)
        stats.sort_stats(order).print_stats(top)
    lines = [line.replace(root, "") for line in text.getvalue().splitlines() if line.strip()]
    path = PROFILES / f"planning_{name}.txt"
    path.parent.mkdir(parents=True, exist_ok=True)
    heading = f"cold planning on the large ontology, 10 rounds of {len(texts)} queries; top {top} by tottime, cumtime"
    path.write_text("\n".join([heading, *lines]) + "\n", encoding="utf-8")
    print(f"\nprofile written to {path}:")
    print("\n".join(lines[: top + 8]))


def main() -> int:
    """Run the benchmark; print the figures and whether each goal is met."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=100, help="rounds over the queries per measurement")
    parser.add_argument("--no-scaling", action="store_true", help="skip the growth sweep")
    parser.add_argument("--profile", metavar="NAME", help="write bench/profiles/planning_NAME.txt")
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs")
    kb = load_knowledge_base(Path(tempfile.mkdtemp()) / "user.ttl")
    make: NodeFactory = partial(instantiate, catalog=AnnotatorCatalog.discover())
    shipped = measure(kb, QUERIES, None, args.repeats, make)
    report(f"shipped ontology ({len(kb.names_of_kind('class'))} classes, {len(kb.annotators())} annotators)", shipped)
    generator = load_generator()
    large = generated(generator, generator.GENERATED_CLASSES, generator.GENERATED_ANNOTATORS)
    classes, annotators = large.size
    timings = measure(large.kb, large.texts, large.source, args.repeats, generic_node)
    report(f"large generated ontology ({classes} classes, {annotators} annotators)", timings)
    if args.profile:
        profile(large.kb, large.texts, large.source, args.profile)
    results: list[bool] = []
    if not args.no_scaling:
        series = sweep(generator, max(5, args.repeats // 10))
        slopes = {varied: slope(points) for varied, points in series.items()}
        path = OUTPUT / "planning_scaling.png"
        plot(series, slopes, path)
        print(f"log-log plot written to {path}")
        for varied, value in slopes.items():
            tail = f", between the two largest {slope(series[varied][-2:]):.2f}" if len(series[varied]) > 2 else ""
            print(f"fitted slope of log(plan p50) over log({varied}): {value:.2f}{tail}")
        results += [
            goal(f"planning grows near-linearly with {varied} (slope {value:.2f} <= {SLOPE_GOAL})", value <= SLOPE_GOAL)
            for varied, value in slopes.items()
        ]
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    cold_p50, cold_p99 = p50(timings.cold) * 1e3, p99(timings.cold) * 1e3
    shipped_p50 = p50(shipped.cold) * 1e3
    results += [
        goal(
            f"large ontology, cache cold: plan p50 {cold_p50:.3f} ms <= {LARGE_GOAL_P50_MS} ms",
            cold_p50 <= LARGE_GOAL_P50_MS,
        ),
        goal(
            f"large ontology, cache cold: plan p99 {cold_p99:.3f} ms <= {LARGE_GOAL_P99_MS} ms",
            cold_p99 <= LARGE_GOAL_P99_MS,
        ),
        goal(
            f"shipped ontology, cache cold: plan p50 {shipped_p50:.3f} ms <= {SHIPPED_GOAL_P50_MS} ms",
            shipped_p50 <= SHIPPED_GOAL_P50_MS,
        ),
    ]
    print(f"goals {'met' if all(results) else 'NOT met'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
