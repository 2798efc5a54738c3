"""The Python of a frame without its SQL (issue 19, goal 1): an experiment, not a benchmark.

It seeds 10,000 beliefs as ``bench_beliefs.py`` does, integrates bench frames (random places, then fixed views) and
captures what ``BeliefStore._step_on_rows`` was given on each (the candidate rows, the observations, the time). Then
it times, on the captured frames, the association alone (``tracker.associate`` on the store's candidate views) and
the whole step on the rows (association, row-level updates, new rows; no SQL), as the minimum of ``--repeats`` passes,
in CPU microseconds per frame. Run it in two trees and compare the figures of one run each, alternating.

Run: ``PYTHONPATH=. .venv/bin/python bench/experiments/frame_python.py [--frames N] [--repeats N]``
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(BENCH))

import bench_beliefs as bench  # noqa: E402

from reasoning.beliefs import store as store_module  # noqa: E402
from reasoning.beliefs.store import BeliefStore  # noqa: E402
from reasoning.fusion.frame import FrameObject, frame_objects  # noqa: E402
from reasoning.fusion.tracking import BeliefTracker  # noqa: E402

Captured = tuple[list[tuple], list[FrameObject], float]


def captured_frames(store: BeliefStore, frames: list[list[FrameObject]]) -> list[Captured]:
    """Integrate ``frames`` and return what each step on the rows was given."""
    captured: list[Captured] = []
    step = store._step_on_rows

    def remember(conn, tracker, rows, objects, at, new_id, camera):  # type: ignore[no-untyped-def]
        captured.append((list(rows), list(objects), at))
        return step(conn, tracker, rows, objects, at, new_id, camera)

    store._step_on_rows = remember  # type: ignore[method-assign]
    try:
        for index, frame in enumerate(frames):
            store.integrate(frame, 1000.0 + index * 0.5)
    finally:
        del store._step_on_rows
    return captured


def seeded_frames(path: Path, count: int) -> list[list[FrameObject]]:
    """Seed a 10,000-belief store at ``path`` and make ``count`` frames of 20: half at random places, half from
    10 fixed camera views (as ``bench_beliefs.py`` does)."""
    seeded = bench.seed_file(path, 10_000, np.random.default_rng(5), named_regions=False)
    rng = np.random.default_rng(7)
    views = bench.fixed_views(seeded, rng, 10, 20)
    half = count // 2
    frames = [frame_objects(bench.hypotheses_near(seeded, rng, 20)) for _ in range(half)]
    frames += [frame_objects(bench.hypotheses_near(seeded, rng, 20, views[k % 10])) for k in range(half)]
    return frames


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=150)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as name:
        path = Path(name) / "seed.sqlite"
        frames = seeded_frames(path, args.frames)
        tracker = BeliefTracker(class_test=bench.is_subclass)
        store = BeliefStore(path, tracker=tracker)
        captured = captured_frames(store, frames)
        update = store._row_update(tracker)
        conn = store._conn
        counter = iter(range(10**9, 2 * 10**9))
        association_us, step_us = [], []
        for _ in range(args.repeats):
            start = time.process_time_ns()
            for rows, objects, _ in captured:
                tracker.associate(objects, [store_module._Candidate(row, update) for row in rows])
            association_us.append((time.process_time_ns() - start) / 1000 / len(captured))
            start = time.process_time_ns()
            for rows, objects, at in captured:
                store._step_on_rows(conn, tracker, rows, objects, at, counter.__next__, None)
            step_us.append((time.process_time_ns() - start) / 1000 / len(captured))
        store.close()
    print(f"frames {len(captured)}, candidates per frame {np.mean([len(c[0]) for c in captured]):.1f}")
    print(f"association (candidate views + associate): min {min(association_us):.1f} us per frame")
    print(f"step on rows (association, row updates, new rows): min {min(step_us):.1f} us per frame")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
