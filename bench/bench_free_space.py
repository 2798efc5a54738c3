"""Free-space estimation on randomized storage layouts of the built-in kitchen (the fridge's upper shelf).

Goal: free-space precision 100 % (every reported placement is free in the scene's geometry, the issue's
"free space 100 %"), reported beside how much of the truly free room for the footprint the placements cover
(hidden room behind objects cannot be seen, so coverage stays below 100 %), and the ms per run of the whole
planned tree and of the FreeSpaceEstimator alone, measured in one run side by side.

    python bench/bench_free_space.py [--runs 30] [--seed 0] [--query "where can I put the cup in the fridge"]
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from annotators.simulation.kitchen_scene import FRIDGE_SHELF_HEIGHTS
from annotators.simulation.storage import (
    StorageLayout,
    covers,
    footprint_in_view,
    on_shelf,
    random_layout,
    rectangle_samples,
)
from queries import parse_query
from reasoning.beliefs.store import BeliefStore
from reasoning.planning.plan import Step
from reasoning.planning.planner import SensorSource
from reasoning.planning.query_planner import QueryPlanner
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.sensor_sources import sensor_source
from robokudo.core.engine import Engine
from robokudo.core.geometry import rotation_matrix
from robokudo.core.types import QueryAnswer
from trees.answer_step import AnswerStep
from trees.synthesis import build_tree


def true_free_spots(layout: StorageLayout, footprint: tuple[float, float], box: object) -> list[np.ndarray]:
    """Centres (1 cm apart, world axes) where the footprint lies on the shelf inside the region and touches nothing."""
    low = np.asarray(box.position[:2]) - np.asarray(box.size[:2]) / 2  # type: ignore[attr-defined]
    high = np.asarray(box.position[:2]) + np.asarray(box.size[:2]) / 2  # type: ignore[attr-defined]
    half = np.asarray(footprint) / 2
    xs = np.arange(low[0] + half[0], high[0] - half[0] + 1e-9, 0.01)
    ys = np.arange(low[1] + half[1], high[1] - half[1] + 1e-9, 0.01)
    centres = np.array([[x, y, FRIDGE_SHELF_HEIGHTS[0]] for x in xs for y in ys])
    offsets = rectangle_samples(np.zeros(3), np.eye(3), footprint, 0.005)
    samples = (centres[:, None, :] + offsets[None, :, :]).reshape(-1, 3)
    blocked = ~on_shelf(samples)
    for obj in layout.occupants():
        blocked |= covers(obj, samples)
    free = ~blocked.reshape(len(centres), -1).any(axis=1)
    return list(centres[free])


def covered(spot: np.ndarray, footprint: tuple[float, float], placements: list[tuple]) -> bool:
    """True when the footprint at ``spot`` lies inside one reported placement rectangle."""
    samples = rectangle_samples(spot, np.eye(3), footprint, 0.01)
    for centre, rotation, size in placements:
        local = (samples - centre) @ rotation
        if np.all(np.abs(local[:, 0]) <= size[0] / 2 + 1e-6) and np.all(np.abs(local[:, 1]) <= size[1] / 2 + 1e-6):
            return True
    return False


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=30)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--query", default="where can I put the cup in the fridge")
    args = parser.parse_args()
    folder = Path(tempfile.mkdtemp())
    kb = load_knowledge_base(folder / "user.ttl")
    planner = QueryPlanner(kb)
    query = parse_query(args.query)
    base = sensor_source(kb, None, region="fridge").step
    reported = correct = spots_total = spots_covered = seen_total = seen_covered = 0
    tree_ms: list[float] = []
    expert_ms: list[float] = []
    for run in range(args.runs):
        layout = random_layout(args.seed + run)
        parameters = (*base.parameters, ("extra", layout.extra()), ("seed", args.seed + run))
        step = Step(base.annotator, base.implemented_by, base.inputs, base.outputs, parameters, base.reason)
        plan = planner.plan(query, SensorSource(step, camera_pose=True)).plan
        footprint = plan.task.footprint or (0.1, 0.1)
        with BeliefStore(folder / f"beliefs{run}.sqlite") as store:
            tree = build_tree(plan, final_steps=[AnswerStep(store, free_space=True)], query=query)
            engine = Engine(tree)
            started = time.perf_counter()
            engine.run(until=lambda status: status.name in ("SUCCESS", "FAILURE"))
            tree_ms.append((time.perf_counter() - started) * 1e3)
            stats = engine.annotator_stats()
            expert_ms.extend(s.last_seconds * 1e3 for name, s in stats.items() if name.startswith("FreeSpaceEstimator"))
            found = tree.cas.view(QueryAnswer)
            scene = next(n for n in tree.iterate() if n.name == base.annotator).last_scene
        placements = list(found.answer.placements or ()) if found is not None else []
        rectangles = [(np.array(p.pose.position), rotation_matrix(p.pose.orientation), p.size) for p in placements]
        reported += len(rectangles)
        correct += sum(layout.is_free(c, r, s) for c, r, s in rectangles)
        spots = true_free_spots(layout, footprint, kb.region("fridge"))
        spots_total += len(spots)
        hits = [covered(s, footprint, rectangles) for s in spots]
        spots_covered += sum(hits)
        seen = [footprint_in_view(s, footprint, scene) for s in spots]
        seen_total += sum(seen)
        seen_covered += sum(h for h, v in zip(hits, seen, strict=True) if v)
    precision = correct / reported if reported else 1.0
    print(
        f"goal: free-space precision 100 % on {args.runs} random layouts"
        f" (seeds {args.seed}..{args.seed + args.runs - 1})"
    )
    print(f"placements reported {reported}, free in the scene's geometry {correct}: precision {100 * precision:.1f} %")
    print(
        f"truly free footprint positions covered by a placement: {spots_covered}/{spots_total}"
        f" ({100 * spots_covered / max(1, spots_total):.1f} %; hidden room behind objects is not seen)"
    )
    print(
        f"ms per run: whole tree median {statistics.median(tree_ms):.0f} (p90 {np.percentile(tree_ms, 90):.0f}),"
        f" FreeSpaceEstimator median {statistics.median(expert_ms):.1f} (p90 {np.percentile(expert_ms, 90):.1f})"
    )
    print(
        f"of those the camera sees entirely: {seen_covered}/{seen_total}"
        f" ({100 * seen_covered / max(1, seen_total):.1f} %; placements are disjoint rectangles, largest first)"
    )
    print(f"goal met: {'yes' if precision == 1.0 else 'no'}")


if __name__ == "__main__":
    main()
