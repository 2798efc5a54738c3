"""Write-behind (issue 19): a store whose frames are committed by its writer process gives exactly the results of one
that commits each frame itself, every read sees the frames integrated before it, and a failed write surfaces."""

from __future__ import annotations

import gc
import sqlite3
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from reasoning.beliefs import pending
from reasoning.beliefs import store as store_module
from reasoning.beliefs.frame_writer import MAX_WRITE_BEHIND
from reasoning.beliefs.pending import rtree_bounds
from reasoning.beliefs.store import _OBJECT_COLUMNS, BeliefFilter, BeliefStore
from reasoning.fusion.association import CameraModel
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import Evidence
from reasoning.fusion.tracking import BeliefTracker, ObjectBelief, TrackerConfig
from robokudo.core.types import CameraIntrinsics
from tests.fusion.camera_poses import camera_looking_at_origin

SLOW_WRITER = (
    "CREATE TRIGGER slow_writer AFTER INSERT ON observations BEGIN SELECT count(*) FROM (WITH RECURSIVE c(x) AS "
    "(SELECT 1 UNION ALL SELECT x + 1 FROM c WHERE x < 3000) SELECT x FROM c); END"
)
"""Work in every sighting's insert: the writer lags, so each frame is fused on pending ones (through the overlay)."""
TABLES = ("objects", "objects_place", "attribute_index", "observations", "classes", "interned", "meta")
INTRINSICS = CameraIntrinsics(500.0, 500.0, 320.0, 240.0, 640, 480)
ANCHORS = np.array([[0.0, 0.0, 0.8], [0.3, 0.1, 0.8], [0.31, 0.12, 0.8], [1.5, -0.5, 0.9], [-0.8, 0.6, 0.7]])


CAMERAS = (
    None,
    CameraModel(INTRINSICS, camera_looking_at_origin((0.0, -1.5, 0.8))),
    CameraModel(INTRINSICS, camera_looking_at_origin((2.0, 1.0, 0.9))),
)

observation = st.builds(
    lambda anchor, offset, cls, color, confidence, recording: FrameObject(
        position=ANCHORS[anchor] + np.array(offset),
        frame="world",
        evidence=[Evidence("class", cls, confidence, "Detector"), Evidence("color", color, 0.8, "Colors")],
        sources={"Detector", "Colors"},
        recording=recording,
    ),
    st.integers(0, len(ANCHORS) - 1),
    st.tuples(*[st.floats(-0.06, 0.06)] * 3),
    st.sampled_from(["Cup", "Bowl"]),
    st.sampled_from(["red", "blue", "teal"]),
    st.floats(0.4, 0.95),
    st.sampled_from(["", "take-1"]),
)
frame = st.tuples(st.lists(observation, max_size=5), st.integers(0, len(CAMERAS) - 1), st.floats(0.2, 1.5))


def _belief_text(b: ObjectBelief) -> str:
    supports = [
        (name, value, s.log_odds, s.count, sorted(s.sources), s.first_seen, s.last_seen)
        for name, attribute in b.attributes.items()
        for value, s in attribute.values.items()
    ]
    return repr(
        (b.id, b.frame, b.position.tolist(), b.orientation.tolist(), supports, b.position_variance, b.existence,
         b.status, b.first_seen, b.last_seen, b.misses, b.region, b.roi, sorted(b.sources), b.observations,
         b.class_name, b.recording)
    )  # fmt: skip


def _run(path: Path, frames: list, write_behind: int) -> tuple[list, list]:
    """Each step's results and, after closing, every table."""
    BeliefStore(path).close()
    with sqlite3.connect(path) as conn:
        conn.execute(SLOW_WRITER)
    steps = []
    store = BeliefStore(path, tracker=BeliefTracker(TrackerConfig(gone_after=2.0)), write_behind=write_behind)
    now = 100.0
    for objects, camera, pause in frames:
        now += pause
        step = store.integrate(objects, now, camera=CAMERAS[camera])
        steps.append(([_belief_text(b) for b in step.changed], step.assigned, step.created, step.missed, step.gone))
    store.close()
    with sqlite3.connect(path) as conn:
        tables = [sorted(conn.execute(f"SELECT * FROM {table}").fetchall(), key=repr) for table in TABLES]
    conn.close()
    return steps, tables


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(frames=st.lists(frame, min_size=1, max_size=14), write_behind=st.sampled_from([1, 2]))
def test_write_behind_gives_the_results_of_committing_each_frame(
    tmp_path_factory: pytest.TempPathFactory, frames: list, write_behind: int
) -> None:
    folder = tmp_path_factory.mktemp("frames")
    assert _run(folder / "behind.sqlite", frames, write_behind) == _run(folder / "serial.sqlite", frames, 0)


