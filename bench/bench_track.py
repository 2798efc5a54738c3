"""Benchmark of a continuous ``track the person`` goal with pose detection in the loop.

Two scenes are played as live sources at 30 frames/s (looped): the kitchen with one person walking behind the
table (frames rendered before the run, so rendering is not timed) and the real five_people.pcd frame
(../shared/data/pcl_people: five people). For each, the served engine's track loop runs the planned tree - the
frame reader, point cloud, range filter, the people detectors' Fallback (HumanPoseDetector first), HumanTracker,
answer step - on every new frame, and then, side by side in the same run, the same experts are called bare: a
plain Pipeline of fresh instances on the same frames, ticked directly (no service, loop, answer step or engine
rate), built with the plan's parameters (the pose detector follows only the tracked person between searches); as
a reference the same bare chain with the pose detector following everyone it sees (``follow_target`` off, the
behaviour before). Printed per scene: the loop's runs per second (answers per second), the bare chain's and the
reference's frames per second, per-expert milliseconds (median, p90) in the loop and bare, and whether the goal of
the issue, >= 15 Hz with pose detection in the loop, is met. ``--profile`` adds the top functions of the loop's
ticks (cProfile in the engine thread, answer step included; ``--profile-out`` writes them to a file).

Run: ``.venv/bin/python bench/bench_track.py [--seconds S] [--profile] [--profile-out FILE]``
"""

from __future__ import annotations

import argparse
import cProfile
import io
import pstats
import statistics
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from annotators.catalog import AnnotatorCatalog  # noqa: E402
from annotators.readers.frame_io import Frame  # noqa: E402
from annotators.readers.streams import FrameStream, PlaybackStream, StreamReader, stream_for  # noqa: E402
from annotators.simulation.kitchen_person import Motion, PersonScript, person_view  # noqa: E402
from annotators.simulation.kitchen_scene import render_kitchen  # noqa: E402
from robokudo.application.service import AnsweringService  # noqa: E402
from robokudo.core.annotator import Annotator  # noqa: E402
from robokudo.core.engine import Engine  # noqa: E402
from robokudo.core.pipeline import Pipeline  # noqa: E402

FIVE_PEOPLE = ROOT.parent / "shared" / "data" / "pcl_people" / "five_people.pcd"
GOAL_HZ = 15.0
RATE = 30.0
QUERY = "track the person"
WALK = PersonScript((Motion("walk", 3.0, ((-0.9, 0.9), (0.9, 0.6))),))
BARE = ("PointCloudGenerator", "RangeFilter", "HumanPoseDetector", "HumanTracker")
"""The experts of the planned track tree called bare (the reader is the stream's)."""

Table = dict[str, list[float]]
Arguments = dict[str, dict[str, object]]


def kitchen_walk(frames: int = 30) -> Callable[[], Iterator[tuple[Frame, str]]]:
    """The walk rendered once (10 frames/s of the script); replayed by a playback stream."""
    rendered = []
    for index in range(frames):
        scene = render_kitchen(person_view(), seed=index, person=WALK.pose_at(index / 10.0))
        rendered.append(Frame(color=scene.color, depth=scene.depth, intrinsics=scene.intrinsics, source="walk"))

    def frames_once() -> Iterator[tuple[Frame, str]]:
        for frame in rendered:
            yield frame, "kitchen walk"

    return frames_once


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(q * (len(ordered) - 1)))]


def _profiled(tick: Callable[[], object], profile: cProfile.Profile) -> Callable[[], object]:
    """``tick`` with ``profile`` enabled while it runs (on the calling thread: the engine's)."""

    def run() -> object:
        profile.enable()
        try:
            return tick()
        finally:
            profile.disable()

    return run


def loop_run(
    stream: FrameStream, seconds: float, profile: cProfile.Profile | None = None
) -> tuple[float, Table, int, Arguments]:
    """Answers per second of the served track loop after a warm-up, per-expert ms, answers that saw the person and
    the plan's constructor arguments per expert; with ``profile`` the engine's ticks after the warm-up are profiled
    (answer step included)."""
    with (
        tempfile.TemporaryDirectory() as folder,
        AnsweringService.open(Path(folder) / "b.sqlite", hz=60, stream=stream, lost_after=30.0) as service,
    ):
        handle = service.start(QUERY)
        arguments: Arguments = {step.annotator: dict(step.parameters) for step in handle.plan.plan.steps()}
        for _ in range(3):  # warm-up: model loading, first frames
            if handle.next_answer(timeout=180) is None:
                raise SystemExit(f"no answer: {handle.reason}")
        if profile is not None:  # the engine thread looks its tick up on every run
            service.engine.tick = _profiled(service.engine.tick, profile)  # type: ignore[method-assign]
        nodes = [n for n in handle.tree.iterate() if isinstance(n, Annotator)]
        counts = {n.name: n.stats.count for n in nodes}
        durations: Table = {}
        answers = seen = 0
        start = time.perf_counter()
        while time.perf_counter() - start < seconds:
            answer = handle.next_answer(timeout=30)
            if answer is None:
                break
            answers += 1
            seen += bool(answer.track and answer.track.seen)
            for node in nodes:
                if node.stats.count > counts[node.name]:
                    counts[node.name] = node.stats.count
                    durations.setdefault(node.name, []).append(node.stats.last_seconds * 1e3)
        elapsed = time.perf_counter() - start
        try:
            handle.cancel()
        except TimeoutError as error:  # a long tick (the full search on a busy machine); closing stops the engine
            print(f"  (cancel: {error})")
    return answers / elapsed, durations, seen, arguments


