"""Benchmark of the belief store (issue 19): update throughput, memory-query latency and resident memory.

Parts, each printing its goal and whether it is met:

* updates: hypotheses per second integrated (``BeliefStore.integrate``: candidate search, association, attribute
  fusion, one transaction per frame; 20 hypotheses per frame) into stores of 10,000 and 100,000 objects, side by
  side with the floor of this storage design: the very statements and rows the store wrote for each frame
  (``BeliefStore.write_log``: the changed columns of known objects, new objects, moved R*Tree entries,
  attribute-index changes, sightings, the next id, gone marks) replayed by plain ``sqlite3`` ``executemany`` in
  one transaction per frame on a copy of the same store; when the store's design changes, the floor changes with
  it. Trials alternate store / reference; the median trial is the figure. Goal: >= 20,000 hypotheses/s, of a
  store with write-behind 1 (``--write-behind``, 0: the store as shipped; the fusion in this process, one
  transaction per frame committed by the store's writer process, timed to the last commit), each trial
  alternating with the store as shipped (write-behind off, printed beside it); the ratio to the reference is
  printed beside it, and both rates in CPU time of the process too (on a shared, loaded machine wall time mostly
  measures waiting for a core). ``frame_objects`` + integrate (from the
  experts' hypotheses) is printed too. The update stores are seeded without region names, as this tracker
  (which has no regions) stores its beliefs; with them, the first sighting of each seeded belief would rename its
  region (an index rewrite that only seeding causes).
* queries: median and p95 latency of memory queries, to beliefs and to designators, with 10,000 and 1,000,000
  objects stored. The world grows with the store (one object per square metre, rooms of about 500 objects), so
  a query's answer stays about the same size. Goals: median to designators <= 1 ms (10,000) and <= 10 ms
  (1,000,000). The large stores are seeded with ``executemany`` of rows encoded like the store's own.
* memory: resident memory of a fresh process that opens a store of 100,000 beliefs and integrates and queries
  (beyond the same process before opening it, less SQLite's page cache bound); goal <= 1 KiB per belief. And the
  RSS of ``robokudo serve`` idle (no goal; informational).

Run: ``.venv/bin/python bench/bench_beliefs.py [--update-sizes N ...] [--query-sizes N ...] [--frames N] [--quick]``
"""

from __future__ import annotations

import argparse
import cProfile
import functools
import io
import os
import pstats
import shutil
import sqlite3
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import scipy.optimize  # noqa: F401 - the assignment imports it on first use: not what the parts measure

ROOT = Path(__file__).resolve().parents[1]
for folder in (ROOT, Path(__file__).resolve().parent):
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))

from reasoning.beliefs.answer import answer_from_memory  # noqa: E402
from reasoning.beliefs.interned import InternedTexts  # noqa: E402
from reasoning.beliefs.store import (  # noqa: E402
    _OBJECT_COLUMNS,
    WAL_AUTOCHECKPOINT_PAGES,
    BeliefFilter,
    BeliefStore,
    _object_row,
)
from reasoning.fusion.frame import FrameContext, FrameObject, frame_objects  # noqa: E402
from reasoning.fusion.rule import AttributeBelief, ValueSupport  # noqa: E402
from reasoning.fusion.tracking import BeliefTracker, ObjectBelief  # noqa: E402
from robokudo.core.regions import RegionBox  # noqa: E402
from robokudo.core.types import Classification, ObjectHypothesis, Pose, SemanticColor, Shape, Size  # noqa: E402

UPDATE_GOAL = 20_000.0
SYNCHRONOUS = "NORMAL"
"""The store's default ``synchronous`` setting, which the reference uses too."""
QUERY_GOALS = {10_000: 1.0, 1_000_000: 10.0}
"""Median ms to designators, by stored objects (sizes not listed here get the goal of the next larger one)."""
BYTES_PER_BELIEF_GOAL = 1024.0
DENSITY = 1.0
"""Objects per square metre."""
ROOM_WIDTH = 5.0
ROOM_DEPTH = 100.0
"""Rooms are 5 m x 100 m cells (about 500 objects each)."""

CLASSES = [f"Thing{i}" for i in range(40)] + ["Milk", "LactoseFreeMilk", "WholeMilk", "Cup", "Bowl", "CerealBox"]
PARENT = {"LactoseFreeMilk": "Milk", "WholeMilk": "Milk"}
COLORS = ["red", "green", "blue", "white", "yellow", "black"]
SHAPES = ["box", "cylinder", "sphere", "flat"]
GUESS_SHARE = 0.2
"""Share of the query benchmark's stored objects without a supported class: their experts' leading class is a guess
below 0.5 with a rival (an object the classifier could not tell, answered with "?"), which a class query reads
through the attribute index (``reasoning.beliefs.class_candidates``)."""


def is_subclass(a: str, b: str) -> bool:
    """The benchmark's tiny class tree."""
    return a == b or PARENT.get(a) == b


@dataclass(frozen=True)
class Seeded:
    """What was stored: positions, classes and colours of the objects."""

    positions: np.ndarray
    classes: list[str]
    colors: list[str]


