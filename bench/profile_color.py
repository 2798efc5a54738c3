"""Where SemanticColorAnnotator's time goes on a real frame: per-phase timers and a cProfile listing.

``python bench/profile_color.py [--frame N] [--rounds R]`` ticks the tabletop tree on frame N (default 3) of
../shared/data/uoc_tabletop_realsense, then times, on that frame's image and hypotheses, rounds alternating: the
annotator's whole run in the tree (its RunStats), its analyse() alone, and its phases through the public functions
it calls (the frame's white balance, picking the objects' pixels, their surfaces, naming them). Wall and CPU
milliseconds (medians); then the cProfile of 100 runs of analyse(), by own time. The machine is shared: compare
runs of this script only side by side.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from annotators.image.color import SemanticColorAnnotator, name_objects_colors  # noqa: E402
from annotators.image.color_surfaces import objects_pixels, objects_surfaces  # noqa: E402
from annotators.image.white_balance import estimate_frame_light  # noqa: E402
from robokudo.core.engine import Engine  # noqa: E402
from robokudo.core.stats import RunStats  # noqa: E402
from robokudo.core.types import ColorImage, ObjectHypothesis  # noqa: E402
from trees.tabletop import create_tree  # noqa: E402

DATA = (ROOT.parent / "shared" / "data" / "uoc_tabletop_realsense").resolve()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--frame", type=int, default=3)
    parser.add_argument("--rounds", type=int, default=30)
    parser.add_argument("--data", type=Path, default=DATA, help="the uoc recording (default: the shared one)")
    args = parser.parse_args()
    root = create_tree(str(args.data), args.frame)
    engine = Engine(root, hz=1000.0)
    for _ in range(3):
        engine.tick()
    color = next(node for node in root.iterate() if isinstance(node, SemanticColorAnnotator))
    image = root.cas.view(ColorImage).image
    hypotheses = root.cas.annotations(ObjectHypothesis)
    light = estimate_frame_light(image)
    picked = objects_pixels(image, hypotheses, color.max_pixels)
    color.stats = RunStats()

    def analyse_alone() -> None:
        color.analyse()  # in the run of the last tick, which the annotator keeps; its writes are dropped
        color._run.writes.clear()

    phases: dict[str, Callable[[], object]] = {
        "tree tick (whole tree)": engine.tick,
        "analyse() alone": analyse_alone,
        "  frame light (white balance)": lambda: estimate_frame_light(image),
        "  pick pixels + edges": lambda: objects_pixels(image, hypotheses, color.max_pixels),
        "  name_objects_colors": lambda: name_objects_colors(picked, light, color.parameters),
        "    objects_surfaces": lambda: objects_surfaces(picked, light, color.parameters),
    }
    wall: dict[str, list[float]] = {name: [] for name in phases}
    cpu: dict[str, list[float]] = {name: [] for name in phases}
    for _ in range(args.rounds):
        for name, work in phases.items():
            repeats = 1 if name.startswith("tree") else 5
            start, start_cpu = time.perf_counter(), time.process_time()
            for _ in range(repeats):
                work()
            wall[name].append((time.perf_counter() - start) / repeats)
            cpu[name].append((time.process_time() - start_cpu) / repeats)
    print(
        f"SemanticColorAnnotator on {DATA.name}/{args.frame:06d}: {len(hypotheses)} hypotheses, "
        f"{sum(p.shape[0] for p, _ in picked)} picked pixels; {args.rounds} rounds, medians"
    )
    print(f"  {'phase':34s} {'wall ms':>8s} {'CPU ms':>8s}")
    print(f"  {'annotator in the tree (RunStats)':34s} {color.stats.median_seconds * 1e3:8.3f} {'':>8s}")
    for name in phases:
        print(f"  {name:34s} {statistics.median(wall[name]) * 1e3:8.3f} {statistics.median(cpu[name]) * 1e3:8.3f}")
    profile = cProfile.Profile()
    profile.enable()
    for _ in range(100):
        analyse_alone()
    profile.disable()
    print("\ncProfile of 100 runs of analyse(), by own time:")
    pstats.Stats(profile, stream=sys.stdout).sort_stats("tottime").print_stats(30)


if __name__ == "__main__":
    main()
