"""Beyond one machine, on a local Ray cluster of 2 CPUs started here, measured side by side in one run.

Every process of the run (this one and Ray's workers, which inherit its environment) computes with one thread
per process (OpenMP, OpenBLAS, MKL, OpenCV pinned to 1), so neither side gets a hidden second core; Ray's
workers run at this process's priority (``robokudo.application.cluster``).

1. ``robokudo eval segmentation`` on the 45 shared mOSD learn scenes: in this process vs ``--workers 2`` (Ray
   tasks), in rounds that alternate which side goes first; the figures must be identical. Goal: >= 1.7x
   faster with 2 workers (median of the warm rounds' ratios), on a running cluster with warm workers (the
   cluster's start and the first round, where the workers import the code, are printed apart; the sequential
   side is warm too). The CPU time both sides spent on the scenes is printed: the same work.
2. Per-call overhead of a remote expert: the colour expert on the kitchen scene's hypotheses, run locally and on
   a Ray actor in two ways, alternating call by call (which remote side goes first alternates too): through the
   actor's compiled graph (the default: shared-memory channels) and by plain actor calls
   (``Placement(compiled_graph=False)``: the image put into the object store, the call submitted as a Ray task).
   Each run is on a new frame object (so the frame's image is sent anew for every remote call, as for a live
   camera), after a warm-up of a few seconds (the actors' imports, the object store's pages). The remote call's
   latency is the node's own (its worker thread: declared inputs gathered and packed, sent, the actor called, its
   answer in hand and its writes checked), not the tree's tick period. The overhead is that latency minus the
   paired local run's time, call by call; its median and 90th percentile are printed for both ways side by side.
   Goal: <= 2 ms median (the compiled graph, the default path). Printed beside it: the latency against the
   expert's run on the actor (measured there), the stages of the remote call, the CPU time each run cost this
   process and the actor's, and Ray's own floor on this machine: a bare compiled-graph call of the expert's shape,
   and for plain calls, measured alternately with the expert's calls in the same way (waited for in a thread
   while this one ticks), calls of growing shape: the simplest call (no arguments, returns None), the actor busy
   as long as the expert ran, the image put and passed, the packed hypotheses passed (the expert's call shape).

Run: ``PYTHONPATH=. .venv/bin/python bench/bench_ray.py``. The load average is printed: the machine is shared,
and when other jobs take the cores, two workers cannot run twice as fast as one.
"""

from __future__ import annotations

import os

THREADS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OPENCV_FOR_THREADS_NUM")
for _variable in THREADS:  # before numpy, OpenCV and Open3D load
    os.environ[_variable] = "1"

import argparse  # noqa: E402
import copy  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import threading  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable  # noqa: E402
from pathlib import Path  # noqa: E402
from types import ModuleType  # noqa: E402
from typing import Any, ClassVar, TypeVar  # noqa: E402

import numpy as np  # noqa: E402
from py_trees.common import Status  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from annotators.image.color import SemanticColorAnnotator  # noqa: E402
from robokudo.application.cluster import ray_cluster  # noqa: E402
from robokudo.application.commands.eval import SceneResult, scene_files, score_scene  # noqa: E402
from robokudo.application.parallel import map_on_cluster, run_in_order  # noqa: E402
from robokudo.core.annotator import Annotator  # noqa: E402
from robokudo.core.engine import Engine  # noqa: E402
from robokudo.core.pipeline import Pipeline, pipelines  # noqa: E402
from robokudo.core.placement import Placement  # noqa: E402
from robokudo.core.remote import in_transit, place_remote  # noqa: E402
from robokudo.core.types import CasType, ColorImage, ObjectHypothesis  # noqa: E402
from trees import tabletop  # noqa: E402

LEARN = (ROOT.parent / "shared" / "data" / "pcl_mosd_tabletop" / "learn").resolve()
ROUNDS = 3
CALLS = 80
FLOOR_CALLS = 200
SPEEDUP_GOAL = 1.7
OVERHEAD_GOAL_MS = 2.0
WARM_SECONDS = 3.0
"""Warm-up before measuring: beyond the actor's imports, the object store's pages (Ray frees a dropped object's
memory in batches about once a second, so the first second of puts lands on pages no process has touched yet)."""
T = TypeVar("T")