def world_side(count: int) -> float:
    """Side (metres) of the square world holding ``count`` objects at :data:`DENSITY`."""
    return float(np.sqrt(count / DENSITY))


def room_of(x: np.ndarray, y: np.ndarray, side: float) -> np.ndarray:
    """Room numbers of positions in a world of ``side`` metres: 5 m x 100 m cells, row by row."""
    per_row = np.ceil(side / ROOM_WIDTH)
    return ((y // ROOM_DEPTH) * per_row + x // ROOM_WIDTH).astype(np.int64)


def template_belief(cls: str, color: str, shape: str, guessed: bool = False) -> ObjectBelief:
    """A stored belief of one class, colour and shape (id and place are filled per object); ``guessed``: the class
    is only the leading guess (p 0.45, a rival class at 0.40), so the belief has no supported class."""
    rival = CLASSES[(CLASSES.index(cls) + 1) % len(CLASSES)]
    stated = (
        {cls: ValueSupport(-0.2, 1, {"Detector"}, 0.0, 0.0), rival: ValueSupport(-0.4, 1, {"Detector"}, 0.0, 0.0)}
        if guessed
        else {cls: ValueSupport(1.4, 1, {"Detector"}, 0.0, 0.0)}
    )
    attributes = {
        "class": AttributeBelief("class", stated),
        "color": AttributeBelief("color", {color: ValueSupport(0.8, 1, {"ColorExpert"}, 0.0, 0.0)}),
        "shape": AttributeBelief("shape", {shape: ValueSupport(0.8, 1, {"ShapeExpert"}, 0.0, 0.0)}),
        "size": AttributeBelief("size", {"medium": ValueSupport(0.8, 1, {"SizeExpert"}, 0.0, 0.0)}),
    }
    return ObjectBelief(
        id=0,
        frame="world",
        position=np.zeros(3),
        dimensions=np.array([0.2, 0.1, 0.07]),
        attributes=attributes,
        existence=1.4,
        class_name=None if guessed else cls,
        sources={"Segmenter", "PoseExpert", "SizeExpert", "ColorExpert", "ShapeExpert", "Detector"},
        observations=1,
    )


def seed_file(
    path: Path, count: int, rng: np.random.Generator, named_regions: bool = True, guess_share: float = 0.0
) -> Seeded:
    """A belief store of ``count`` objects, written with ``executemany`` of rows the store's own encoder made for
    each (class, colour, shape) and placed per object (50,000 rows per transaction); each object's region
    is its room's name when ``named_regions``, else empty; a ``guess_share`` of the objects have no supported class
    (:func:`template_belief`)."""
    BeliefStore(path).close()  # the schema
    side = world_side(count)
    positions = np.column_stack([rng.uniform(0, side, count), rng.uniform(0, side, count), np.full(count, 0.8)])
    positions = positions[np.lexsort((positions[:, 1], positions[:, 0] // 10.0))]  # ids in spatial order
    class_index = rng.integers(len(CLASSES), size=count)
    color_index = rng.integers(len(COLORS), size=count)
    rooms = room_of(positions[:, 0], positions[:, 1], side)
    templates: dict[tuple[int, int, int], tuple[tuple, tuple, tuple, list[tuple[str, str]]]] = {}
    interned = InternedTexts()
    conn = sqlite3.connect(path, isolation_level=None)
    conn.execute("PRAGMA journal_mode = MEMORY")  # seeding only: the store switches the file back to WAL
    conn.execute("PRAGMA synchronous = OFF")
    conn.execute("PRAGMA cache_size = -131072")
    marks = ", ".join("?" * len(_OBJECT_COLUMNS.split(",")))
    # indexes are built once after the rows are in (sorting beats inserting into them row by row)
    indexes = conn.execute("SELECT name, sql FROM sqlite_master WHERE type = 'index' AND sql IS NOT NULL").fetchall()
    for index_name, _ in indexes:
        conn.execute(f"DROP INDEX {index_name}")
    xs, ys, zs = positions.T.tolist()
    room_names = [f"room{r}" if named_regions else "" for r in rooms.tolist()]
    keys = list(zip(class_index.tolist(), color_index.tolist(), [i % len(SHAPES) for i in range(count)], strict=True))
    # the guessed objects' templates are kept apart, so that without guesses seeding allocates exactly as before
    # (the update benchmark's rates moved by 10% with the Python objects seeding had allocated and freed)
    guessed = set(np.flatnonzero(rng.random(count) < guess_share).tolist()) if guess_share > 0.0 else set()
    guess_templates: dict[tuple[int, int, int], tuple[tuple, tuple, tuple, list[tuple[str, str]]]] = {}
    for begin in range(0, count, 50_000):
        objects, places, entries = [], [], []
        for i in range(begin, min(begin + 50_000, count)):
            key = keys[i]
            guess = i in guessed
            kept = guess_templates if guess else templates
            found = kept.get(key)
            if found is None:
                belief = template_belief(CLASSES[key[0]], COLORS[key[1]], SHAPES[key[2]], guess)
                row = _object_row(belief, is_subclass, {}, interned, conn, functools.partial(replay, conn))
                pairs = [tuple(entry.split("=", 1)) for entry in row[-1].split("\x1f")]
                found = kept[key] = (row[1:3], row[6:21], row[22:], pairs)  # type: ignore[assignment]
            head, middle, tail, pairs = found
            x, y, z = xs[i], ys[i], zs[i]
            object_id = i + 1
            objects.append((object_id, *head, x, y, z, *middle, room_names[i], *tail))
            places.append((object_id, x - 0.05, x + 0.05, y - 0.05, y + 0.05, z - 0.05, z + 0.05))
            entries.extend([(name, value, object_id) for name, value in pairs])
        conn.execute("BEGIN")
        conn.executemany(f"INSERT INTO objects ({_OBJECT_COLUMNS}) VALUES ({marks})", objects)
        conn.executemany("INSERT INTO objects_place VALUES (?, ?, ?, ?, ?, ?, ?)", places)
        entries.sort()
        conn.executemany("INSERT OR IGNORE INTO attribute_index VALUES (?, ?, ?)", entries)
        conn.execute("COMMIT")
    conn.execute("BEGIN")
    for _, sql in indexes:
        conn.execute(sql)
    conn.executemany("INSERT OR IGNORE INTO classes VALUES (?)", [(c,) for c in CLASSES])
    conn.execute("UPDATE meta SET value = ? WHERE key = 'next_id'", (str(count + 1),))
    conn.execute("COMMIT")
    conn.execute("PRAGMA journal_mode = WAL")
    conn.close()
    return Seeded(positions, [CLASSES[k] for k in class_index.tolist()], [COLORS[k] for k in color_index.tolist()])


def hypotheses_near(
    seeded: Seeded, rng: np.random.Generator, per_frame: int, view: tuple[int, list[int]] | None = None
) -> list[ObjectHypothesis]:
    """One frame around a random place (or the fixed ``view``: a place and the stored objects a camera there
    sees): re-observations of stored objects (1 cm noise) and two new objects.

    Every hypothesis carries a pose, a size, a colour, a shape and a class, like the output of a tabletop tree.
    """
    positions = seeded.positions
    if view is None:
        centre = positions[int(rng.integers(len(positions)))]
        near = np.flatnonzero(np.abs(positions[:, :2] - centre[:2]).max(axis=1) < 4.0)
        near = near[np.linalg.norm(positions[near, :2] - centre[:2], axis=1) < 4.0]
        chosen = [int(i) for i in rng.choice(near, size=min(len(near), per_frame - 2), replace=False)]
    else:
        centre, chosen = positions[view[0]], view[1]
    seen = [
        (positions[i] + rng.normal(0, 0.01, 3), seeded.classes[i], seeded.colors[i], SHAPES[i % len(SHAPES)])
        for i in chosen
    ]
    while len(seen) < per_frame:
        place = centre + np.array([rng.uniform(-3, 3), rng.uniform(-3, 3), 0.0])
        cls, color = CLASSES[int(rng.integers(len(CLASSES)))], COLORS[int(rng.integers(len(COLORS)))]
        seen.append((place, cls, color, SHAPES[int(rng.integers(len(SHAPES)))]))
    hypotheses = []
    for k, (place, cls, color, shape) in enumerate(seen):
        h = ObjectHypothesis(point_indices=np.array([k]), mask=np.zeros((1, 1), bool), roi=(k, 0, k + 1, 1))
        h.source = "Segmenter"
        h.annotations += [
            Pose(position=place, orientation=np.array([0.0, 0.0, 0.0, 1.0]), frame="world", source="PoseExpert"),
            Size(dimensions=(0.2, 0.1, 0.07), size_class="medium", source="SizeExpert"),
            SemanticColor(color=color, confidence=0.8, source="ColorExpert"),
            Shape(shape=shape, confidence=0.7, source="ShapeExpert"),
            Classification(class_name=cls, confidence=0.6, source="Detector"),
        ]
        hypotheses.append(h)
    return hypotheses


Recorded = list[tuple[str, list[tuple]]]
"""The write statements of one frame's integration with their rows (``BeliefStore.write_log``)."""


@dataclass(frozen=True)
class Rates:
    """Hypotheses/s of one run, in wall time and in CPU time of the process."""

    wall: float
    cpu: float


def bench_store(
    path: Path, prepared: list[list[ObjectHypothesis]], record: bool, write_behind: int = 0
) -> tuple[Rates, float, int, list[Recorded]]:
    """Integrate the prepared frames; hypotheses/s of integrate, of frame_objects + integrate, objects created, and
    (when ``record``) the statements and rows each frame wrote. With ``write_behind`` the timed region ends with the
    writer's last commit (:meth:`BeliefStore.flush`): committed frames, not handed-over ones; the CPU figure is this
    process's only (not the writer's)."""
    store = BeliefStore(path, tracker=BeliefTracker(class_test=is_subclass), write_behind=write_behind)
    if record:
        store.write_log = []
    t_fuse = t_integrate = c_integrate = 0.0
    count = created = 0
    for index, hypotheses in enumerate(prepared):
        start = time.perf_counter()
        objects: list[FrameObject] = frame_objects(hypotheses, FrameContext(time=float(index)))
        middle = time.perf_counter()
        cpu = time.process_time()
        step = store.integrate(objects, 1000.0 + index)
        c_integrate += time.process_time() - cpu
        end = time.perf_counter()
        t_fuse += middle - start
        t_integrate += end - middle
        count += len(hypotheses)
        created += len(step.created)
    start, cpu = time.perf_counter(), time.process_time()
    store.flush()
    t_integrate += time.perf_counter() - start
    c_integrate += time.process_time() - cpu
    recorded = store.write_log or []
    store.close()
    return Rates(count / t_integrate, count / c_integrate), count / (t_fuse + t_integrate), created, recorded


def replay(conn: sqlite3.Connection, statement: str, rows: list[tuple]) -> None:
    """Run one recorded write statement over its rows."""
    conn.executemany(statement, rows)


def bench_reference(path: Path, recorded: list[Recorded], per_frame: int) -> Rates:
    """Hypotheses/s of writing the recorded statements and rows with plain sqlite3 ``executemany``, one
    transaction per frame (the store's journal mode, synchronous setting and checkpoint interval)."""
    conn = sqlite3.connect(path, isolation_level=None)
    conn.execute("PRAGMA journal_mode = WAL")
    conn.execute(f"PRAGMA synchronous = {SYNCHRONOUS}")
    conn.execute(f"PRAGMA wal_autocheckpoint = {WAL_AUTOCHECKPOINT_PAGES}")
    start = time.perf_counter()
    cpu = time.process_time()
    for frame in recorded:
        conn.execute("BEGIN IMMEDIATE")
        for statement, rows in frame:
            conn.executemany(statement, rows)
        conn.execute("COMMIT")
    elapsed = time.perf_counter() - start
    used = time.process_time() - cpu
    conn.close()
    return Rates(len(recorded) * per_frame / elapsed, len(recorded) * per_frame / used)


def fixed_views(seeded: Seeded, rng: np.random.Generator, cameras: int, per_frame: int) -> list[tuple[int, list[int]]]:
    """``cameras`` fixed cameras: each a random place and the stored objects within 4 m it sees every frame."""
    positions = seeded.positions
    views = []
    for _ in range(cameras):
        place = int(rng.integers(len(positions)))
        near = np.flatnonzero(np.linalg.norm(positions[:, :2] - positions[place, :2], axis=1) < 4.0)
        views.append((place, [int(i) for i in rng.choice(near, size=min(len(near), per_frame - 2), replace=False)]))
    return views


def bench_updates(
    size: int, frames: int, per_frame: int, trials: int, folder: Path, cameras: int = 0, write_behind: int = 0
) -> dict[str, Any]:
    """Median over trials (each on a fresh copy of one seeded store) of the store's and the reference's rates;
    frames anywhere in the world, or (``cameras`` > 0) from that many fixed cameras in turn. With ``write_behind``,
    each trial also runs the same frames on a store with that write-behind (the two in alternating order), and the
    ``behind`` figures are its rates."""
    template = folder / f"seed-{size}.sqlite"
    for suffix in ("", "-wal", "-shm"):
        Path(f"{template}{suffix}").unlink(missing_ok=True)
    seeded = seed_file(template, size, np.random.default_rng(size), named_regions=False)
    store_rates: list[Rates] = []
    reference_rates: list[Rates] = []
    end_to_end: list[float] = []
    behind_rates: list[Rates] = []
    created = 0
    for trial in range(trials):
        rng = np.random.default_rng(trial + 1)
        views = fixed_views(seeded, rng, cameras, per_frame) if cameras else []
        prepared = [
            hypotheses_near(seeded, rng, per_frame, views[k % len(views)] if views else None) for k in range(frames + 1)
        ]
        warm = folder / "warm.sqlite"
        for mode in sorted({0, write_behind}):
            shutil.copy(template, warm)
            bench_store(warm, prepared[:1], record=False, write_behind=mode)  # lazy imports, statement cache
            for suffix in ("", "-wal", "-shm"):
                Path(f"{warm}{suffix}").unlink(missing_ok=True)
        trial_path = folder / f"trial-{size}.sqlite"
        behind_path = folder / f"behind-{size}.sqlite"
        for mode in [0, write_behind][:: 1 if trial % 2 == 0 else -1] if write_behind else [0]:
            if mode:
                shutil.copy(template, behind_path)
                behind_rates.append(bench_store(behind_path, prepared[1:], record=False, write_behind=mode)[0])
                for suffix in ("", "-wal", "-shm"):
                    Path(f"{behind_path}{suffix}").unlink(missing_ok=True)
            else:
                shutil.copy(template, trial_path)
                rate, full, made, recorded = bench_store(trial_path, prepared[1:], record=True)
        reference_path = folder / f"reference-{size}.sqlite"
        shutil.copy(template, reference_path)
        reference_rates.append(bench_reference(reference_path, recorded, per_frame))
        written = [(len(frame), sum(len(rows) for _, rows in frame)) for frame in recorded]
        store_rates.append(rate)
        end_to_end.append(full)
        created = made
        for path in (trial_path, reference_path):
            for suffix in ("", "-wal", "-shm"):
                Path(f"{path}{suffix}").unlink(missing_ok=True)
    pairs = list(zip(store_rates, reference_rates, strict=True))
    behind = {}
    if behind_rates:
        behind = {
            "behind": statistics.median(b.wall for b in behind_rates),
            "behind best": max(b.wall for b in behind_rates),
            "behind ratio": statistics.median(b.wall / s.wall for b, s in zip(behind_rates, store_rates, strict=True)),
            "behind ratios": [b.wall / s.wall for b, s in zip(behind_rates, store_rates, strict=True)],
            "behind reference ratio": statistics.median(
                b.wall / r.wall for b, r in zip(behind_rates, reference_rates, strict=True)
            ),
        }
    return behind | {
        "integrate": statistics.median(s.wall for s in store_rates),
        "integrate best": max(s.wall for s in store_rates),
        "integrate cpu": statistics.median(s.cpu for s in store_rates),
        "end to end": statistics.median(end_to_end),
        "reference": statistics.median(r.wall for r in reference_rates),
        "reference cpu": statistics.median(r.cpu for r in reference_rates),
        "ratio": statistics.median(s.wall / r.wall for s, r in pairs),
        "ratio cpu": statistics.median(s.cpu / r.cpu for s, r in pairs),
        "created": created,
        "hypotheses": frames * per_frame,
        "statements": statistics.mean(n for n, _ in written),
        "rows": statistics.mean(m for _, m in written),
    }


def memory_queries(count: int) -> dict[str, BeliefFilter]:
    """The benchmark's memory queries (the fridge box in the first room row, rooms by number)."""
    fridge = RegionBox("fridge", "FridgeInterior", "world", (25.0, 50.0, 0.8), (0.0, 0.0, 0.0, 1.0), (10.0, 10.0, 2.0))
    return {
        "milk in fridge (class subsumption + region box)": BeliefFilter(
            object_class="Milk", class_test=is_subclass, region="fridge", region_boxes=(fridge,)
        ),
        "milk in room3 (class subsumption + region name)": BeliefFilter(
            object_class="Milk", class_test=is_subclass, region="room3"
        ),
        "red cup in room7 (class + attribute + region)": BeliefFilter(
            object_class="Cup", class_test=is_subclass, attributes={"color": "red"}, region="room7"
        ),
    }


def bench_queries(
    store: BeliefStore, count: int, repeats: int
) -> list[tuple[str, float, float, float, float, float, int]]:
    """Per query: median and p95 ms to beliefs, median and p95 ms to designators, median CPU ms of the process to
    designators (on a loaded machine wall time includes waiting for a core), results."""
    found: list[tuple[str, float, float, float, float, float, int]] = []
    for label, belief_filter in memory_queries(count).items():
        figures: list[float] = []
        results = 0
        cpu: list[float] = []
        for use_answer in (False, True):
            samples = []
            for _ in range(repeats):
                start, used = time.perf_counter(), time.process_time()
                if use_answer:
                    results = len(answer_from_memory(store, belief_filter).objects)
                    cpu.append((time.process_time() - used) * 1000.0)
                else:
                    store.query(belief_filter)
                samples.append((time.perf_counter() - start) * 1000.0)
            figures += [statistics.median(samples), float(np.percentile(samples, 95))]
        found.append((label, *figures, statistics.median(cpu), results))  # type: ignore[arg-type]
    return found


def rss_kib(pid: int | str = "self") -> int:
    """Resident memory (KiB) of a process, from /proc."""
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    raise RuntimeError("no VmRSS in /proc (Linux only)")


def rss_child(path: Path, count: int) -> None:
    """In a fresh process: RSS before opening the store of ``count`` beliefs and after using it (prints KiB)."""
    seeded = Seeded(np.load(f"{path}.positions.npy"), ["Milk"] * count, ["red"] * count)
    rng = np.random.default_rng(5)
    prepared = [frame_objects(hypotheses_near(seeded, rng, 20)) for _ in range(50)]
    before = rss_kib()
    store = BeliefStore(path, tracker=BeliefTracker(class_test=is_subclass))
    for index, objects in enumerate(prepared):
        store.integrate(objects, 5000.0 + index)
    for belief_filter in memory_queries(count).values():
        answer_from_memory(store, belief_filter)
    store.query(BeliefFilter(object_class="Thing3"))
    held = store.count()
    after = rss_kib()
    store.close()
    with sqlite3.connect(path) as probe:  # the store keeps SQLite's default page cache
        page_cache = int(probe.execute("PRAGMA cache_size").fetchone()[0])
    cache_kib = -page_cache if page_cache < 0 else page_cache * 4
    print(f"{held} {before} {after} {cache_kib}")


def bench_memory(count: int, folder: Path) -> tuple[int, int, int, int]:
    """Beliefs held, RSS before and after (KiB), SQLite's page cache bound (KiB), measured in a child process."""
    path = folder / f"memory-{count}.sqlite"
    seeded = seed_file(path, count, np.random.default_rng(11))
    np.save(f"{path}.positions.npy", seeded.positions)
    output = subprocess.run(
        [sys.executable, __file__, "--rss-child", str(path), "--rss-count", str(count)],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.split()
    held, before, after, cache = (int(v) for v in output[-4:])
    return held, before, after, cache


def serve_idle_rss(folder: Path) -> float | None:
    """RSS (MiB) of ``robokudo serve`` a few seconds after it started listening (None when it cannot start)."""
    from bench_serve import environment_in, running, serve_command

    try:
        with running(serve_command(), environment_in(str(folder))) as server:
            time.sleep(3.0)
            return server.rss_mib()
    except (RuntimeError, OSError) as error:
        print(f"  robokudo serve did not start: {error}")
        return None


def profile_updates(size: int, frames: int, per_frame: int, cameras: int, folder: Path, out: Path) -> None:
    """cProfile of ``store.integrate`` over ``frames`` frames into a store of ``size``, frames at random places and
    then from ``cameras`` fixed cameras; the top entries by own and by cumulative time are written to ``out``."""
    path = folder / f"profile-{size}.sqlite"
    seeded = seed_file(path, size, np.random.default_rng(size), named_regions=False)
    text = io.StringIO()
    for scenario in (0, cameras):
        copy = folder / f"profile-{size}-{scenario}.sqlite"
        shutil.copy(path, copy)
        rng = np.random.default_rng(1)
        views = fixed_views(seeded, rng, scenario, per_frame) if scenario else []
        objects = [
            frame_objects(hypotheses_near(seeded, rng, per_frame, views[k % len(views)] if views else None))
            for k in range(frames + 1)
        ]
        store = BeliefStore(copy, tracker=BeliefTracker(class_test=is_subclass))
        store.integrate(objects[0], 999.0)
        profiler = cProfile.Profile()
        profiler.enable()
        for index, frame in enumerate(objects[1:]):
            store.integrate(frame, 1000.0 + index)
        profiler.disable()
        store.close()
        where = f"from {scenario} fixed cameras in turn" if scenario else "each at a random place"
        text.write(f"store.integrate, {frames} frames x {per_frame} hypotheses {where}, {size} stored objects\n")
        write_top_entries(profiler, text, 25)
    write_profile(text.getvalue(), out)


def profile_queries(size: int, repeats: int, folder: Path, out: Path) -> None:
    """cProfile of ``answer_from_memory`` (every memory query ``repeats`` times) on a store of ``size`` objects; the
    median ms of each query to designators and the top entries by own and by cumulative time are written to
    ``out``."""
    path = folder / f"profile-queries-{size}.sqlite"
    seed_file(path, size, np.random.default_rng(size + 1), guess_share=GUESS_SHARE)
    text = io.StringIO()
    with BeliefStore(path, tracker=BeliefTracker(class_test=is_subclass)) as store:
        queries = memory_queries(size)
        for label, belief_filter in queries.items():
            samples = []
            for _ in range(repeats):
                start = time.perf_counter()
                answer_from_memory(store, belief_filter)
                samples.append((time.perf_counter() - start) * 1000.0)
            text.write(f"{label}: {statistics.median(samples):.3f} ms median to designators (unprofiled)\n")
        profiler = cProfile.Profile()
        profiler.enable()
        for _ in range(repeats):
            for belief_filter in queries.values():
                answer_from_memory(store, belief_filter)
        profiler.disable()
    text.write(f"answer_from_memory, {len(queries)} queries x {repeats}, {size} stored objects\n")
    write_top_entries(profiler, text, 20)
    write_profile(text.getvalue(), out)


def write_top_entries(profiler: cProfile.Profile, text: io.StringIO, count: int) -> None:
    """The ``count`` top entries of ``profiler`` by own and by cumulative time, written to ``text``."""
    pstats.Stats(profiler, stream=text).sort_stats("tottime").print_stats(count)
    pstats.Stats(profiler, stream=text).sort_stats("cumulative").print_stats(count)


def write_profile(text: str, out: Path) -> None:
    """Write a profile's text to ``out`` with paths relative to the project."""
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text.replace(str(ROOT) + "/", ""))
    print(f"profile written to {out}")


FLOOR_VARIANTS: dict[str, tuple[tuple[str, ...], str, str]] = {
    "as designed (the reference)": ((), "", "NORMAL"),
    "synchronous = OFF": ((), "", "OFF"),
    "no sightings written (observations)": ((), "INSERT OR REPLACE INTO observations", "NORMAL"),
    "sightings without their (object_id, seq) index": (("DROP INDEX observations_object",), "", "NORMAL"),
    "no class and region indexes on objects": (("DROP INDEX objects_class", "DROP INDEX objects_region"), "", "NORMAL"),
    "no updates of known objects": ((), "UPDATE objects SET frame", "NORMAL"),
    "no R*Tree writes": ((), "INSERT OR REPLACE INTO objects_place", "NORMAL"),
}
"""Variants of the storage design for ``--floor-variants``: statements run first, statements left out (prefix),
``synchronous``."""


def floor_variants(size: int, frames: int, per_frame: int, folder: Path) -> None:
    """Where the floor's time and pages go: the store's write log of ``frames`` frames (random places) replayed
    per variant of the design (:data:`FLOOR_VARIANTS`); hypotheses/s in wall and CPU time, WAL pages per frame."""
    template = folder / f"floor-{size}.sqlite"
    seeded = seed_file(template, size, np.random.default_rng(size), named_regions=False)
    rng = np.random.default_rng(1)
    prepared = [hypotheses_near(seeded, rng, per_frame) for _ in range(frames)]
    run = folder / "floor-run.sqlite"
    shutil.copy(template, run)
    rates, _, _, log = bench_store(run, prepared, record=True)
    print(f"floor variants, {size} stored, {frames} frames x {per_frame} hypotheses at random places:")
    print(f"  {'store.integrate':52s} wall {rates.wall:7.0f}/s  cpu {rates.cpu:7.0f}/s")
    variants = [("warm-up (not printed)", FLOOR_VARIANTS["as designed (the reference)"]), *FLOOR_VARIANTS.items()]
    for label, (setup, left_out, synchronous) in variants:
        path = folder / "floor-variant.sqlite"
        for suffix in ("", "-wal", "-shm"):
            Path(f"{path}{suffix}").unlink(missing_ok=True)
        shutil.copy(template, path)
        conn = sqlite3.connect(path, isolation_level=None)
        conn.execute("PRAGMA journal_mode = WAL")
        conn.execute(f"PRAGMA synchronous = {synchronous}")
        conn.execute("PRAGMA wal_autocheckpoint = 0")  # the WAL's size counts the pages written
        for statement in setup:
            conn.execute(statement)
        conn.execute("PRAGMA wal_checkpoint(TRUNCATE)")
        start, cpu = time.perf_counter(), time.process_time()
        for frame in log:
            conn.execute("BEGIN IMMEDIATE")
            for statement, rows in frame:
                if not (left_out and statement.startswith(left_out)):
                    conn.executemany(statement, rows)
            conn.execute("COMMIT")
        wall, used = time.perf_counter() - start, time.process_time() - cpu
        pages = (Path(f"{path}-wal").stat().st_size - 32) / (4096 + 24) / len(log)
        conn.close()
        count = len(log) * per_frame
        if label.startswith("warm-up"):
            continue
        print(f"  {label:52s} wall {count / wall:7.0f}/s  cpu {count / used:7.0f}/s  WAL pages/frame {pages:5.1f}")


def goal_for(size: int) -> float:
    return next((goal for limit, goal in sorted(QUERY_GOALS.items()) if size <= limit), max(QUERY_GOALS.values()))


def main() -> int:
    """Run the parts and print their figures and goals."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--update-sizes", type=int, nargs="*", default=[10_000, 100_000])
    parser.add_argument("--query-sizes", type=int, nargs="*", default=[10_000, 1_000_000])
    parser.add_argument("--memory-size", type=int, default=100_000)
    parser.add_argument("--frames", type=int, default=300)
    parser.add_argument("--per-frame", type=int, default=20)
    parser.add_argument("--cameras", type=int, default=30, help="fixed cameras of the second update scenario")
    parser.add_argument("--repeats", type=int, default=300)
    parser.add_argument("--trials", type=int, default=3)
    parser.add_argument(
        "--write-behind",
        type=int,
        default=1,
        help="the goal figure: a store committing up to this many frames behind (its writer process), each trial "
        "alternating with the store as shipped (write-behind off, printed beside it); 0: the goal figure is the "
        "store as shipped alone",
    )
    parser.add_argument("--no-serve", action="store_true", help="skip the RSS of robokudo serve")
    parser.add_argument(
        "--floor-variants", action="store_true", help="only replay the write log per variant of the storage design"
    )
    parser.add_argument("--profile", type=Path, help="only write a cProfile of integrate (10,000 stored) to PROFILE")
    parser.add_argument(
        "--profile-queries", type=Path, help="only write a cProfile of the memory queries (10,000 stored) to PATH"
    )
    parser.add_argument("--rss-child", type=Path, help=argparse.SUPPRESS)
    parser.add_argument("--rss-count", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.rss_child:
        rss_child(args.rss_child, args.rss_count)
        return 0
    if args.floor_variants:
        with tempfile.TemporaryDirectory() as name:
            floor_variants(10_000, args.frames, args.per_frame, Path(name))
        return 0
    if args.profile_queries:
        with tempfile.TemporaryDirectory() as name:
            profile_queries(10_000, args.repeats, Path(name), args.profile_queries)
        return 0
    if args.profile:
        with tempfile.TemporaryDirectory() as name:
            profile_updates(10_000, args.frames, args.per_frame, args.cameras, Path(name), args.profile)
        return 0
    print(f"load average before: {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs")
    met: list[bool] = []
    with tempfile.TemporaryDirectory() as name:
        folder = Path(name)
        for size in args.update_sizes:
            for cameras in (0, args.cameras):
                r = bench_updates(size, args.frames, args.per_frame, args.trials, folder, cameras, args.write_behind)
                rate = r["behind"] if args.write_behind else r["integrate"]
                ok = rate >= UPDATE_GOAL
                met.append(ok)
                where = f"from {cameras} fixed cameras in turn" if cameras else "each at a random place"
                goal = f"goal >= {UPDATE_GOAL:.0f}: {'met' if ok else 'NOT met'}"
                print(
                    f"updates, {size} stored, frames {where} ({args.trials} trials of {args.frames} frames x "
                    f"{args.per_frame} hypotheses, {r['created']:.0f} new objects in {r['hypotheses']:.0f} hypotheses):"
                )
                if args.write_behind:
                    ratios = " ".join(f"{x:.2f}" for x in r["behind ratios"])
                    print(
                        f"  store.integrate, write-behind {args.write_behind} (association + fusion; one transaction "
                        f"per frame, committed by the store's writer process; timed to the last commit) {rate:8.0f} "
                        f"hypotheses/s median (best {r['behind best']:.0f})   {goal}"
                    )
                    print(
                        f"  same store as shipped (write-behind off; same trials, alternating) {r['integrate']:8.0f} "
                        f"hypotheses/s median (best {r['integrate best']:.0f});  write-behind / off "
                        f"{r['behind ratio']:.2f} median (per trial {ratios})"
                    )
                else:
                    print(
                        f"  store.integrate (association + fusion + transaction) {rate:8.0f} hypotheses/s median "
                        f"(best {r['integrate best']:.0f})   {goal}"
                    )
                print(
                    f"  plain sqlite3 executemany, same rows (reference)   {r['reference']:8.0f} hypotheses/s median   "
                    f"(the store's own {r['statements']:.1f} write statements, {r['rows']:.1f} rows per frame)"
                )
                print(
                    f"  ratio store / reference                            {r['ratio']:8.2f} write-behind off"
                    + (f", {r['behind reference ratio']:.2f} write-behind" if args.write_behind else "")
                )
                print(
                    f"  in CPU time of the process: store (write-behind off) {r['integrate cpu']:.0f}, reference "
                    f"{r['reference cpu']:.0f} hypotheses/s, ratio {r['ratio cpu']:.2f}"
                )
                print(
                    f"  frame_objects + integrate                          {r['end to end']:8.0f} hypotheses/s median"
                )
        for size in args.query_sizes:
            path = folder / f"query-{size}.sqlite"
            start = time.perf_counter()
            seed_file(path, size, np.random.default_rng(size + 1), guess_share=GUESS_SHARE)
            seeding = time.perf_counter() - start
            goal = goal_for(size)
            with BeliefStore(path, tracker=BeliefTracker(class_test=is_subclass)) as store:
                print(
                    f"queries, {store.count()} stored, {GUESS_SHARE:.0%} of them without a supported class (seeded in "
                    f"{seeding:.1f} s), {args.repeats} runs each:"
                )
                print(
                    f"  {'query':48s} {'beliefs ms p50':>14s} {'p95':>7s} {'designators ms p50':>18s} {'p95':>7s} "
                    f"{'cpu p50':>7s} n"
                )
                for label, q50, q95, d50, d95, c50, results in bench_queries(store, size, args.repeats):
                    ok = d50 <= goal
                    met.append(ok)
                    print(
                        f"  {label:48s} {q50:14.3f} {q95:7.3f} {d50:18.3f} {d95:7.3f} {c50:7.3f} {results}   "
                        f"goal median <= {goal:g} ms: {'met' if ok else 'NOT met'}"
                    )
            for suffix in ("", "-wal", "-shm"):
                Path(f"{path}{suffix}").unlink(missing_ok=True)
        if args.memory_size:
            held, before, after, cache = bench_memory(args.memory_size, folder)
            per_belief = max(after - before - cache, 0) * 1024.0 / held
            ok = per_belief <= BYTES_PER_BELIEF_GOAL
            met.append(ok)
            print(f"memory, a process holding {held} beliefs (integrating 50 frames, answering the queries):")
            print(
                f"  RSS {before / 1024:.1f} MiB before opening the store, {after / 1024:.1f} MiB after; "
                f"SQLite page cache bound {cache / 1024:.1f} MiB"
            )
            print(
                f"  beyond the page cache: {per_belief:.1f} bytes per belief "
                f"(all of it: {(after - before) * 1024.0 / held:.1f})   goal <= {BYTES_PER_BELIEF_GOAL:.0f}: "
                f"{'met' if ok else 'NOT met'}"
            )
        if not args.no_serve:
            rss = serve_idle_rss(folder)
            if rss is not None:
                print(f"memory, robokudo serve idle: RSS {rss:.1f} MiB (no goal)")
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    print("goals met" if all(met) else "goals NOT met")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
