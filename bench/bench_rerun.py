"""Cost of recording with Rerun (``--rerun``): per logged frame, beside the perception that produced it, and on the
engine thread of a server (what ``robokudo serve --rerun`` adds to each tick).

For a real RealSense frame (uoc) and the built-in kitchen, the tabletop tree analyses the frame once; then rounds
alternate between running that tree again and logging its CAS (colour, depth, cloud, 2-D and 3-D boxes) into a
``.rrd`` file, so machine noise hits both alike. The served part ticks a served-shaped root (perception, then the
task slot) with the recorder in background mode: the engine thread's cost per tick with an idle slot (status
signature only) and on a tick whose task run finished (the frame is handed to the worker thread).

Run: ``.venv/bin/python bench/bench_rerun.py [--rounds N]``
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

from py_trees.common import Status

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from robokudo.application.rerun_log import RerunLog, TickRecorder  # noqa: E402
from robokudo.core.composites import Sequence  # noqa: E402
from robokudo.core.engine import Engine  # noqa: E402
from robokudo.core.pipeline import Pipeline  # noqa: E402
from robokudo.core.slot import Idle, TaskSlot  # noqa: E402
from robokudo.core.types import ObjectHypothesis  # noqa: E402
from trees import load_tree  # noqa: E402

UOC = ROOT.parent / "shared" / "data" / "uoc_tabletop_realsense"


def analysed(input_path: str | None) -> Pipeline:
    """The tabletop tree after one run on the input (its CAS holds the frame and the hypotheses)."""
    root = load_tree("tabletop").create(input_path=input_path, frame=0)
    Engine(root, hz=1000).run(until=lambda status: status is not Status.RUNNING)
    return root


def per_frame(label: str, input_path: str | None, rounds: int, folder: Path) -> None:
    root = analysed(input_path)
    path = folder / f"{label}.rrd"
    perceive, record = [], []
    with RerunLog(path) as log:
        for tick in range(rounds):
            start = time.perf_counter()
            again = analysed(input_path)
            perceive.append(time.perf_counter() - start)
            start = time.perf_counter()
            log.log_frame(again.cas, tick)
            record.append(time.perf_counter() - start)
    hypotheses = len(root.cas.annotations(ObjectHypothesis))
    perceive_ms, record_ms = statistics.median(perceive) * 1e3, statistics.median(record) * 1e3
    print(
        f"{label:9s} {hypotheses:2d} hypotheses   log_frame {record_ms:6.1f} ms   tabletop tree {perceive_ms:7.1f} ms"
        f"   ratio {record_ms / perceive_ms:5.2f}   file {path.stat().st_size / rounds / 1e6:4.2f} MB/frame"
    )


def served_tick(rounds: int, folder: Path) -> None:
    """Engine-thread cost of the background recorder per tick: idle slot, and a tick whose task run finished."""
    tasks = [analysed(None), analysed(None)]  # alternated: a run is recorded once, the next one is new
    slot = TaskSlot("task")
    slot.set_subtree(Idle())
    perception = Pipeline("perception", [Idle("read frame")])
    root = Sequence("robot", [perception, slot])
    root.tick_once()
    log = RerunLog(folder / "served.rrd")
    recorder = TickRecorder(log, task_of=lambda _: slot.subtree, tick_of=lambda: 0, background=True)
    idle, finished = [], []
    for round_number in range(rounds):
        start = time.perf_counter()
        for _ in range(100):
            recorder.record(root)
        idle.append((time.perf_counter() - start) / 100)
        slot.set_subtree(tasks[round_number % 2])  # a finished run
        start = time.perf_counter()
        recorder.record(root)
        finished.append(time.perf_counter() - start)
        slot.set_subtree(Idle())
    start = time.perf_counter()
    recorder.close()
    drained = time.perf_counter() - start
    print(
        f"served    engine thread per tick: idle {statistics.median(idle) * 1e6:6.1f} µs   "
        f"finished run {statistics.median(finished) * 1e3:5.2f} ms (tree text + hand-off)   "
        f"worker drained {rounds} frames in {drained:4.1f} s after the last tick"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=10)
    args = parser.parse_args()
    print(f"Rerun recording cost, median of {args.rounds} alternating rounds")
    with tempfile.TemporaryDirectory() as folder:
        if UOC.is_dir():
            per_frame("uoc", str(UOC), args.rounds, Path(folder))
        per_frame("kitchen", None, args.rounds, Path(folder))
        served_tick(args.rounds, Path(folder))


if __name__ == "__main__":
    main()