def verdict(met: bool) -> str:
    return "met" if met else "NOT met"


def load() -> str:
    return "load average " + " ".join(f"{value:.1f}" for value in os.getloadavg())


def timed(work: Callable[[], T]) -> tuple[T, float]:
    start = time.perf_counter()
    result = work()
    return result, time.perf_counter() - start


def scored(path: Path, segmenter_name: str) -> tuple[SceneResult, float]:
    """One scene scored as ``eval`` scores it, and the CPU time it took where it ran."""
    start = time.process_time()
    result = score_scene(path, segmenter_name)
    return result, time.process_time() - start


def figures(results: list[tuple[SceneResult, float]]) -> list:
    return [(r.scene, r.category, r.score) for r, _ in results]


def cpu(results: list[tuple[SceneResult, float]]) -> float:
    return sum(seconds for _, seconds in results)


def bench_eval() -> None:
    files = scene_files([str(LEARN)])
    print(f"1. eval segmentation, {len(files)} scenes (clutter segmenter), {load()}")
    score_scene(files[0], "clutter")  # this process's imports and caches warm, as the workers' after round 1
    ratios: list[float] = []
    reference = None
    for round_number in range(1, ROUNDS + 2):

        def sequential() -> list[tuple[SceneResult, float]]:
            return run_in_order(scored, files, "clutter")

        def parallel() -> list[tuple[SceneResult, float]]:
            return map_on_cluster(scored, files, "clutter", workers=2)

        if round_number % 2:
            (seq, seq_wall), (par, par_wall) = timed(sequential), timed(parallel)
        else:
            (par, par_wall), (seq, seq_wall) = timed(parallel), timed(sequential)
        reference = reference or figures(seq)
        assert figures(seq) == reference and figures(par) == reference, "the figures differ"
        note = "  (workers start cold: imports; not counted)" if round_number == 1 else ""
        print(
            f"   round {round_number}: sequential {seq_wall:6.2f} s (cpu {cpu(seq):5.2f} s)   --workers 2 "
            f"{par_wall:6.2f} s (workers' cpu {cpu(par):5.2f} s)   {seq_wall / par_wall:4.2f}x{note}"
        )
        if round_number > 1:
            ratios.append(seq_wall / par_wall)
    speedup = statistics.median(ratios)
    print(f"   figures identical in every round: yes; {load()}")
    print(
        f"   speed-up with 2 workers, warm (median of {ROUNDS} rounds' ratios): {speedup:.2f}x   "
        f"goal >= {SPEEDUP_GOAL}x: {verdict(speedup >= SPEEDUP_GOAL)}"
    )


class Replay(Annotator):
    """Puts one recorded frame's colour image and hypotheses into the CAS as a new frame (new objects sharing
    the recorded arrays) each run."""

    outputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage, ObjectHypothesis)

    def __init__(self, image: ColorImage, hypotheses: list[ObjectHypothesis]) -> None:
        super().__init__(name="replay")
        self.image = image
        self.hypotheses = hypotheses

    def analyse(self) -> None:
        self.write(ColorImage(self.image.image))
        for hypothesis in self.hypotheses:
            fresh = copy.copy(hypothesis)
            fresh.annotations = []
            self.write(fresh)


def one_run(engine: Engine, tick: float = 0.0002) -> None:
    """One run of the tree, ticked every ``tick`` seconds while it is RUNNING."""
    status = engine.tick()
    while status is Status.RUNNING:
        time.sleep(tick)
        status = engine.tick()
    assert status is Status.SUCCESS, status


class Empty:
    """An actor that does nothing: Ray's own floor for a call."""

    def call(self, *arguments: Any) -> None:
        return None


class Busy:
    """An actor that takes the arguments of the expert's call and stays busy as long as the expert ran on its
    actor: Ray's floor for a call of that shape (and, with ``nothing``, for the simplest call)."""

    def nothing(self) -> None:
        return None

    def call(self, annotations: list[Any], view: ColorImage | None, seconds: float) -> None:
        end = time.perf_counter() + seconds
        while time.perf_counter() < end:
            pass

    def packed(self, inputs: tuple[list[Any], ColorImage, float]) -> None:
        """:meth:`call` as a compiled graph's call brings its arguments."""
        self.call(*inputs)


