"""What a row-level hot path would save per matched belief (issue 19, goal 1): an experiment, not a benchmark.

``BeliefStore.integrate`` decodes each candidate row into an ``ObjectBelief`` (``_belief_from_row``), the tracker
updates it (``BeliefTracker.update``) and the store encodes it again (``_object_row``). This script captures the
(stored row, observation, time) of every update of bench frames and computes the new row two ways:

* reference: decode + ``update`` + ``_object_row``, as ``integrate`` does;
* row level: the packed supports unpacked to records, the frame's statements accumulated into them with the rule of
  ``ValueSupport.add``, the position filtered and the size blended with Python floats, the records packed again,
  with no ``ObjectBelief``, ``AttributeBelief``, ``ValueSupport``, set or numpy array made. It covers the common
  case only (no appearance, every attribute single-valued, no regions on the tracker) and says how many updates
  fell outside it (those are not timed).

Both must give the same row (checked for every update); it prints the CPU us per update of each. The difference
bounds what a hot path without per-belief objects could save in pure Python (association, candidate search,
sightings and SQL unchanged).

Run: ``PYTHONPATH=. .venv/bin/python bench/experiments/row_level_update.py [--size N] [--frames N]``
"""

from __future__ import annotations

import argparse
import functools
import json
import shutil
import sqlite3
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(BENCH))

import bench_beliefs as bench  # noqa: E402

from reasoning.beliefs import packed as packed_forms  # noqa: E402
from reasoning.beliefs import store as store_module  # noqa: E402
from reasoning.beliefs.interned import InternedTexts  # noqa: E402
from reasoning.beliefs.store import BeliefStore  # noqa: E402
from reasoning.fusion.frame import FrameObject, frame_objects  # noqa: E402
from reasoning.fusion.rule import CLASS_ATTRIBUTE, MAX_LOG_ODDS, logit  # noqa: E402
from reasoning.fusion.tracking import BeliefTracker  # noqa: E402
from robokudo.core.types import Location  # noqa: E402


class GeneralTracker(BeliefTracker):
    """The plain tracker, which ``integrate`` runs the general way (decode, ``update``, encode): since store8 the
    plain ``BeliefTracker`` has its common-case updates done on the rows (``reasoning/beliefs/row_update.py``)."""


Update = tuple[tuple, FrameObject, float]
"""A stored row, the observation matched to it and the frame's time."""


def captured_updates(store: BeliefStore, frames: list[list[FrameObject]]) -> list[Update]:
    """Integrate ``frames`` and return every (row as loaded, observation, time) the tracker updated."""
    rows: dict[int, tuple] = {}
    updates: list[Update] = []
    decode, update = store_module._belief_from_row, BeliefTracker.update

    def remember_row(row: tuple, *args: object) -> object:
        rows[row[0]] = row
        return decode(row, *args)  # type: ignore[arg-type]

    def remember_update(tracker: BeliefTracker, belief: object, observation: FrameObject, at: float) -> None:
        updates.append((rows[belief.id], observation, at))  # type: ignore[attr-defined]
        update(tracker, belief, observation, at)  # type: ignore[arg-type]

    store_module._belief_from_row = remember_row  # type: ignore[assignment]
    BeliefTracker.update = remember_update  # type: ignore[assignment,method-assign]
    try:
        for index, frame in enumerate(frames):
            store.integrate(frame, 1000.0 + index)
    finally:
        store_module._belief_from_row = decode
        BeliefTracker.update = update  # type: ignore[method-assign]
    return updates