def _seen(position: tuple[float, float, float], color: str = "red") -> FrameObject:
    return FrameObject(
        position=np.array(position),
        frame="world",
        evidence=[Evidence("class", "Cup", 0.9, "Detector"), Evidence("color", color, 0.8, "Colors")],
        sources={"Detector", "Colors"},
    )


def lagging_store(path: Path) -> BeliefStore:
    """A new write-behind store at ``path`` whose writer lags (two frames may be pending)."""
    BeliefStore(path).close()
    with sqlite3.connect(path) as conn:
        conn.execute(SLOW_WRITER)
    return BeliefStore(path, write_behind=2)


@pytest.fixture
def lagging(tmp_path: Path) -> BeliefStore:
    """A write-behind store whose writer lags (two frames may be pending), holding two frames."""
    store = lagging_store(tmp_path / "beliefs.sqlite")
    store.integrate([_seen((0.0, 0.0, 0.8)), _seen((1.0, 0.0, 0.8))], 10.0)
    store.integrate([_seen((0.0, 0.0, 0.8), "blue"), _seen((2.0, 0.0, 0.8))], 11.0)
    return store


def test_every_read_after_integrate_sees_the_frame(lagging: BeliefStore) -> None:
    store = lagging
    step = store.integrate([_seen((0.0, 0.0, 0.8)), _seen((3.0, 0.0, 0.8))], 12.0)
    new = step.created[0]
    assert store.get(new) is not None
    assert store.count() == 4
    assert [b.id for b in store.query(BeliefFilter(ids=(new,)))] == [new]
    assert len(store.history(step.assigned[0])) == 3
    step = store.integrate([_seen((4.0, 0.0, 0.8))], 13.0)
    assert store.forget([step.created[0]]) == 1
    step = store.integrate([_seen((5.0, 0.0, 0.8))], 14.0)
    belief = step.changed[0]
    belief.region = "shelf"
    store.put([belief])  # written after the pending frame, so the pending frame does not overwrite it
    assert store.get(belief.id).region == "shelf"  # type: ignore[union-attr]
    step = store.integrate([_seen((6.0, 0.0, 0.8))], 15.0)
    assert len(store.beliefs()) == 6
    store.close()


def test_wait_commits_the_frame_before_returning(lagging: BeliefStore) -> None:
    step = lagging.integrate([_seen((7.0, 0.0, 0.8))], 12.0, wait=True)
    with BeliefStore(lagging.path) as other:  # another connection: sees only what is committed
        assert other.get(step.created[0]) is not None
        assert other.count() == 4
    lagging.close()


def test_close_commits_the_pending_frames(lagging: BeliefStore) -> None:
    step = lagging.integrate([_seen((7.0, 0.0, 0.8))], 12.0)
    lagging.close()
    with BeliefStore(lagging.path) as reopened:
        assert reopened.count() == 4
        assert reopened.get(step.created[0]) is not None
        assert len(reopened.history(step.assigned[0])) == 1


