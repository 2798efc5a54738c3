"""Benchmark of pointing on the built-in kitchen: accuracy over randomised person positions and targets, and ms
per expert.

Each run puts the person at a random place behind the table (x in [-0.45, 0.45] m, y in [0.6, 0.8] m) pointing
at a random target: a table object (asked ``which object is the person pointing at``) or a region of the map
other than the table (asked ``where is the person pointing``). The planned tree answers from the rendered colour
and depth only; the ground truth scores it (an object answer is right when the pointed belief lies nearest to
the target object). Goal (issue 16): pointing right in at least 95 % of the runs.

Run: ``.venv/bin/python bench/bench_pointing.py [--runs N] [--seed S]``
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from annotators.simulation.kitchen_scene import kitchen_objects  # noqa: E402
from robokudo.application.service import AnsweringService, PerceptionFailedError  # noqa: E402
from robokudo.core.annotator import Annotator  # noqa: E402

GOAL = 0.95
TABLE_OBJECTS = ("cereal_box", "red_cup", "bowl")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=30)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    truth = {o.name: o.position for o in kitchen_objects()}
    timings: dict[str, list[float]] = {}
    results: dict[str, list[bool]] = {"object": [], "region": []}
    errors: list[float] = []
    with tempfile.TemporaryDirectory() as folder, AnsweringService.open(Path(folder) / "beliefs.sqlite") as service:
        regions = [r.name for r in service.kb.regions() if r.name != "table"]
        for run in range(args.runs):
            x, y = float(rng.uniform(-0.45, 0.45)), float(rng.uniform(0.6, 0.8))
            kind = "region" if rng.random() < 0.3 else "object"
            target = str(rng.choice(regions if kind == "region" else TABLE_OBJECTS))
            service.person = f"point:{target}@{x:.3f},{y:.3f}"
            text = "where is the person pointing" if kind == "region" else "which object is the person pointing at"
            try:
                outcome = service.answer(text)
            except PerceptionFailedError as error:
                print(f"run {run}: {service.person}: failed ({error})")
                results[kind].append(False)
                continue
            for node in outcome.tree.iterate():
                if isinstance(node, Annotator) and node.stats.count:
                    timings.setdefault(node.name, []).append(node.stats.last_seconds * 1000.0)
            pointing = outcome.answer.pointing
            if kind == "region":
                right = pointing is not None and pointing.region == target
                named = pointing.region if pointing is not None else "nothing"
            else:
                objects = outcome.answer.objects
                named = "nothing"
                if objects:
                    position = np.asarray(objects[0].pose.position)
                    named = min(truth, key=lambda name: float(np.linalg.norm(truth[name] - position)))
                right = named == target
            if pointing is not None:
                errors.append(pointing.angular_error_degrees)
            results[kind].append(right)
            if not right:
                print(f"run {run}: {service.person}: named {named}")
    total = results["object"] + results["region"]
    share = sum(total) / len(total) if total else 0.0
    print(f"\npointing right: {sum(total)}/{len(total)} ({100 * share:.1f} %)", end="")
    for kind, found in results.items():
        print(f"; {kind}s {sum(found)}/{len(found)}", end="")
    if errors:
        print(
            f"\nangle between the arm's ray and the named target: median {statistics.median(errors):.1f}°, "
            f"max {max(errors):.1f}°"
        )
    print("\nms per expert (median, p90 over the runs):")
    for name, values in sorted(timings.items(), key=lambda item: -statistics.median(item[1])):
        p90 = float(np.percentile(values, 90))
        print(f"  {name:28s} {statistics.median(values):8.1f} {p90:8.1f}")
    print(f"\ngoal: pointing right in >= {100 * GOAL:.0f} % of the runs: {'met' if share >= GOAL else 'NOT met'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