def in_worker(work: Callable[[], object], tick: float) -> float:
    """Ms that ``work`` took in a worker thread while this thread ticked every ``tick`` s (as a remote node's
    worker waits while the tree ticks)."""
    outcome: list[Any] = []

    def run() -> None:
        start = time.perf_counter()
        try:
            work()
        except Exception as error:  # handed to the ticking thread
            outcome.append(error)
        else:
            outcome.append(time.perf_counter() - start)

    worker = threading.Thread(target=run, name="bare call")
    worker.start()
    while worker.is_alive():
        time.sleep(tick)
    if isinstance(outcome[0], Exception):
        raise outcome[0]
    return 1000 * outcome[0]


class Floors:
    """Ray's floor for calls of growing shape, each waited for in a worker thread while this thread ticks, one of
    each alternating with the expert's calls (so both see the same machine): what each adds beyond the actor's
    work."""

    RUNGS: ClassVar[tuple[str, ...]] = (
        "the simplest call (no arguments, returns None)",
        "+ the actor busy as long as the expert ran",
        "+ the frame's image put and its reference passed",
        "+ the packed hypotheses (the expert's call shape)",
    )

    def __init__(self, ray: ModuleType, annotations: list[Any], image: np.ndarray, tick: float) -> None:
        self.ray = ray
        self.busy = ray.remote(Busy).options(num_cpus=1).remote()  # the expert's actor takes the other CPU
        self.annotations = annotations
        self.image = image
        self.tick = tick
        self.ms: dict[str, list[float]] = {rung: [] for rung in self.RUNGS}

    def measure(self, seconds: float) -> None:
        """One call of each rung; ``seconds``: how long the expert ran on its actor."""
        ray, busy, tick = self.ray, self.busy, self.tick
        simplest, with_work, with_image, shaped = self.RUNGS
        self.ms[simplest].append(in_worker(lambda: ray.get(busy.nothing.remote()), tick))
        self.ms[with_work].append(
            in_worker(lambda: ray.get(busy.call.remote([], None, seconds)), tick) - 1000 * seconds
        )
        image = self.image

        def imaged() -> None:
            ray.get(busy.call.remote([], ray.put(ColorImage(image)), seconds))

        def packed() -> None:
            ray.get(busy.call.remote(self.annotations, ray.put(ColorImage(image)), seconds))

        self.ms[with_image].append(in_worker(imaged, tick) - 1000 * seconds)
        self.ms[shaped].append(in_worker(packed, tick) - 1000 * seconds)

    def medians(self) -> dict[str, float]:
        return {rung: statistics.median(values) for rung, values in self.ms.items()}

    def close(self) -> None:
        self.ray.kill(self.busy)


def ray_floor(ray: ModuleType, image: np.ndarray) -> tuple[float, float]:
    """Median ms of an empty actor call, and of a call with a reference to ``image`` put anew each time, called
    back to back from this thread."""
    actor = ray.remote(Empty).options(num_cpus=1).remote()
    ray.get(actor.call.remote())
    empty, with_image = [], []
    for _ in range(FLOOR_CALLS):
        start = time.perf_counter()
        ray.get(actor.call.remote())
        empty.append(1000 * (time.perf_counter() - start))
        start = time.perf_counter()
        ray.get(actor.call.remote(ray.put(ColorImage(image))))
        with_image.append(1000 * (time.perf_counter() - start))
    ray.kill(actor)
    return statistics.median(empty), statistics.median(with_image)


def percentile(values: list[float], fraction: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(fraction * len(ordered)))]


