"""Benchmark of the belief store: update throughput and query latency with 10,000 stored objects.

Goals: >= 5,000 hypotheses/s integrated (association + fusion + one transaction per frame) and <= 1 ms median
latency of a memory query ("milk in fridge": class subsumption + region) with 10,000 objects stored.

Run: ``.venv/bin/python bench/bench_beliefs.py [--objects N] [--frames N] [--per-frame N]``
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from reasoning.beliefs.answer import answer_from_memory  # noqa: E402
from reasoning.beliefs.store import BeliefFilter, BeliefStore  # noqa: E402
from reasoning.fusion.frame import FrameContext, FrameObject, frame_objects  # noqa: E402
from reasoning.fusion.rule import AttributeBelief, ValueSupport  # noqa: E402
from reasoning.fusion.tracking import BeliefTracker, ObjectBelief  # noqa: E402
from robokudo.core.types import Classification, ObjectHypothesis, Pose, SemanticColor, Shape, Size  # noqa: E402

CLASSES = [f"Thing{i}" for i in range(40)] + ["Milk", "LactoseFreeMilk", "WholeMilk", "Cup", "Bowl", "CerealBox"]
PARENT = {"LactoseFreeMilk": "Milk", "WholeMilk": "Milk"}
COLORS = ["red", "green", "blue", "white", "yellow", "black"]
SHAPES = ["box", "cylinder", "sphere", "flat"]
REGIONS = [f"room{i}" for i in range(20)]
WORLD = 100.0  # objects spread over a WORLD x WORLD metre area


def is_subclass(a: str, b: str) -> bool:
    """The benchmark's tiny class tree."""
    return a == b or PARENT.get(a) == b


@dataclass(frozen=True)
class Box:
    """A region box for the region-containment query."""

    name: str
    region_class: str
    pose: np.ndarray
    size: tuple[float, float, float]


@dataclass(frozen=True)
class Seeded:
    """What was stored: positions, classes and colours of the objects."""

    positions: np.ndarray
    classes: list[str]
    colors: list[str]


