"""CPU ms of the ClutterSegmenter's late steps per uoc frame: this checkout beside another git revision.

``python bench/bench_clutter_steps.py --reference REV`` segments frames 0-4 of ../shared/data/uoc_tabletop_realsense
with this checkout's :func:`~annotators.cloud.clutter.segment_clutter` and with REV's (exported with ``git archive``),
each in a worker process of its own, workers alternating; each step the segmenter calls by name (the piece joins,
the inner walls, the slabs, the container floors and the second piece join they may call for) is wrapped and timed
in CPU seconds (``time.process_time``: the least disturbed by other processes on a loaded machine), the least of the
rounds reported. "late" sums the steps after the first piece join: what the inner walls, slabs and floors cost.
"""

from __future__ import annotations

import argparse
import collections
import io
import json
import subprocess
import sys
import tarfile
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = (ROOT.parent / "shared" / "data" / "uoc_tabletop_realsense").resolve()
FRAMES = 5
STEPS = {
    "join_pieces": "pieces",
    "join_pieces_summarized": "pieces",
    "summarize_pieces": "summary",
    "join_inner_walls": "walls",
    "join_slab_pieces": "slabs",
    "claim_container_floors": "floors",
    "touches_other_labels": "touch",
}
"""The steps timed, by the name the segmenter calls them, and their columns (a piece join is #1 or #2 by order)."""
COLUMNS = ("segment", "pieces#1", "summary", "walls", "slabs", "floors", "touch", "pieces#2")


def worker(checkout: str, rounds: int) -> dict[str, list[float]]:
    """Least CPU ms per frame and column of ``rounds`` segmentations with the checkout's segmenter."""
    sys.path.insert(0, checkout)
    import numpy as np

    import annotators.cloud.clutter as clutter
    from annotators.cloud.filters import range_mask
    from annotators.cloud.plane import ransac_support_plane
    from annotators.cloud.point_cloud import back_project, pixel_rays
    from annotators.readers.frame_io import read_color_depth_pair

    inputs = []
    for index in range(FRAMES):
        frame = read_color_depth_pair(DATA, index)
        points = back_project(frame.depth, pixel_rays(frame.intrinsics))
        mask = range_mask(points, np.isfinite(points[..., 2]), 0.2, 2.5)
        fit = ransac_support_plane(points, mask)
        inputs.append((points, mask, fit.model, fit.inlier_indices, frame.color))
    times: dict[tuple[int, str], list[float]] = collections.defaultdict(list)
    current = {"frame": 0, "joins": 0}

    def timed(name: str, original: Callable[..., object]) -> Callable[..., object]:
        def call(*args: object, **kwargs: object) -> object:
            column = STEPS[name]
            if column == "pieces":
                current["joins"] += 1
                column = "pieces#1" if current["joins"] == 1 else "pieces#2"
            start = time.process_time()
            result = original(*args, **kwargs)
            times[(current["frame"], column)].append(time.process_time() - start)
            return result

        return call

    for name in STEPS:
        if hasattr(clutter, name):
            setattr(clutter, name, timed(name, getattr(clutter, name)))
    parameters = clutter.ClutterParameters()
    for round_index in range(rounds + 2):  # two rounds to warm up
        for index, (points, mask, model, plane, colors) in enumerate(inputs):
            current["frame"], current["joins"] = index, 0
            start = time.process_time()
            clutter.segment_clutter(points, mask, model, plane, parameters, colors)
            if round_index >= 2:
                times[(index, "segment")].append(time.process_time() - start)
    return {
        str(index): [min(times[(index, column)][-rounds:], default=0.0) * 1e3 for column in COLUMNS]
        for index in range(FRAMES)
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--reference", required=True, help="git revision timed beside this checkout")
    parser.add_argument("--rounds", type=int, default=12, help="segmentations of each frame per worker")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        print(json.dumps(worker(args.worker, args.rounds)))
        return
    with tempfile.TemporaryDirectory() as folder:
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", args.reference], check=True, capture_output=True)
        with tarfile.open(fileobj=io.BytesIO(archive.stdout)) as tar:
            tar.extractall(folder, filter="data")
        checkouts = {"ours": str(ROOT), args.reference: folder}
        best: dict[str, dict[str, list[float]]] = {}
        for _ in range(2):  # workers alternate
            for name, checkout in checkouts.items():
                command = [sys.executable, __file__, "--reference", args.reference, "--rounds", str(args.rounds)]
                output = subprocess.run([*command, "--worker", checkout], check=True, capture_output=True, text=True)
                found = json.loads(output.stdout)
                previous = best.get(name, found)
                best[name] = {key: [min(a, b) for a, b in zip(previous[key], found[key], strict=True)] for key in found}
    print(f"least CPU ms per step (rounds of {args.rounds}, twice each), this checkout / {args.reference}:")
    print("frame " + " ".join(f"{column:>15}" for column in (*COLUMNS, "late")))
    for index in range(FRAMES):
        ours, theirs = best["ours"][str(index)], best[args.reference][str(index)]
        cells = [*zip(ours, theirs, strict=True), (sum(ours[2:]), sum(theirs[2:]))]
        print(f"{index:5d} " + " ".join(f"{a:6.2f} / {b:6.2f}" for a, b in cells))


if __name__ == "__main__":
    main()
