"""Where the tabletop tree's tick goes on a real frame: per annotator, per segmenter step, and by function.

``python bench/profile_tabletop.py [--checkout PATH] [--frame N] [--ticks T]`` builds ``trees.tabletop`` of
CHECKOUT (default: this one; another checkout - e.g. one exported with ``git archive`` - is profiled the same way)
on frame N (default 3) of ../shared/data/uoc_tabletop_realsense, ticks it three times to warm up and then reports,
over T ticks (medians per tick, wall ms; the tick's CPU ms too, the least disturbed by other processes):

* the tick, each annotator's run (its RunStats) and the rest - the tree, the CAS and the engine around the runs;
* the ClutterSegmenter's steps: each function :func:`~annotators.cloud.clutter.segment_clutter` calls by name is
  wrapped and timed inclusively (what a step calls is in its time);
* cProfile of as many ticks (before the steps are wrapped): the functions with the most own time and the most
  calls (cProfile's own overhead inflates functions called often, so its milliseconds are for ranking only);
* with ``--alone R``: each step run by itself R times on a copy of the inputs it had in one tick, the least time
  (what it calls included, the tree and the steps around it not: steadier than the medians in the tree when the
  machine is busy).

The machine is shared: compare runs of this script only side by side (alternating), by ratios.
"""

from __future__ import annotations

import argparse
import collections
import copy
import cProfile
import io
import pstats
import statistics
import sys
import time
import types
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = (ROOT.parent / "shared" / "data" / "uoc_tabletop_realsense").resolve()


def step_timers(module: types.ModuleType) -> dict[str, list[float]]:
    """Wrap every function ``module`` imported from the annotators (what its segmentation calls by name) in a wall
    timer; returns the seconds of each call, by function name (filled while the wrappers stay in place)."""
    seconds: dict[str, list[float]] = collections.defaultdict(list)

    def timed(name: str, original: Callable[..., object]) -> Callable[..., object]:
        def call(*args: object, **kwargs: object) -> object:
            start = time.perf_counter()
            try:
                return original(*args, **kwargs)
            finally:
                seconds[name].append(time.perf_counter() - start)

        return call

    for name, value in list(vars(module).items()):
        if isinstance(value, types.FunctionType) and value.__module__.startswith("annotators."):
            setattr(module, name, timed(name, value))
    return seconds


def captured_steps(module: types.ModuleType) -> dict[str, tuple[Callable[..., object], tuple, dict]]:
    """Wrap every function ``module`` imported from the annotators so that its first call's arguments are kept (a
    deep copy, made before the call); returns the function and arguments by name, filled while the wrappers stay in
    place."""
    calls: dict[str, tuple[Callable[..., object], tuple, dict]] = {}

    def keeping(name: str, original: Callable[..., object]) -> Callable[..., object]:
        def call(*args: object, **kwargs: object) -> object:
            if name not in calls:
                calls[name] = (original, copy.deepcopy(args), copy.deepcopy(kwargs))
            return original(*args, **kwargs)

        return call

    for name, value in list(vars(module).items()):
        if isinstance(value, types.FunctionType) and value.__module__.startswith("annotators."):
            setattr(module, name, keeping(name, value))
    return calls


def least_alone(calls: dict[str, tuple[Callable[..., object], tuple, dict]], rounds: int) -> dict[str, float]:
    """The least wall seconds of each kept call, run ``rounds`` times on fresh copies of its arguments."""
    least = {}
    for name, (function, args, kwargs) in calls.items():
        times = []
        for _ in range(rounds):
            fresh_args, fresh_kwargs = copy.deepcopy(args), copy.deepcopy(kwargs)
            start = time.perf_counter()
            function(*fresh_args, **fresh_kwargs)
            times.append(time.perf_counter() - start)
        least[name] = min(times)
    return least


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--checkout", type=Path, default=ROOT, help="the checkout whose tree is profiled")
    parser.add_argument("--frame", type=int, default=3)
    parser.add_argument("--ticks", type=int, default=40)
    parser.add_argument("--top", type=int, default=30, help="functions listed from cProfile")
    parser.add_argument("--alone", type=int, default=0, metavar="R", help="time each step alone, R runs (least)")
    args = parser.parse_args()
    sys.path.insert(0, str(args.checkout))
    import annotators.cloud.clutter as clutter
    from robokudo.core.annotator import Annotator
    from robokudo.core.engine import Engine
    from trees.tabletop import create_tree

    root = create_tree(str(DATA), args.frame)
    engine = Engine(root, hz=1000.0)
    for _ in range(3):
        engine.tick()
    annotators = [node for node in root.iterate() if isinstance(node, Annotator)]
    ticks: list[float] = []
    cpu: list[float] = []
    runs: dict[str, list[float]] = {node.name: [] for node in annotators}
    for _ in range(args.ticks):
        start, start_cpu = time.perf_counter(), time.process_time()
        engine.tick()
        ticks.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
        for node in annotators:
            runs[node.name].append(node.stats.last_seconds)
    tick = statistics.median(ticks) * 1e3
    print(f"tabletop tree of {args.checkout} on {DATA.name}/{args.frame:06d}, {args.ticks} ticks, median wall ms")
    print(f"  {'tick':34s} {tick:7.2f}  ({1e3 / tick:.1f} Hz; CPU {statistics.median(cpu) * 1e3:.2f} ms, all threads)")
    summed = 0.0
    for name, seconds in runs.items():
        ms = statistics.median(seconds) * 1e3
        summed += ms
        print(f"  {name:34s} {ms:7.2f}")
    print(f"  {'rest (tree, CAS, engine)':34s} {tick - summed:7.2f}")

    profile = cProfile.Profile()
    profile.enable()
    for _ in range(args.ticks):
        engine.tick()
    profile.disable()
    for order in ("tottime", "ncalls"):
        text = io.StringIO()
        pstats.Stats(profile, stream=text).sort_stats(order).print_stats(args.top)
        listing = text.getvalue().replace(str(args.checkout) + "/", "")
        print(f"\ncProfile of {args.ticks} ticks, by {order}:\n{listing.split('Ordered by', 1)[-1]}")

    if args.alone > 0:
        original = dict(vars(clutter))
        calls = captured_steps(clutter)
        engine.tick()
        vars(clutter).update(original)
        print(f"\nClutterSegmenter steps alone on one tick's inputs (least wall ms of {args.alone} runs; what a step")
        print("calls is in its time, the tree and the steps around it are not):")
        for name, least in sorted(least_alone(calls, args.alone).items(), key=lambda item: -item[1]):
            print(f"  {name:34s} {least * 1e3:7.3f}")

    seconds = step_timers(clutter)
    for _ in range(args.ticks):
        engine.tick()
    print("\nClutterSegmenter steps (inclusive wall ms per tick, median call x calls per tick):")
    per_tick = {name: statistics.median(calls) * len(calls) / args.ticks for name, calls in seconds.items()}
    for name, value in sorted(per_tick.items(), key=lambda item: -item[1]):
        print(f"  {name:34s} {value * 1e3:7.3f}  x{len(seconds[name]) / args.ticks:.0f}")


if __name__ == "__main__":
    main()
