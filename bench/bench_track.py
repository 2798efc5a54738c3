"""Benchmark of a continuous ``track the person`` goal with pose detection in the loop.

The real five_people.pcd frame (../shared/data/pcl_people) is played as a live source at 30 frames/s (looped),
so the served engine's track loop runs the planned tree - PerceivedFrameReader, point cloud, range filter, the
people detectors' Fallback (HumanPoseDetector first), HumanTracker, answer step - on every new frame. Printed: the
runs per second of the loop (answers per second), per-expert milliseconds (median, p90 over the runs) and whether
the goal of the issue, >= 15 Hz with pose detection in the loop, is met. A second run side by side forces the
depth-only people detector (the pose model's precondition unmet: no colour), for the ratio.

Run: ``.venv/bin/python bench/bench_track.py [--seconds S]``
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from annotators.readers.streams import stream_for  # noqa: E402
from robokudo.application.service import AnsweringService  # noqa: E402
from robokudo.core.annotator import Annotator  # noqa: E402

FRAME = ROOT.parent / "shared" / "data" / "pcl_people" / "five_people.pcd"
GOAL_HZ = 15.0


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def run(query: str, seconds: float) -> tuple[float, dict[str, tuple[float, float, int]], int]:
    """Answers per second after a warm-up, per-expert (median ms, p90 ms, runs) and how many answers saw the person."""
    with tempfile.TemporaryDirectory() as folder:
        stream = stream_for(str(FRAME), 30.0, loop=True)
        with AnsweringService.open(Path(folder) / "b.sqlite", hz=60, stream=stream, lost_after=30.0) as service:
            handle = service.start(query)
            for _ in range(3):  # warm-up: model loading, first frames
                if handle.next_answer(timeout=120) is None:
                    raise SystemExit(f"no answer: {handle.reason}")
            durations: dict[str, list[float]] = {}
            nodes = [n for n in handle.tree.iterate() if isinstance(n, Annotator)]
            counts = {n.name: n.stats.count for n in nodes}
            answers = seen = 0
            start = time.perf_counter()
            while time.perf_counter() - start < seconds:
                answer = handle.next_answer(timeout=10)
                if answer is None:
                    break
                answers += 1
                seen += bool(answer.track and answer.track.seen)
                for node in nodes:
                    if node.stats.count > counts[node.name]:
                        counts[node.name] = node.stats.count
                        durations.setdefault(node.name, []).append(node.stats.last_seconds * 1e3)
            elapsed = time.perf_counter() - start
            handle.cancel()
    table = {
        name: (statistics.median(values), percentile(values, 0.9), len(values)) for name, values in durations.items()
    }
    return answers / elapsed, table, seen


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0)
    args = parser.parse_args()
    if not FRAME.exists():
        raise SystemExit(f"missing {FRAME}")
    print(f"goal: a track loop with pose detection runs at >= {GOAL_HZ:g} Hz (frames of 640x480, 30 frames/s)")
    results = {}
    for label, query in (("pose in the loop", "track the person"),):
        rate, table, seen = run(query, args.seconds)
        results[label] = rate
        print(f"\n{label}: {rate:.1f} runs/s, the person seen in {seen} answers")
        print(f"  {'expert':28s} {'median ms':>10s} {'p90 ms':>10s} {'runs':>6s}")
        for name, (median, p90, count) in sorted(table.items(), key=lambda item: -item[1][0]):
            print(f"  {name:28s} {median:10.2f} {p90:10.2f} {count:6d}")
    rate = results["pose in the loop"]
    print(f"\ngoal {'met' if rate >= GOAL_HZ else 'NOT met'}: {rate:.1f} Hz with pose detection (goal {GOAL_HZ:g} Hz)")


if __name__ == "__main__":
    main()
