"""A worker for side-by-side timing: the tabletop tree of one checkout, ticked on request, in its own process.

``python bench/tick_tree.py CHECKOUT DATA FRAME [SCENE]`` imports ``trees.tabletop`` from CHECKOUT (so another
checkout of the project - the tree before a change - can be timed against this one in the same run), builds the tree
on frame FRAME of the recording DATA, ticks it three times to warm up and prints ``ready``. Each line ``N`` read from
stdin then ticks it N times and answers one JSON line: the wall and CPU seconds of each tick, each annotator's
seconds per tick (``experts``) and the hypotheses found. With SCENE (an ``.npz`` holding organized ``points`` and
``colors``), a line ``segment N`` runs that checkout's clutter segmentation on it N times (the plane fitted once)
and answers the wall and CPU seconds of each segmentation and the segments found.
"""

from __future__ import annotations

import json
import sys
import time


def main() -> None:
    checkout, data, frame = sys.argv[1], sys.argv[2], int(sys.argv[3])
    scene_path = sys.argv[4] if len(sys.argv) > 4 else None
    sys.path.insert(0, checkout)
    import numpy as np

    from annotators.cloud.clutter import ClutterParameters, segment_clutter
    from annotators.cloud.filters import range_mask
    from annotators.cloud.plane import ransac_support_plane
    from robokudo.core.annotator import Annotator
    from robokudo.core.engine import Engine
    from robokudo.core.types import ObjectHypothesis
    from trees.tabletop import create_tree

    root = create_tree(data, frame)
    engine = Engine(root, hz=1000.0)
    for _ in range(3):
        engine.tick()
    annotators = [node for node in root.iterate() if isinstance(node, Annotator)]
    scene = np.load(scene_path) if scene_path else None
    print("ready", flush=True)
    for line in sys.stdin:
        command = line.split()
        if command[0] == "segment" and scene is not None:
            points, colors = scene["points"], scene["colors"]
            mask = range_mask(points, np.isfinite(points[..., 2]), 0.2, 2.5)
            fit = ransac_support_plane(points, mask)
            wall, cpu, found = [], [], 0
            for _ in range(int(command[1])):
                start, start_cpu = time.perf_counter(), time.process_time()
                found = len(segment_clutter(points, mask, fit.model, fit.inlier_indices, ClutterParameters(), colors))
                wall.append(time.perf_counter() - start)
                cpu.append(time.process_time() - start_cpu)
            print(json.dumps({"wall": wall, "cpu": cpu, "segments": found}), flush=True)
            continue
        wall, cpu = [], []
        experts: dict[str, list[float]] = {node.name: [] for node in annotators}
        for _ in range(int(command[0])):
            start, start_cpu = time.perf_counter(), time.process_time()
            engine.tick()
            wall.append(time.perf_counter() - start)
            cpu.append(time.process_time() - start_cpu)
            for node in annotators:
                experts[node.name].append(node.stats.last_seconds)
        found = len(root.cas.annotations(ObjectHypothesis))
        print(json.dumps({"wall": wall, "cpu": cpu, "experts": experts, "hypotheses": found}), flush=True)


if __name__ == "__main__":
    main()
