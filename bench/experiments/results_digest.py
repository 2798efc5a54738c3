"""A digest of what ``BeliefStore.integrate`` gives on bench frames, to show two trees give the same results (issue
19): an experiment, not a benchmark. Run it in each tree; equal digests mean equal steps and equal stores.

It seeds 10,000 beliefs as ``bench_beliefs.py`` does, integrates 150 frames at random places and 150 from 10 fixed
views, and hashes every step (each changed belief in full, its log-odds not rounded; assigned, created, missed, gone,
the association) and, at the end, every table of the store.

Run: ``PYTHONPATH=. .venv/bin/python bench/experiments/results_digest.py [--write-behind N]`` (``--write-behind``:
the store commits its frames in its writer process, up to N frames behind; the digest must not change).
"""

from __future__ import annotations

import argparse
import hashlib
import sqlite3
import sys
import tempfile
from pathlib import Path

import numpy as np

BENCH = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(BENCH))

import bench_beliefs as bench  # noqa: E402

from reasoning.beliefs.store import BeliefStore  # noqa: E402
from reasoning.fusion.frame import frame_objects  # noqa: E402
from reasoning.fusion.tracking import BeliefTracker, ObjectBelief  # noqa: E402

SLOW_TRIGGER = (
    "CREATE TRIGGER slow_writer AFTER INSERT ON observations BEGIN SELECT count(*) FROM (WITH RECURSIVE c(x) AS "
    "(SELECT 1 UNION ALL SELECT x + 1 FROM c WHERE x < 400) SELECT x FROM c); END"
)
"""Work in every sighting's insert (the digest hashes the tables, not the schema, so it does not change it)."""
TABLES = ("objects", "objects_place", "attribute_index", "observations", "classes", "interned", "meta", "views")


def belief_text(b: ObjectBelief) -> str:
    """Everything a belief holds, as text (arrays as lists, sets sorted)."""
    dimensions = None if b.dimensions is None else b.dimensions.tolist()
    appearance = None if b.appearance is None else b.appearance.tolist()
    supports = [
        (name, value, s.log_odds, s.count, sorted(s.sources), s.first_seen, s.last_seen)
        for name, attribute in b.attributes.items()
        for value, s in attribute.values.items()
    ]
    return repr(
        (b.id, b.frame, b.position.tolist(), b.orientation.tolist(), dimensions, appearance, supports,
         b.position_variance, b.existence, b.status, b.first_seen, b.last_seen, b.misses, b.region, b.region_class,
         b.roi, sorted(b.sources), b.observations, b.class_name, b.recording)
    )  # fmt: skip


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write-behind", type=int, default=0, help="frames the store may commit behind (0: off)")
    parser.add_argument(
        "--slow-writer",
        action="store_true",
        help="a trigger slows every sighting's insert, so the writer lags and every frame is fused on pending ones",
    )
    args = parser.parse_args()
    digest = hashlib.sha256()
    with tempfile.TemporaryDirectory() as name:
        path = Path(name) / "seed.sqlite"
        seeded = bench.seed_file(path, 10_000, np.random.default_rng(5), named_regions=False)
        rng = np.random.default_rng(7)
        views = bench.fixed_views(seeded, rng, 10, 20)
        frames = [frame_objects(bench.hypotheses_near(seeded, rng, 20)) for _ in range(150)]
        frames += [frame_objects(bench.hypotheses_near(seeded, rng, 20, views[k % 10])) for k in range(150)]
        if args.slow_writer:
            with sqlite3.connect(path) as conn:
                conn.execute(SLOW_TRIGGER)
        store = BeliefStore(path, tracker=BeliefTracker(class_test=bench.is_subclass),
                            write_behind=args.write_behind)  # fmt: skip
        for index, frame in enumerate(frames):
            step = store.integrate(frame, 1000.0 + index * 0.5)
            for belief in step.changed:
                digest.update(belief_text(belief).encode())
            digest.update(repr((step.assigned, step.created, step.missed, step.gone, step.association)).encode())
        store.close()
        conn = sqlite3.connect(path)
        for table in TABLES:
            rows = sorted(conn.execute(f"SELECT * FROM {table}").fetchall(), key=repr)
            digest.update(repr(rows).encode())
        conn.close()
    print(digest.hexdigest())
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