class RemoteSide:
    """One way of calling the expert on an actor (a tree of its own) and its figures, call by call."""

    def __init__(
        self,
        label: str,
        image: ColorImage,
        hypotheses: list[ObjectHypothesis],
        compiled: bool,
        nap: float | None = None,
    ) -> None:
        self.label = label
        tree = Pipeline(label, [Replay(image, hypotheses), SemanticColorAnnotator()])
        hints = Placement(remote=True, num_cpus=0.3, compiled_graph=compiled)  # all actors fit beside the floor's
        [self.node] = place_remote(tree, ["SemanticColorAnnotator"], hints)
        calls = self.node.compiled_calls()
        if calls is not None and nap is not None:
            calls.nap_fraction = nap
        self.engine = Engine(tree, hz=100000)
        self.latency_ms: list[float] = []
        self.added_ms: list[float] = []
        self.versus_local_ms: list[float] = []
        self.wall_ms: list[float] = []
        self.stages: dict[str, list[float]] = {}
        self.cpu_ms: list[float] = []
        self.actor_cpu_ms: list[float] = []
        self.actor_pid = 0

    def run(self, tick: float, local_ms: float | None) -> None:
        """One run; with ``local_ms`` (the paired local run's time) its figures are kept."""
        actor_cpu = process_cpu(self.actor_pid)
        cpu = time.process_time()
        start = time.perf_counter()
        one_run(self.engine, tick)
        wall = 1000 * (time.perf_counter() - start)
        if local_ms is None:
            return
        self.cpu_ms.append(1000 * (time.process_time() - cpu))
        self.actor_cpu_ms.append(1000 * (process_cpu(self.actor_pid) - actor_cpu))
        latency = 1000 * self.node.stats.last_seconds
        self.wall_ms.append(wall)
        self.latency_ms.append(latency)
        self.added_ms.append(latency - 1000 * self.node.remote_seconds)
        self.versus_local_ms.append(latency - local_ms)
        for stage, seconds in self.node.call_times.stages().items():
            self.stages.setdefault(stage, []).append(1000 * seconds)


