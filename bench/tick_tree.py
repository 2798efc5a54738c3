"""A worker for side-by-side timing: the tabletop tree of one checkout, ticked on request, in its own process.

``python bench/tick_tree.py CHECKOUT DATA FRAME`` imports ``trees.tabletop`` from CHECKOUT (so another checkout of
the project - the tree before a change - can be timed against this one in the same run), builds the tree on frame
FRAME of the recording DATA, ticks it three times to warm up and prints ``ready``. Each line ``N`` read from stdin
then ticks it N times and answers one JSON line: the wall and CPU seconds of each tick, each annotator's seconds
per run in those ticks (from its RunStats) and the hypotheses found.
"""

from __future__ import annotations

import json
import sys
import time


def main() -> None:
    checkout, data, frame = sys.argv[1], sys.argv[2], int(sys.argv[3])
    sys.path.insert(0, checkout)
    from robokudo.core.engine import Engine
    from robokudo.core.stats import RunStats
    from robokudo.core.types import ObjectHypothesis
    from trees.tabletop import create_tree

    root = create_tree(data, frame)
    engine = Engine(root, hz=1000.0)
    for _ in range(3):
        engine.tick()
    print("ready", flush=True)
    for line in sys.stdin:
        for node in root.iterate():
            if hasattr(node, "stats"):
                node.stats = RunStats()  # only this request's runs
        wall, cpu = [], []
        for _ in range(int(line)):
            start, start_cpu = time.perf_counter(), time.process_time()
            engine.tick()
            wall.append(time.perf_counter() - start)
            cpu.append(time.process_time() - start_cpu)
        found = len(root.cas.annotations(ObjectHypothesis))
        nodes = {name: list(stats.samples) for name, stats in engine.annotator_stats().items()}
        print(json.dumps({"wall": wall, "cpu": cpu, "nodes": nodes, "hypotheses": found}), flush=True)


if __name__ == "__main__":
    main()