class RowLevel:
    """The common case of ``update`` + ``_object_row`` computed on the stored row (see the module docstring)."""

    def __init__(self, tracker: BeliefTracker, interned: InternedTexts, conn: sqlite3.Connection) -> None:
        self.config = tracker.config
        self.interned = interned
        self.conn = conn
        self.unions: dict[tuple[int, str], int] = {}
        self.sources: dict[tuple[str, frozenset[str]], str] = {}
        self.write = functools.partial(store_module._write, conn, [])

    def covers(self, row: tuple, observation: FrameObject) -> bool:
        """True when the update is the common case this sketch handles."""
        if row[14] is not None or observation.appearance is not None or observation.dimensions is None:
            return False
        names = [r[0] for r in packed_forms.SUPPORT.iter_unpack(row[26])]
        if len(set(names)) != len(names):
            return False
        stated: dict[str, str] = {}
        for e in observation.evidence:
            if stated.setdefault(e.attribute, e.value) != e.value:
                return False
        texts = self.interned.texts
        values = {texts[r[0]]: texts[r[1]] for r in packed_forms.SUPPORT.iter_unpack(row[26])}
        return all(values.get(name, value) == value for name, value in stated.items())

    def row(self, row: tuple, observation: FrameObject, at: float) -> tuple:
        """The new ``objects`` row of ``row`` updated by ``observation`` at ``at``."""
        (object_id, _, frame, px, py, pz, _, _, _, _, sx, sy, sz, variance, appearance, existence, _, first_seen,
         last_seen, _, observations, _, _, recording, _, sources, packed, _) = row[:28]  # fmt: skip
        interned, conn, write = self.interned, self.conn, self.write
        codes = interned.codes
        records = [list(r) for r in packed_forms.SUPPORT.iter_unpack(packed)]
        by_name = {r[0]: r for r in records}
        for e in observation.evidence:
            name = codes.get(e.attribute)
            if name is None:
                name = interned.code(conn, e.attribute, write)
            r = by_name.get(name)
            if r is None:
                value = codes.get(e.value)
                if value is None:
                    value = interned.code(conn, e.value, write)
                r = by_name[name] = [name, value, 0.0, 0, interned.experts_code(conn, set(), write), at, at]
                records.append(r)
            if r[3] == 0 or at < r[5]:
                r[5] = at
            total = r[2] + logit(e.confidence)
            total = -MAX_LOG_ODDS if total < -MAX_LOG_ODDS else total
            r[2] = MAX_LOG_ODDS if total > MAX_LOG_ODDS else total
            r[3] += 1
            key = (r[4], e.source)
            union = self.unions.get(key)
            if union is None:
                union = self.unions[key] = interned.experts_code(conn, {*interned.experts(conn, r[4]), e.source}, write)
            r[4] = union
            if r[6] < at:
                r[6] = at
        config = self.config
        predicted = variance + config.motion_sigma**2 * max(at - last_seen, 0.0)
        gain = predicted / (predicted + config.measurement_sigma**2 / max(observation.confidence, 0.1))
        x, y, z = observation.position.tolist()
        rate = config.blend_rate
        a, b, c = observation.dimensions.tolist()  # type: ignore[union-attr]
        if sx is not None:
            a, b, c = (1.0 - rate) * sx + rate * a, (1.0 - rate) * sy + rate * b, (1.0 - rate) * sz + rate * c
        texts = interned.texts
        flat: list = []
        entries = []
        named: dict[str, tuple[str, float]] = {}
        for r in records:
            flat += r
            log_odds = r[2]
            flat[-5] = packed_forms.rounded_cached(log_odds, 9) if log_odds else round(log_odds, 9)
            name, value = texts[r[0]], texts[r[1]]
            named[name] = (value, log_odds)
            entries.append(f"{name}={value}")
        class_value = named.get(CLASS_ATTRIBUTE)
        stated_sources = frozenset(observation.sources)
        text = self.sources.get((sources, stated_sources))
        if text is None:
            merged = sorted({*json.loads(sources), *stated_sources})
            text = self.sources[(sources, stated_sources)] = json.dumps(merged)
        return (
            object_id,
            class_value[0] if class_value is not None and class_value[1] > 0 else None,
            frame,
            px + gain * (x - px),
            py + gain * (y - py),
            pz + gain * (z - pz),
            *observation.orientation.tolist(),
            a,
            b,
            c,
            (1.0 - gain) * predicted,
            appearance,
            min(existence + config.hit_log_odds, MAX_LOG_ODDS),
            "present",
            first_seen,
            max(last_seen, at),
            0,
            observations + 1,
            named.get(Location.attribute, ("",))[0],
            "",
            recording,
            packed_forms.roi_text(observation.roi),
            text,
            packed_forms.supports_packing(len(records)).pack(*flat),
            packed_forms.INDEX_SEPARATOR.join(sorted(entries)),
        )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=10_000)
    parser.add_argument("--frames", type=int, default=300)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        template = folder / "seed.sqlite"
        seeded = bench.seed_file(template, args.size, np.random.default_rng(args.size), named_regions=False)
        rng = np.random.default_rng(1)
        frames = [frame_objects(bench.hypotheses_near(seeded, rng, 20)) for _ in range(args.frames)]
        path = folder / "run.sqlite"
        shutil.copy(template, path)
        tracker = GeneralTracker(class_test=bench.is_subclass)  # the general way: every update is captured
        store = BeliefStore(path, tracker=tracker)
        updates = captured_updates(store, frames)
        conn, interned = store._conn, store._interned
        sketch = RowLevel(tracker, interned, conn)
        covered = [u for u in updates if sketch.covers(u[0], u[1])]
        write = functools.partial(store_module._write, conn, [])
        cache = store._sources_cache()

        def reference(row: tuple, observation: FrameObject, at: float) -> tuple:
            belief = store_module._belief_from_row(row, interned, conn)
            tracker.update(belief, observation, at)
            return store_module._object_row(belief, tracker.class_test, cache, interned, conn, write)

        conn.execute("BEGIN IMMEDIATE")  # codes interned by the sketch are rolled back
        try:
            differ = sum(1 for u in covered if reference(*u) != sketch.row(*u))
            timings = {"reference": 0, "row level": 0}
            for _ in range(3):
                for label, compute in (("reference", reference), ("row level", sketch.row)):
                    start = time.process_time_ns()
                    for update in covered:
                        compute(*update)
                    timings[label] += time.process_time_ns() - start
        finally:
            conn.execute("ROLLBACK")
            store.close()
        print(f"{len(updates)} updates of {args.frames} frames ({args.size} stored); {len(covered)} in the common case")
        print(f"  rows that differ between the two ways: {differ}")
        for label, spent in timings.items():
            print(f"  {label:10s} {spent / 3 / max(len(covered), 1) / 1000:6.2f} us CPU per update")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
