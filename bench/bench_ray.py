"""Beyond one machine, on a local Ray cluster of 2 CPUs started here, measured side by side in one run.

1. ``robokudo eval segmentation`` on the 45 shared mOSD learn scenes: in this process vs ``--workers 2`` (Ray
   tasks), alternating rounds; the figures must be identical. Goal: >= 1.7x faster with 2 workers, on a running
   cluster with warm workers (the cluster's start and the first round's worker imports are printed apart).
2. Per-call overhead of a remote expert: the colour expert on the kitchen scene's hypotheses, run locally and on
   a Ray actor, alternating; the overhead is the median remote call (inputs gathered and sent, the actor's run,
   the writes committed) minus the median local run. Goal: <= 2 ms.

Run: ``PYTHONPATH=. .venv/bin/python bench/bench_ray.py``. CPU time of this process is printed beside wall time
(other jobs on a shared machine sway wall time).
"""

from __future__ import annotations

import copy
import logging
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import ClassVar, TypeVar

import ray
from py_trees.common import Status

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from annotators.image.color import SemanticColorAnnotator  # noqa: E402
from robokudo.application.commands.eval import scene_files, score_scene  # noqa: E402
from robokudo.application.parallel import map_on_cluster, run_in_order  # noqa: E402
from robokudo.core.annotator import Annotator  # noqa: E402
from robokudo.core.engine import Engine  # noqa: E402
from robokudo.core.pipeline import Pipeline, pipelines  # noqa: E402
from robokudo.core.remote import place_remote  # noqa: E402
from robokudo.core.types import CasType, ColorImage, ObjectHypothesis  # noqa: E402
from trees import tabletop  # noqa: E402

LEARN = (ROOT.parent / "shared" / "data" / "pcl_mosd_tabletop" / "learn").resolve()
ROUNDS = 2
CALLS = 60
SPEEDUP_GOAL = 1.7
OVERHEAD_GOAL_MS = 2.0
T = TypeVar("T")


def verdict(met: bool) -> str:
    return "met" if met else "NOT met"


def timed(work: Callable[[], T]) -> tuple[T, float, float]:
    wall, cpu = time.perf_counter(), time.process_time()
    result = work()
    return result, time.perf_counter() - wall, time.process_time() - cpu


def figures(results: list) -> list:
    return [(r.scene, r.category, r.score) for r in results]


def bench_eval() -> None:
    files = scene_files([str(LEARN)])
    print(f"1. eval segmentation, {len(files)} scenes (clutter segmenter)")
    score_scene(files[0], "clutter")  # this process's imports and caches warm, as the workers' after round 1
    sequential, parallel = [], []
    reference = None
    for round_number in range(1, ROUNDS + 2):
        seq, seq_wall, seq_cpu = timed(lambda: run_in_order(score_scene, files, "clutter"))
        par, par_wall, par_cpu = timed(lambda: map_on_cluster(score_scene, files, "clutter", workers=2))
        reference = reference or figures(seq)
        assert figures(seq) == reference and figures(par) == reference, "the figures differ"
        note = " (workers start cold: imports)" if round_number == 1 else ""
        print(
            f"   round {round_number}: sequential {seq_wall:6.2f} s (cpu {seq_cpu:5.2f} s)   "
            f"--workers 2 {par_wall:6.2f} s (this process' cpu {par_cpu:5.2f} s){note}"
        )
        if round_number > 1:
            sequential.append(seq_wall)
            parallel.append(par_wall)
    speedup = statistics.median(sequential) / statistics.median(parallel)
    print("   figures identical in every round: yes")
    print(
        f"   speed-up with 2 workers, warm (median of {ROUNDS} rounds): {speedup:.2f}x   "
        f"goal >= {SPEEDUP_GOAL}x: {verdict(speedup >= SPEEDUP_GOAL)}"
    )


class Replay(Annotator):
    """Puts one recorded frame's colour image and hypotheses into the CAS (fresh hypotheses each run)."""

    outputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage, ObjectHypothesis)

    def __init__(self, image: ColorImage, hypotheses: list[ObjectHypothesis]) -> None:
        super().__init__(name="replay")
        self.image = image
        self.hypotheses = hypotheses

    def analyse(self) -> None:
        self.write(ColorImage(self.image.image))  # a new frame's view (sharing the array): put anew by remote experts
        for hypothesis in self.hypotheses:
            fresh = copy.copy(hypothesis)  # shares its arrays
            fresh.annotations = []
            self.write(fresh)


def one_run(engine: Engine) -> None:
    status = engine.tick()
    while status is Status.RUNNING:
        time.sleep(0.0002)
        status = engine.tick()
    assert status is Status.SUCCESS, status


def bench_overhead() -> None:
    root = tabletop.create_tree()
    one_run(Engine(root, hz=1000))
    cas = next(pipelines(root)).cas
    image, hypotheses = cas.view(ColorImage), cas.annotations(ObjectHypothesis)
    megabytes = (image.image.nbytes + sum(h.mask.nbytes + h.point_indices.nbytes for h in hypotheses)) / 1e6
    print(
        f"2. colour expert per call, kitchen scene: {len(hypotheses)} hypotheses, "
        f"{image.image.shape[1]}x{image.image.shape[0]} image, {megabytes:.1f} MB of declared inputs per call"
    )
    local = SemanticColorAnnotator()
    local_engine = Engine(Pipeline("local", [Replay(image, hypotheses), local]), hz=100000)
    remote_tree = Pipeline("remote", [Replay(image, hypotheses), SemanticColorAnnotator()])
    [remote] = place_remote(remote_tree, ["SemanticColorAnnotator"])
    remote_engine = Engine(remote_tree, hz=100000)
    for _ in range(3):  # warm: the actor's process, its imports and caches
        one_run(local_engine)
        one_run(remote_engine)
    local_ms, remote_ms, local_wall, remote_wall = [], [], [], []
    for _ in range(CALLS):
        start = time.perf_counter()
        one_run(local_engine)
        local_wall.append(1000 * (time.perf_counter() - start))
        local_ms.append(1000 * local.stats.last_seconds)
        start = time.perf_counter()
        one_run(remote_engine)
        remote_wall.append(1000 * (time.perf_counter() - start))
        remote_ms.append(1000 * remote.stats.last_seconds)
    overhead = statistics.median(remote_ms) - statistics.median(local_ms)
    for name, calls, runs in (("local ", local_ms, local_wall), ("remote", remote_ms, remote_wall)):
        print(
            f"   {name} call median {statistics.median(calls):7.2f} ms   (tree run {statistics.median(runs):7.2f} ms)"
        )
    print(
        f"   overhead median {overhead:.2f} ms   goal <= {OVERHEAD_GOAL_MS} ms: {verdict(overhead <= OVERHEAD_GOAL_MS)}"
    )
    remote.stop_actor()


def main() -> None:
    if not LEARN.is_dir():
        sys.exit(f"no scenes at {LEARN}")
    _, startup, _ = timed(
        lambda: ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, logging_level=logging.ERROR)
    )
    print(f"local Ray cluster of 2 CPUs started in {startup:.1f} s (not counted below)")
    try:
        bench_eval()
        bench_overhead()
    finally:
        ray.shutdown()


if __name__ == "__main__":
    main()