def seed_store(store: BeliefStore, count: int, rng: np.random.Generator) -> Seeded:
    """Put ``count`` beliefs (written in batches of 1,000)."""
    positions = np.column_stack([rng.uniform(0, WORLD, count), rng.uniform(0, WORLD, count), np.full(count, 0.8)])
    classes = [CLASSES[int(rng.integers(len(CLASSES)))] for _ in range(count)]
    colors = [COLORS[int(rng.integers(len(COLORS)))] for _ in range(count)]
    batch: list[ObjectBelief] = []
    for i in range(count):
        cls, color = classes[i], colors[i]
        shape = SHAPES[i % len(SHAPES)]
        attributes = {
            "class": AttributeBelief("class", {cls: ValueSupport(1.4, 1, {"Detector"}, 0.0, 0.0)}),
            "color": AttributeBelief("color", {color: ValueSupport(0.8, 1, {"ColorExpert"}, 0.0, 0.0)}),
            "shape": AttributeBelief("shape", {shape: ValueSupport(0.8, 1, {"ShapeExpert"}, 0.0, 0.0)}),
            "size": AttributeBelief("size", {"medium": ValueSupport(0.8, 1, {"SizeExpert"}, 0.0, 0.0)}),
        }
        batch.append(
            ObjectBelief(
                id=i + 1,
                frame="world",
                position=positions[i],
                dimensions=np.array([0.2, 0.1, 0.07]),
                attributes=attributes,
                existence=1.4,
                region=REGIONS[int(positions[i, 0] // (WORLD / len(REGIONS)))],
                class_name=cls,
                sources={"Segmenter", "PoseExpert", "SizeExpert", "ColorExpert", "ShapeExpert", "Detector"},
                observations=1,
            )
        )
        if len(batch) == 1000:
            store.put(batch, is_subclass)
            batch = []
    if batch:
        store.put(batch, is_subclass)
    return Seeded(positions, classes, colors)


def hypotheses_near(seeded: Seeded, rng: np.random.Generator, per_frame: int) -> list[ObjectHypothesis]:
    """One frame around a random place: re-observations of stored objects (1 cm noise) and two new objects.

    Every hypothesis carries a pose, a size, a colour, a shape and a class, like the output of a tabletop tree.
    """
    positions = seeded.positions
    centre = positions[int(rng.integers(len(positions)))]
    near = np.flatnonzero(np.linalg.norm(positions[:, :2] - centre[:2], axis=1) < 4.0)
    chosen = [int(i) for i in rng.choice(near, size=min(len(near), per_frame - 2), replace=False)]
    seen = [
        (positions[i] + rng.normal(0, 0.01, 3), seeded.classes[i], seeded.colors[i], SHAPES[i % len(SHAPES)])
        for i in chosen
    ]
    while len(seen) < per_frame:
        place = centre + np.array([rng.uniform(-3, 3), rng.uniform(-3, 3), 0.0])
        cls, color = CLASSES[int(rng.integers(len(CLASSES)))], COLORS[int(rng.integers(len(COLORS)))]
        seen.append((place, cls, color, SHAPES[int(rng.integers(len(SHAPES)))]))
    hypotheses = []
    for k, (place, cls, color, shape) in enumerate(seen):
        h = ObjectHypothesis(point_indices=np.array([k]), mask=np.zeros((1, 1), bool), roi=(k, 0, k + 1, 1))
        h.source = "Segmenter"
        h.annotations += [
            Pose(position=place, orientation=np.array([0.0, 0.0, 0.0, 1.0]), frame="world", source="PoseExpert"),
            Size(dimensions=(0.2, 0.1, 0.07), size_class="medium", source="SizeExpert"),
            SemanticColor(color=color, confidence=0.8, source="ColorExpert"),
            Shape(shape=shape, confidence=0.7, source="ShapeExpert"),
            Classification(class_name=cls, confidence=0.6, source="Detector"),
        ]
        hypotheses.append(h)
    return hypotheses


def bench_updates(store: BeliefStore, seeded: Seeded, frames: int, per_frame: int) -> dict[str, float]:
    """Hypotheses per second: (a) store.integrate of fused frame objects, (b) from ObjectHypothesis end to end."""
    rng = np.random.default_rng(1)
    store.integrate(frame_objects(hypotheses_near(seeded, rng, per_frame)), 999.0)  # warm-up: lazy imports
    prepared = [hypotheses_near(seeded, rng, per_frame) for _ in range(frames)]
    t_fuse = 0.0
    t_integrate = 0.0
    count = created = 0
    for index, hypotheses in enumerate(prepared):
        start = time.perf_counter()
        objects: list[FrameObject] = frame_objects(hypotheses, FrameContext(time=float(index)))
        middle = time.perf_counter()
        step = store.integrate(objects, 1000.0 + index)
        end = time.perf_counter()
        t_fuse += middle - start
        t_integrate += end - middle
        count += len(hypotheses)
        created += len(step.created)
    return {
        "hypotheses": count,
        "created": created,
        "integrate_per_s": count / t_integrate,
        "end_to_end_per_s": count / (t_fuse + t_integrate),
    }


def bench_queries(store: BeliefStore, repeats: int) -> dict[str, float]:
    """Median and 95th percentile latency (ms) of memory queries."""
    fridge_pose = np.eye(4)
    fridge_pose[:3, 3] = (25.0, 50.0, 0.8)
    fridge = Box("fridge", "FridgeInterior", fridge_pose, (10.0, 10.0, 2.0))
    queries = {
        "milk in fridge (class subsumption + region box)": BeliefFilter(
            object_class="Milk", class_test=is_subclass, region="fridge", region_boxes=(fridge,)
        ),
        "milk in room3 (class subsumption + region name)": BeliefFilter(
            object_class="Milk", class_test=is_subclass, region="room3"
        ),
        "red cup (class + attribute)": BeliefFilter(
            object_class="Cup", class_test=is_subclass, attributes={"color": "red"}, region="room7"
        ),
    }
    results: dict[str, float] = {}
    for label, belief_filter in queries.items():
        for use_answer in (False, True):
            samples = []
            for _ in range(repeats):
                start = time.perf_counter()
                if use_answer:
                    found = len(answer_from_memory(store, belief_filter).objects)
                else:
                    found = len(store.query(belief_filter))
                samples.append((time.perf_counter() - start) * 1000.0)
            key = f"{label}{' -> designators' if use_answer else ''}"
            results[key + " median ms"] = statistics.median(samples)
            results[key + " p95 ms"] = float(np.percentile(samples, 95))
            results[key + " results"] = found
    return results


def main() -> int:
    """Run the benchmark and print its figures (update trials on fresh stores; the median trial is the figure)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", type=int, default=10_000)
    parser.add_argument("--frames", type=int, default=300)
    parser.add_argument("--per-frame", type=int, default=20)
    parser.add_argument("--repeats", type=int, default=1000)
    parser.add_argument("--trials", type=int, default=3)
    args = parser.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs")
    trials: list[dict[str, float]] = []
    queries: dict[str, float] = {}
    for trial in range(args.trials):
        with tempfile.TemporaryDirectory() as folder:
            store = BeliefStore(Path(folder) / "beliefs.sqlite", tracker=BeliefTracker(class_test=is_subclass))
            start = time.perf_counter()
            seeded = seed_store(store, args.objects, np.random.default_rng(trial))
            seeding = time.perf_counter() - start
            if trial == 0:
                print(f"seeded {store.count()} objects in {seeding:.2f} s")
                queries = bench_queries(store, args.repeats)
            trials.append(bench_updates(store, seeded, args.frames, args.per_frame))
            store.close()
    integrate = sorted(t["integrate_per_s"] for t in trials)
    end_to_end = sorted(t["end_to_end_per_s"] for t in trials)
    middle = len(trials) // 2
    print(
        f"updates ({args.trials} trials of {args.frames} frames x {args.per_frame} hypotheses, {args.objects} stored):"
    )
    print(
        f"  store.integrate        {integrate[middle]:8.0f} hypotheses/s median "
        f"(best {integrate[-1]:.0f}, worst {integrate[0]:.0f})   goal >= 5000"
    )
    print(f"  fusion + integrate     {end_to_end[middle]:8.0f} hypotheses/s median (best {end_to_end[-1]:.0f})")
    print(f"  new objects            {trials[0]['created']:8.0f} of {trials[0]['hypotheses']:.0f} hypotheses")
    print(f"queries ({args.repeats} runs each, {args.objects} objects stored):")
    for key, value in queries.items():
        print(f"  {key:75s} {value:8.3f}" if not key.endswith("results") else f"  {key:75s} {value:8.0f}")
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    ok = integrate[middle] >= 5000 and all(
        v <= 1.0 for k, v in queries.items() if k.endswith("median ms") and "designators" not in k
    )
    print("goals met" if ok else "goals NOT met")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