def test_a_failed_write_raises_on_the_next_call_and_keeps_every_earlier_frame(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    BeliefStore(path).close()
    with sqlite3.connect(path) as conn:
        conn.execute(SLOW_WRITER)
        conn.execute(  # a write failing like a full disk would, at the frame of time 13
            "CREATE TRIGGER full_disk BEFORE INSERT ON observations WHEN NEW.time = 13.0 "
            "BEGIN SELECT RAISE(ABORT, 'injected failure'); END"
        )
    store = BeliefStore(path, write_behind=1)
    for t in (10.0, 11.0, 12.0):
        store.integrate([_seen((t, 0.0, 0.8))], t)
    store.integrate([_seen((13.0, 0.0, 0.8))], 13.0)  # returns: its write is pending
    with pytest.raises(sqlite3.IntegrityError, match="injected failure"):
        store.flush()
    assert store.count() == 3  # the failed frame is not stored, every earlier one is
    step = store.integrate([_seen((14.0, 0.0, 0.8))], 14.0)  # a new writer takes over
    store.close()
    with BeliefStore(path) as reopened:
        assert sorted(b.last_seen for b in reopened.beliefs()) == [10.0, 11.0, 12.0, 14.0]
        assert reopened.get(step.created[0]) is not None


def test_a_failed_write_surfaces_from_the_next_integrate(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    BeliefStore(path).close()
    with sqlite3.connect(path) as conn:
        conn.execute(
            "CREATE TRIGGER full_disk BEFORE INSERT ON observations WHEN NEW.time = 11.0 "
            "BEGIN SELECT RAISE(ABORT, 'injected failure'); END"
        )
    store = BeliefStore(path, write_behind=1)
    store.integrate([_seen((10.0, 0.0, 0.8))], 10.0)
    store.integrate([_seen((11.0, 0.0, 0.8))], 11.0)
    with pytest.raises(sqlite3.IntegrityError, match="injected failure"):
        store.integrate([_seen((12.0, 0.0, 0.8))], 12.0)  # fused on the failed frame: not stored either
    store.close()
    with BeliefStore(path) as reopened:
        assert [b.last_seen for b in reopened.beliefs()] == [10.0]


def test_rtree_bounds_are_what_sqlite_stores(tmp_path: Path) -> None:
    rng = np.random.default_rng(3)
    centres = np.concatenate([rng.uniform(-50.0, 50.0, (3000, 3)), rng.normal(0.0, 1e-3, (3000, 3))])
    boxes = np.empty((len(centres), 7))
    boxes[:, 0] = np.arange(len(centres))
    boxes[:, 1::2] = centres - 0.05
    boxes[:, 2::2] = centres + 0.05
    conn = sqlite3.connect(":memory:")
    conn.execute("CREATE VIRTUAL TABLE place USING rtree (id, x0, x1, y0, y1, z0, z1)")
    conn.executemany("INSERT INTO place VALUES (?, ?, ?, ?, ?, ?, ?)", boxes.tolist())
    stored = conn.execute("SELECT * FROM place ORDER BY id").fetchall()
    assert rtree_bounds(boxes.tolist()) == stored
    assert stored != [tuple(row) for row in boxes.tolist()]  # the rounding is not a no-op


def test_write_behind_must_not_be_negative(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="write_behind"):
        BeliefStore(tmp_path / "beliefs.sqlite", write_behind=-1)


def test_write_behind_is_bounded_so_the_writers_answers_never_fill_their_pipe(tmp_path: Path) -> None:
    """Unread answers pile up in the writer's output pipe: beyond what it holds the writer would block on them while
    the store blocks sending it the next frame (1e6 hung after about 4,700 empty frames)."""
    with pytest.raises(ValueError, match="write_behind"):
        BeliefStore(tmp_path / "beliefs.sqlite", write_behind=MAX_WRITE_BEHIND + 1)
    with BeliefStore(tmp_path / "beliefs.sqlite", write_behind=MAX_WRITE_BEHIND) as store:
        for t in range(3 * MAX_WRITE_BEHIND):
            store.integrate([_seen((float(t), 0.0, 0.8))] if t % 100 == 0 else [], float(t))
    with BeliefStore(tmp_path / "beliefs.sqlite") as reopened:
        assert sorted(b.last_seen for b in reopened.beliefs()) == [0.0, 100.0, 200.0, 300.0, 400.0, 500.0, 600.0, 700.0]


def test_the_overlay_reads_the_columns_it_names() -> None:
    """The overlay reads ``objects`` rows by position; each position names the column the store writes there."""
    columns = [c.strip() for c in _OBJECT_COLUMNS.split(",")]
    for name in ("frame", "status", "last_seen", "misses", "recording"):
        assert columns[getattr(pending, name.upper())] == name


def test_a_store_dropped_unclosed_ends_its_writer_which_commits_the_pending_frames(tmp_path: Path) -> None:
    """Without close the writer's input stayed open for the life of the process: the writer went on running."""
    path = tmp_path / "beliefs.sqlite"
    store = lagging_store(path)
    process = store._writer.process  # type: ignore[union-attr]
    for t in (10.0, 11.0, 12.0):
        store.integrate([_seen((t, 0.0, 0.8))], t)
    del store
    gc.collect()
    assert process.poll() == 0
    with BeliefStore(path) as reopened:
        assert sorted(b.last_seen for b in reopened.beliefs()) == [10.0, 11.0, 12.0]


def test_a_writer_that_cannot_start_leaves_no_open_connection(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """When the writer process cannot be started (no process slots, no interpreter), the store is not made; the
    connection it had opened is closed, not left to the garbage collector with the file's locks."""
    opened: list[sqlite3.Connection] = []
    real_open = BeliefStore._open

    def remembering_open(self: BeliefStore, *args: object) -> sqlite3.Connection:
        conn = real_open(self, *args)  # type: ignore[arg-type]
        opened.append(conn)
        return conn

    def failing_writer(*_: object) -> None:
        raise OSError("no writer process")

    monkeypatch.setattr(BeliefStore, "_open", remembering_open)
    monkeypatch.setattr(store_module, "FrameWriter", failing_writer)
    with pytest.raises(OSError, match="no writer process"):
        BeliefStore(tmp_path / "beliefs.sqlite", write_behind=1)
    assert len(opened) == 1
    with pytest.raises(sqlite3.ProgrammingError):
        opened[0].execute("SELECT 1")
