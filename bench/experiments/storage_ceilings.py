"""Ceilings of ``BeliefStore.integrate`` by storage mode (issue 19, goal 1): an experiment, not a benchmark.

The same frames are integrated into fresh copies of one seeded store, the modes alternating per round:

* ``wal``: the store as it ships (WAL, ``synchronous=NORMAL``);
* ``cache``: ``wal`` with a page cache of 256 MiB (the default is 2 MiB);
* ``no-object-index``: ``wal`` without the index ``attribute_index_object`` and without the statement that needs it
  (the delete of a new belief's entries by object id, which finds none in these frames): what dropping it saves
  (store12 built that with deletes by key, schema 4, and measured it: see bench/profiles/store12-analysis.txt);
* ``memory``: the seeded file copied into an in-memory SQLite database (``Connection.backup``): no file I/O at all,
  what is left is SQLite's C work and Python;
* ``memory+log``: ``memory`` plus one ``os.write`` per frame of the frame's write log (``marshal``), the least a
  durable append-only frame log would add (no fold into the file);
* ``mmap``: ``wal`` with the file read through a memory map (``PRAGMA mmap_size``) instead of ``pread``;
* ``memory+log+fold``: ``memory+log`` plus the fold: every :data:`FOLD_FRAMES` frames (and after the last) the
  frames' write logs replayed on the file (WAL, ``executemany``) in one transaction: the whole of such a design's
  work (its recovery aside), inside the measured time;
* ``off``: on disk with ``journal_mode=OFF`` and ``synchronous=OFF`` (no durability, no journal);
* ``floor``: the write log of the ``wal`` run replayed by plain ``sqlite3`` ``executemany`` (as bench_beliefs.py).

Rates are hypotheses/s in CPU time of the process and in wall time; medians over rounds, with per-round ratios.

Run: ``PYTHONPATH=. .venv/bin/python bench/experiments/storage_ceilings.py [--sizes N ...] [--frames N]``
"""

from __future__ import annotations

import argparse
import marshal
import os
import shutil
import sqlite3
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(BENCH))

import bench_beliefs as bench  # noqa: E402

import reasoning.beliefs.store as store_module  # noqa: E402
from reasoning.beliefs.store import BeliefStore  # noqa: E402
from reasoning.fusion.frame import FrameContext, FrameObject, frame_objects  # noqa: E402
from reasoning.fusion.tracking import BeliefTracker  # noqa: E402

MODES = ("wal", "mmap", "cache", "no-object-index", "memory", "memory+log", "memory+log+fold", "off")


_WRITE = store_module._write
_OBJECT_DELETE = "DELETE FROM attribute_index WHERE object_id = ?"


def _without_object_deletes(conn: sqlite3.Connection, log: list, statement: str, rows: list[tuple]) -> None:
    """The store's ``_write``, skipping the deletes by object id (mode ``no-object-index``)."""
    if statement != _OBJECT_DELETE:
        _WRITE(conn, log, statement, rows)


FOLD_FRAMES = 50
"""Frames per fold of mode ``memory+log+fold``."""


def _remove(path: Path) -> None:
    for suffix in ("", "-wal", "-shm", "-log"):
        Path(f"{path}{suffix}").unlink(missing_ok=True)


def open_store(path: Path, mode: str) -> tuple[BeliefStore, Callable[[bool], None]]:
    """The store on ``path`` in ``mode`` and what to call after each integrate (the frame log's write and the fold;
    its argument: the last frame)."""
    store = BeliefStore(path, tracker=BeliefTracker(class_test=bench.is_subclass))
    after: Callable[[bool], None] = lambda last: None  # noqa: E731
    if mode in ("memory", "memory+log", "memory+log+fold"):
        memory = sqlite3.connect(":memory:", isolation_level=None, check_same_thread=False)
        store._conn.backup(memory)
        store._conn.close()
        store._conn = memory
    if mode in ("memory+log", "memory+log+fold"):
        store.write_log = []
        fd = os.open(f"{path}-log", os.O_WRONLY | os.O_CREAT | os.O_APPEND, 0o644)
        log = store.write_log
        fold = mode == "memory+log+fold"
        disk = sqlite3.connect(path, isolation_level=None) if fold else None

        def after(last: bool) -> None:
            frame = log.pop() if not fold else log[-1]
            record = marshal.dumps(frame)
            os.write(fd, len(record).to_bytes(4, "little") + record)
            if disk is not None and (len(log) >= FOLD_FRAMES or last):
                disk.execute("BEGIN IMMEDIATE")
                for writes in log:
                    for statement, rows in writes:
                        disk.executemany(statement, rows)
                disk.execute("COMMIT")
                log.clear()
            if last:
                os.close(fd)
                if disk is not None:
                    disk.close()

    if mode == "mmap":
        store._conn.execute("PRAGMA mmap_size = 1073741824")
    if mode == "cache":
        store._conn.execute("PRAGMA cache_size = -262144")
    if mode == "no-object-index":
        store._conn.execute("DROP INDEX attribute_index_object")
    if mode == "off":
        store._conn.execute("PRAGMA journal_mode = OFF")
        store._conn.execute("PRAGMA synchronous = OFF")
    return store, after


