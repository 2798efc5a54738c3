"""Where a frame of ``BeliefStore.integrate`` goes, unprofiled: CPU ms per frame of each phase and of each SQL
statement (issue 19, goal 1). An experiment, not a benchmark with a goal: it prints figures to compare trees.

Phases are timed by wrapping the store's and the tracker's methods for the run (restored afterwards); SQL by a
connection wrapper that times each ``execute``/``executemany`` (the candidate query's ``fetchall`` included) by the
statement's first words. Frames as in ``bench_beliefs.py`` (20 hypotheses, at random places or from fixed cameras).

Run: ``PYTHONPATH=. .venv/bin/python bench/experiments/integrate_phases.py [--size N] [--frames N] [--cameras N]``
"""

from __future__ import annotations

import argparse
import shutil
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np

BENCH = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(BENCH))

import bench_beliefs as bench  # noqa: E402

from reasoning.beliefs import store as store_module  # noqa: E402
from reasoning.beliefs.store import BeliefStore  # noqa: E402
from reasoning.fusion.frame import frame_objects  # noqa: E402
from reasoning.fusion.tracking import BeliefTracker  # noqa: E402

try:  # the row-level update (store8 and later); the phases of a tree without it are skipped
    from reasoning.beliefs.row_update import RowUpdate
except ImportError:  # pragma: no cover - an older tree
    RowUpdate = None  # type: ignore[assignment,misc]

PHASES: tuple[tuple[object, str, str], ...] = (
    (BeliefStore, "integrate", "integrate (all)"),
    (BeliefStore, "_candidates", "candidate search"),
    (store_module, "_belief_from_row", "  of it: decoding rows"),
    (BeliefTracker, "step", "tracker.step"),
    (BeliefStore, "_step_on_rows", "tracker step on rows"),
    (RowUpdate, "supports", "  of it: supports unpacked"),
    (BeliefTracker, "associate", "  of it: association"),
    (BeliefTracker, "_associate", "  of it: association"),  # its name before store9
    (BeliefTracker, "update", "  of it: updates (general)"),
    (BeliefTracker, "_update", "  of it: updates (general)"),  # its name before store9
    (RowUpdate, "update", "  of it: updates (on rows)"),
    (BeliefStore, "_write_beliefs", "object rows written (general)"),
    (store_module, "_object_row", "  of it: building rows"),
    (RowUpdate, "pack", "supports packed (on rows)"),
    (BeliefStore, "_write_rows", "object rows written"),
    (BeliefStore, "_write_observations", "sightings written"),
)
"""(owner, method, label) of each timed phase; a phase whose owner or method a tree lacks is left out."""


class _Fetched:
    """The rows of a cursor, fetched while timed."""

    def __init__(self, rows: list[tuple]) -> None:
        self._rows = rows

    def fetchall(self) -> list[tuple]:
        return self._rows

    def fetchone(self) -> tuple | None:
        return self._rows[0] if self._rows else None

    def __iter__(self) -> Iterator[tuple]:
        return iter(self._rows)


class _TimedConnection:
    """An ``sqlite3.Connection`` whose statements are timed (CPU ns, by the first 40 characters)."""

    def __init__(self, connection: Any, totals: dict[str, int]) -> None:
        self._connection = connection
        self._totals = totals

    def execute(self, statement: str, *parameters: Any) -> Any:
        start = time.process_time_ns()
        result = _Fetched(self._connection.execute(statement, *parameters).fetchall())
        self._note(statement, start)
        return result

    def executemany(self, statement: str, rows: Any) -> Any:
        start = time.process_time_ns()
        result = self._connection.executemany(statement, rows)
        self._note(statement, start)
        return result

    def _note(self, statement: str, start: int) -> None:
        key = " ".join(statement.split())[:40]
        self._totals[key] = self._totals.get(key, 0) + time.process_time_ns() - start

    def __getattr__(self, name: str) -> Any:
        return getattr(self._connection, name)


@contextmanager
def timed_phases(totals: dict[str, int]) -> Iterator[None]:
    """Wrap the methods of :data:`PHASES` so each adds its CPU ns to ``totals`` (restored on exit)."""
    originals = []
    for owner, name, label in PHASES:
        original = getattr(owner, name, None)
        if original is None:
            continue
        originals.append((owner, name, original))
        setattr(owner, name, _timed(original, label, totals))
    try:
        yield
    finally:
        for owner, name, original in originals:
            setattr(owner, name, original)


def _timed(function: Callable[..., Any], label: str, totals: dict[str, int]) -> Callable[..., Any]:
    def timed(*args: Any, **kwargs: Any) -> Any:
        start = time.process_time_ns()
        try:
            return function(*args, **kwargs)
        finally:
            totals[label] = totals.get(label, 0) + time.process_time_ns() - start

    return timed


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=10_000)
    parser.add_argument("--frames", type=int, default=300)
    parser.add_argument("--cameras", type=int, default=30)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        template = folder / "seed.sqlite"
        seeded = bench.seed_file(template, args.size, np.random.default_rng(args.size), named_regions=False)
        for cameras in (0, args.cameras):
            rng = np.random.default_rng(1)
            views = bench.fixed_views(seeded, rng, cameras, 20) if cameras else []
            frames = [
                frame_objects(bench.hypotheses_near(seeded, rng, 20, views[k % len(views)] if views else None))
                for k in range(args.frames + 1)
            ]
            path = folder / f"run-{cameras}.sqlite"
            shutil.copy(template, path)
            store = BeliefStore(path, tracker=BeliefTracker(class_test=bench.is_subclass))
            store.integrate(frames[0], 999.0)
            phases: dict[str, int] = {}
            statements: dict[str, int] = {}
            store._conn = _TimedConnection(store._conn, statements)  # type: ignore[assignment]
            with timed_phases(phases):
                for index, frame in enumerate(frames[1:]):
                    store.integrate(frame, 1000.0 + index)
            store.close()
            where = f"from {cameras} fixed cameras in turn" if cameras else "each at a random place"
            print(f"{args.size} stored, {args.frames} frames x 20 hypotheses {where}: CPU ms per frame")
            for label in dict.fromkeys(label for _, _, label in PHASES):  # a label twice: a method renamed
                print(f"  {label:32s} {phases.get(label, 0) / args.frames / 1e6:7.3f}")
            sql = sum(statements.values())
            print(f"  {'SQL (all statements)':32s} {sql / args.frames / 1e6:7.3f}")
            for statement, spent in sorted(statements.items(), key=lambda item: -item[1]):
                print(f"    {spent / args.frames / 1e6:7.3f}  {statement}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