def process_cpu(pid: int) -> float:
    """Seconds of CPU process ``pid`` has used (0 where /proc cannot tell)."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except (OSError, IndexError):
        return 0.0
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def compiled_floor(ray: ModuleType, annotations: list[Any], image: np.ndarray, seconds: float) -> float:
    """Median ms beyond the actor's work of a bare compiled-graph call of the expert's shape (image and packed
    hypotheses in, None out), called back to back from this thread."""
    from ray.dag import InputNode

    actor = ray.remote(Busy).options(num_cpus=0.5).remote()
    with InputNode() as inputs:
        graph = actor.packed.bind(inputs)
    compiled = graph.experimental_compile(_buffer_size_bytes=4 << 20)
    try:
        for _ in range(5):
            ray.get(compiled.execute((annotations, ColorImage(image), seconds)))
        ms = []
        for _ in range(FLOOR_CALLS):
            start = time.perf_counter()
            ray.get(compiled.execute((annotations, ColorImage(image), seconds)))
            ms.append(1000 * (time.perf_counter() - start - seconds))
    finally:
        compiled.teardown()
        ray.kill(actor)
    return statistics.median(ms)


def bench_overhead(ray: ModuleType, calls: int = CALLS, tick: float = 0.0002, compare_nap: bool = False) -> None:
    root = tabletop.create_tree()
    one_run(Engine(root, hz=1000))
    cas = next(pipelines(root)).cas
    image, hypotheses = cas.view(ColorImage), cas.annotations(ObjectHypothesis)
    megabytes = (image.image.nbytes + sum(h.mask.nbytes + h.point_indices.nbytes for h in hypotheses)) / 1e6
    print(
        f"2. colour expert per call, kitchen scene: {len(hypotheses)} hypotheses, "
        f"{image.image.shape[1]}x{image.image.shape[0]} image, {megabytes:.1f} MB of declared inputs, {load()}"
    )
    local = SemanticColorAnnotator()
    local_engine = Engine(Pipeline("local", [Replay(image, hypotheses), local]), hz=100000)
    sides = [
        RemoteSide("compiled", image, hypotheses, compiled=True),
        RemoteSide("plain", image, hypotheses, compiled=False),
    ]
    if compare_nap:  # a compiled side that sleeps through most of the expected wait (CPU and tail vs the default)
        sides.append(RemoteSide("nap 0.8", image, hypotheses, compiled=True, nap=0.8))
    sent = [in_transit(copy.copy(hypothesis), (ObjectHypothesis,)) for hypothesis in hypotheses]
    floors = Floors(ray, sent, image.image, tick)
    warm_until = time.perf_counter() + WARM_SECONDS
    warm_runs = 0
    while warm_runs < 5 or time.perf_counter() < warm_until:
        one_run(local_engine, tick)
        for side in sides:
            side.run(tick, None)
        floors.measure(0.001)
        warm_runs += 1
    for side in sides:
        print(f"   {side.label:8s}: calls take {side.node.call_path}")
        side.actor_pid = side.node.actor_process_id()
    floors.ms = {rung: [] for rung in floors.RUNGS}
    local_ms, local_wall, actor_ms = [], [], []
    for call in range(calls):
        start = time.perf_counter()
        one_run(local_engine, tick)
        local_wall.append(1000 * (time.perf_counter() - start))
        local_ms.append(1000 * local.stats.last_seconds)
        for side in sides if call % 2 else sides[::-1]:  # which remote side goes first alternates
            side.run(tick, local_ms[-1])
        actor_ms.append(1000 * sides[0].node.remote_seconds)
        floors.measure(sides[0].node.remote_seconds)
    for side in sides:
        side.node.stop_actor()
    floors.close()
    empty_ms, image_ms = ray_floor(ray, image.image)
    compiled_ms = compiled_floor(ray, sent, image.image, statistics.median(actor_ms) / 1000)
    median = statistics.median
    rungs = floors.medians()
    print(f"   (warmed for {warm_runs} rounds: the actors' processes, their caches, the object store's pages)")
    print(f"   local run of the expert   median {median(local_ms):7.2f} ms   (tree run {median(local_wall):.2f} ms)")
    for side in sides:
        print(
            f"   {side.label:8s} remote call latency median {median(side.latency_ms):7.2f} ms   (tree run "
            f"{median(side.wall_ms):.2f} ms, ticking every {1000 * tick:g} ms); latency - the run on the actor "
            f"{median(side.added_ms):.2f} ms"
        )
        print(
            f"      CPU per run (ms, sums over the measured runs / runs, the local run included in neither): "
            f"this process (tree, worker, ticks) {statistics.mean(side.cpu_ms):.2f}, "
            f"the actor's process {statistics.mean(side.actor_cpu_ms):.2f}"
        )
        print(
            "      stages (medians, ms): "
            + ", ".join(f"{stage} {median(values):.2f}" for stage, values in side.stages.items())
        )
    print(
        f"   Ray's floor, back to back from one thread: an empty actor call {empty_ms:.2f} ms, "
        f"one with a reference to a 640x480 image put for it {image_ms:.2f} ms; a compiled-graph call of the "
        f"expert's shape (image and packed hypotheses in) {compiled_ms:.2f} ms beyond the actor's work"
    )
    print("   Ray's floor for plain calls, waited for in a thread as the node waits, alternating with the expert's")
    print("   calls (ms beyond the actor's work, medians):")
    for rung, value in rungs.items():
        print(f"      {rung:52s} {value:6.2f}")
    print("   overhead per call (remote latency - local run, paired calls), side by side in one run:")
    for side in sides:
        values = side.versus_local_ms
        print(f"      {side.label:8s} median {median(values):6.2f} ms   p90 {percentile(values, 0.9):6.2f} ms")
    compiled, plain = (median(side.versus_local_ms) for side in sides[:2])
    if compiled > 0:
        print(f"      plain / compiled overhead: {plain / compiled:.1f}x")
    print(
        f"   overhead per call (compiled graph, the default): median {compiled:.2f} ms   "
        f"goal <= {OVERHEAD_GOAL_MS} ms: {verdict(compiled <= OVERHEAD_GOAL_MS)}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--only", choices=("eval", "overhead"), help="run one of the two benchmarks")
    parser.add_argument("--calls", type=int, default=CALLS, help="remote calls measured (overhead)")
    parser.add_argument(
        "--compare-nap", action="store_true", help="also a compiled side that sleeps while it waits (overhead)"
    )
    parser.add_argument("--tick-ms", type=float, default=0.2, help="tick period while a run is RUNNING (overhead)")
    args = parser.parse_args()
    if not LEARN.is_dir():
        sys.exit(f"no scenes at {LEARN}")
    print(f"one thread per process on both sides ({', '.join(f'{name}=1' for name in THREADS)}); {load()}")
    start = time.perf_counter()
    with ray_cluster(num_cpus=2) as ray:
        print(f"local Ray cluster of 2 CPUs started in {time.perf_counter() - start:.1f} s (not counted below)")
        if args.only != "overhead":
            bench_eval()
        if args.only != "eval":
            bench_overhead(ray, args.calls, args.tick_ms / 1000, args.compare_nap)


if __name__ == "__main__":
    main()