def run(path: Path, mode: str, frames: list[list[FrameObject]], record: bool) -> tuple[float, float, list]:
    """Seconds of CPU and wall over the frames' integrate calls (the first frame is a warm-up), and the write log."""
    store, after = open_store(path, mode)
    if mode == "no-object-index":
        store_module._write = _without_object_deletes
    if record:
        store.write_log = []
    store.integrate(frames[0], 999.0)
    if record:
        store.write_log.clear()
    cpu = wall = 0.0
    for index, objects in enumerate(frames[1:]):
        c0, w0 = time.process_time(), time.perf_counter()
        store.integrate(objects, 1000.0 + index)
        after(index == len(frames) - 2)
        cpu += time.process_time() - c0
        wall += time.perf_counter() - w0
    log = list(store.write_log or []) if record else []
    store_module._write = _WRITE
    store.close()
    return cpu, wall, log


def floor(path: Path, log: list) -> tuple[float, float]:
    """CPU and wall seconds of replaying ``log`` with plain executemany, one transaction per frame."""
    conn = sqlite3.connect(path, isolation_level=None)
    conn.execute("PRAGMA journal_mode = WAL")
    conn.execute(f"PRAGMA synchronous = {bench.SYNCHRONOUS}")
    c0, w0 = time.process_time(), time.perf_counter()
    for frame in log:
        conn.execute("BEGIN IMMEDIATE")
        for statement, rows in frame:
            conn.executemany(statement, rows)
        conn.execute("COMMIT")
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    conn.close()
    return cpu, wall


TABLES = ("objects", "objects_place", "attribute_index", "observations", "classes", "interned", "meta")


def check_fold(folder: Path, frames: int) -> bool:
    """Whether the file the fold wrote holds the same tables as the store on WAL after the same frames (10,000
    stored, random places)."""
    template = folder / "check.sqlite"
    seeded = bench.seed_file(template, 10_000, np.random.default_rng(10_000), named_regions=False)
    rng = np.random.default_rng(1)
    prepared = [
        frame_objects(bench.hypotheses_near(seeded, rng, 20), FrameContext(time=float(k))) for k in range(frames)
    ]
    tables = []
    for mode in ("wal", "memory+log+fold"):
        path = folder / f"check-{mode}.sqlite"
        shutil.copy(template, path)
        run(path, mode, prepared, record=False)
        conn = sqlite3.connect(path)
        tables.append([sorted(conn.execute(f"SELECT * FROM {name}").fetchall(), key=repr) for name in TABLES])
        conn.close()
    return tables[0] == tables[1]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="*", default=[10_000, 100_000])
    parser.add_argument("--frames", type=int, default=200)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--cameras", type=int, default=30)
    parser.add_argument("--modes", nargs="*", default=list(MODES), choices=MODES)
    parser.add_argument("--check-fold", action="store_true", help="only check that the fold writes the same tables")
    args = parser.parse_args()
    if args.check_fold:
        with tempfile.TemporaryDirectory() as name:
            same = check_fold(Path(name), args.frames)
        print(f"fold after {args.frames} frames: {'the same tables as on WAL' if same else 'OTHER TABLES than on WAL'}")
        return 0 if same else 1
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        for size in args.sizes:
            template = folder / f"seed-{size}.sqlite"
            seeded = bench.seed_file(template, size, np.random.default_rng(size), named_regions=False)
            for cameras in (0, args.cameras):
                rng = np.random.default_rng(1)
                views = bench.fixed_views(seeded, rng, cameras, 20) if cameras else []
                frames = [
                    frame_objects(
                        bench.hypotheses_near(seeded, rng, 20, views[k % len(views)] if views else None),
                        FrameContext(time=float(k)),
                    )
                    for k in range(args.frames + 1)
                ]
                count = args.frames * 20
                modes = tuple(m for m in MODES if m in args.modes or m == "wal")
                cpu: dict[str, list[float]] = {m: [] for m in (*modes, "floor")}
                wall: dict[str, list[float]] = {m: [] for m in (*modes, "floor")}
                for round_ in range(args.rounds):
                    order = modes if round_ % 2 == 0 else tuple(reversed(modes))
                    path = folder / "trial.sqlite"
                    _remove(path)
                    shutil.copy(template, path)
                    run(path, order[0], frames[:50], record=False)  # the first run of a round reads slow: not kept
                    for mode in order:
                        path = folder / "trial.sqlite"
                        _remove(path)
                        shutil.copy(template, path)
                        c, w, log = run(path, mode, frames, record=mode == "wal")
                        cpu[mode].append(count / c)
                        wall[mode].append(count / w)
                        if mode == "wal":
                            _remove(path)
                            shutil.copy(template, path)
                            fc, fw = floor(path, log)
                            cpu["floor"].append(count / fc)
                            wall["floor"].append(count / fw)
                        _remove(path)
                where = f"{cameras} fixed cameras" if cameras else "random places"
                print(f"{size} stored, {where}, {args.frames} frames x 20, {args.rounds} rounds "
                      f"(load {os.getloadavg()[0]:.2f}):")  # fmt: skip
                for mode in (*modes, "floor"):
                    ratios = [m / b for m, b in zip(cpu[mode], cpu["wal"], strict=True)]
                    print(
                        f"  {mode:11s} cpu {statistics.median(cpu[mode]):8.0f}/s  wall "
                        f"{statistics.median(wall[mode]):8.0f}/s  cpu / wal per round "
                        + " ".join(f"{r:.2f}" for r in ratios)
                    )
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
