"""Which pages one ``BeliefStore.integrate`` commit writes to the WAL, by table and index (issue 19, goal 1): an
experiment, not a benchmark. Each page in the WAL costs a write at COMMIT, so this says what a change of the
layout (fewer indexes touched per update, another sightings layout) could save.

It seeds a store as ``bench_beliefs.py`` does, integrates warm-up frames at random places, checkpoints, integrates
``--frames`` more, then reads the WAL's frame headers (page numbers) and names each page's owner with SQLite's
``dbstat`` table. Pages per commit of each owner are printed.

Run: ``PYTHONPATH=. .venv/bin/python bench/experiments/wal_pages.py [--size N] [--frames N]``
"""

from __future__ import annotations

import argparse
import collections
import sqlite3
import struct
import sys
import tempfile
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(BENCH))

import bench_beliefs as bench  # noqa: E402

from reasoning.beliefs.store import BeliefStore  # noqa: E402
from reasoning.fusion.frame import frame_objects  # noqa: E402
from reasoning.fusion.tracking import BeliefTracker  # noqa: E402

WAL_HEADER, FRAME_HEADER = 32, 24


def wal_pages(wal: Path, page_size: int) -> list[tuple[int, bool]]:
    """(page number, ends a commit) of every frame in a WAL file."""
    data = wal.read_bytes()
    frames = []
    offset = WAL_HEADER
    while offset + FRAME_HEADER + page_size <= len(data):
        page, size_after_commit = struct.unpack(">II", data[offset : offset + 8])
        frames.append((page, size_after_commit != 0))
        offset += FRAME_HEADER + page_size
    return frames


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=10_000)
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--warm-up", type=int, default=100)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as name:
        path = Path(name) / "seed.sqlite"
        seeded = bench.seed_file(path, args.size, np.random.default_rng(args.size), named_regions=False)
        rng = np.random.default_rng(1)
        frames = [frame_objects(bench.hypotheses_near(seeded, rng, 20)) for _ in range(args.warm_up + args.frames)]
        store = BeliefStore(path, tracker=BeliefTracker(class_test=bench.is_subclass))
        for index, frame in enumerate(frames[: args.warm_up]):
            store.integrate(frame, 1000.0 + index)
        store._conn.execute("PRAGMA wal_checkpoint(TRUNCATE)")
        for index, frame in enumerate(frames[args.warm_up :]):
            store.integrate(frame, 2000.0 + index)
        conn = sqlite3.connect(path)
        page_size = int(conn.execute("PRAGMA page_size").fetchone()[0])
        frames_written = wal_pages(Path(f"{path}-wal"), page_size)
        owner = dict((page, table) for table, page in conn.execute("SELECT name, pageno FROM dbstat"))
        conn.close()
        store.close()
    commits = sum(1 for _, ends in frames_written if ends)
    counts = collections.Counter(owner.get(page, "?") for page, _ in frames_written)
    print(f"{args.size} stored, {commits} commits: {len(frames_written) / commits:.1f} WAL pages per commit")
    for table, count in counts.most_common():
        print(f"  {table:28s} {count / commits:5.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
