"""Write-behind side by side (issue 19, store13): the same frames into fresh copies of one seeded store (10,000
objects, frames at random places) with write-behind 0, 1 and 2, the order alternating per round, then the recorded
writes replayed by the writer process alone and by plain ``executemany`` in this process. Prints wall and CPU
hypotheses/s (CPU of this process only: the writer's is not in it) and the load. An experiment, not a benchmark.

Run: ``PYTHONPATH=. .venv/bin/python bench/experiments/write_behind_modes.py [rounds]``
"""

from __future__ import annotations

import os
import shutil
import sqlite3
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import bench_beliefs as bench

from reasoning.beliefs.frame_writer import FrameWriter

PER_FRAME = 20


def writer_alone(path: Path, recorded: list) -> float:
    """Hypotheses/s of the writer process committing ``recorded`` (all sent, then every answer awaited)."""
    writer = FrameWriter(path, "NORMAL", 10.0, 4000)
    start = time.perf_counter()
    for seq, frame in enumerate(recorded):
        writer.send(seq, None, frame)
    for _ in recorded:
        writer.answer()
    elapsed = time.perf_counter() - start
    writer.close()
    return len(recorded) * PER_FRAME / elapsed


def main() -> int:
    rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 4
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        template = folder / "seed.sqlite"
        seeded = bench.seed_file(template, 10_000, np.random.default_rng(10_000), named_regions=False)
        rng = np.random.default_rng(1)
        prepared = [bench.hypotheses_near(seeded, rng, PER_FRAME) for _ in range(301)]
        for mode in (0, 1, 2):  # warm-up
            warm = folder / f"warm-{mode}.sqlite"
            shutil.copy(template, warm)
            bench.bench_store(warm, prepared[:1], False, mode)
        for round_index in range(rounds):
            figures = []
            for mode in (0, 1, 2) if round_index % 2 == 0 else (2, 1, 0):
                path = folder / f"round-{round_index}-{mode}.sqlite"
                shutil.copy(template, path)
                rates, _, _, recorded = bench.bench_store(path, prepared[1:], mode == 0, mode)
                figures.append(f"write-behind {mode}: wall {rates.wall:6.0f} cpu {rates.cpu:6.0f}")
                if mode == 0:
                    log = recorded
            plain = folder / f"plain-{round_index}.sqlite"
            shutil.copy(template, plain)
            reference = bench.bench_reference(plain, log, PER_FRAME)
            alone = folder / f"alone-{round_index}.sqlite"
            shutil.copy(template, alone)
            with sqlite3.connect(alone):
                pass
            figures.append(f"writes: executemany {reference.wall:6.0f}, writer process {writer_alone(alone, log):6.0f}")
            print(f"load {os.getloadavg()[0]:.2f} | " + " | ".join(sorted(figures)), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