def bare_run(
    stream: FrameStream, seconds: float, profile: cProfile.Profile | None, arguments: Arguments
) -> tuple[float, Table]:
    """Frames per second of the same experts (built with ``arguments`` per expert) in a plain Pipeline ticked
    directly, and their per-expert ms."""
    catalog = AnnotatorCatalog.discover()
    experts = [catalog[name](name=name, **arguments.get(name, {})) for name in BARE]
    root = Pipeline("bare", [StreamReader(stream, wait=False, name="read frame"), *experts])
    engine = Engine(root)
    for _ in range(3):
        engine.tick()
    durations: Table = {}
    frames, busy = 0, 0.0
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        began = time.perf_counter()
        if profile is not None:
            profile.enable()
        engine.tick()
        if profile is not None:
            profile.disable()
        if all(e.stats.count and e.stats.last_seconds for e in experts) and root.status.name == "SUCCESS":
            frames += 1
            busy += time.perf_counter() - began
            for expert in experts:
                durations.setdefault(expert.name, []).append(expert.stats.last_seconds * 1e3)
    return (frames / busy if busy else 0.0), durations


def row(name: str, loop: Table, bare: Table) -> str:
    def cells(table: Table) -> str:
        values = table.get(name)
        if not values:
            return f"{'-':>9s} {'-':>9s}"
        return f"{statistics.median(values):9.2f} {percentile(values, 0.9):9.2f}"

    return f"  {name:26s} {cells(loop)}   {cells(bare)}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0, help="measuring time per run (default 20)")
    parser.add_argument("--profile", action="store_true", help="print the top functions of the loop's ticks")
    parser.add_argument("--profile-out", type=Path, help="also write them (all scenes) to this file")
    args = parser.parse_args()
    print(f"goal: a track loop with pose detection runs at >= {GOAL_HZ:g} Hz (640x480 frames offered at {RATE:g}/s)")
    scenes: list[tuple[str, Callable[[], FrameStream]]] = []
    walk = kitchen_walk()
    scenes.append(("kitchen, one person walking", lambda: PlaybackStream(walk, "kitchen walk", RATE, loop=True)))
    if FIVE_PEOPLE.exists():
        scenes.append(("five_people.pcd, five people", lambda: stream_for(str(FIVE_PEOPLE), RATE, loop=True)))
    else:
        print(f"(missing {FIVE_PEOPLE}: the real frame is left out)")
    verdicts = []
    profiles: list[str] = []
    for label, make in scenes:
        profile = cProfile.Profile() if args.profile else None
        rate, loop, seen, arguments = loop_run(make(), args.seconds, profile)
        bare_rate, bare = bare_run(make(), args.seconds, None, arguments)
        everyone = {
            name: {**values, "follow_target": False} for name, values in arguments.items() if "follow_target" in values
        }
        reference_rate, _ = bare_run(make(), args.seconds, None, {**arguments, **everyone}) if everyone else (0.0, {})
        print(f"\n{label}: loop {rate:.1f} runs/s (the person seen in {seen} answers); bare experts {bare_rate:.1f}/s")
        if everyone:
            ratio = bare_rate / reference_rate if reference_rate else float("inf")
            print(
                f"  reference, bare experts following everyone seen: {reference_rate:.1f}/s (target only: {ratio:.2f}x)"
            )
        print(f"  {'expert':26s} {'loop median':>9s} {'p90':>9s}   {'bare median':>9s} {'p90':>9s}   (ms)")
        names = sorted(set(loop) | set(bare), key=lambda n: -statistics.median(loop.get(n) or bare.get(n) or [0.0]))
        for name in names:
            print(row(name, loop, bare))
        verdicts.append((label, rate))
        if profile is not None:
            text = io.StringIO()
            text.write(f"{label}: the loop's ticks ({rate:.1f} runs/s), by cumulative time\n")
            stats = pstats.Stats(profile, stream=text)
            stats.sort_stats("cumulative").print_stats(30)
            text.write("by own time\n")
            stats.sort_stats("tottime").print_stats(20)
            print(text.getvalue())
            profiles.append(text.getvalue())
    if args.profile_out is not None and profiles:
        args.profile_out.parent.mkdir(parents=True, exist_ok=True)
        args.profile_out.write_text("\n".join(profiles))
    print()
    for label, rate in verdicts:
        verdict = "met" if rate >= GOAL_HZ else "NOT met"
        print(f"goal {verdict} on {label}: {rate:.1f} Hz with pose detection in the loop (goal {GOAL_HZ:g} Hz)")


if __name__ == "__main__":
    main()
