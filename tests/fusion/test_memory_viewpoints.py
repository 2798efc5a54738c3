"""The store keeps the last view of each recording and frame (schema 5: camera pose and support plane), so a
selection asked of memory measures what the frame measured: the leftmost of world-frame beliefs, heights above the
support plane. A schema-4 store is upgraded when opened; a robokudo of schema 4 refuses a schema-5 store."""

from __future__ import annotations

import sqlite3
from pathlib import Path

import numpy as np
import pytest

from queries.selection import SELECTIONS, SelectionRequest
from reasoning.beliefs import store as store_module
from reasoning.beliefs.answer import answer_from_memory
from reasoning.beliefs.selection import Viewpoint, select
from reasoning.beliefs.store import SCHEMA_VERSION, BeliefFilter, BeliefStore, BeliefStoreError
from reasoning.fusion.association import CameraModel
from reasoning.fusion.frame import WORLD_FRAME, FrameObject
from reasoning.fusion.rule import Evidence
from robokudo.core.types import CameraIntrinsics

INTRINSICS = CameraIntrinsics(525.0, 525.0, 319.5, 239.5, 640, 480)

# a camera 1.2 m up looking along world +x: its x axis is world -y, its y axis world -z
POSE = np.array(
    [
        [0.0, 0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0, 0.0],
        [0.0, -1.0, 0.0, 1.2],
        [0.0, 0.0, 0.0, 1.0],
    ]
)
TABLE = np.array([0.0, -1.0, 0.0, 0.5])
"""The table at world z = 0.7 in that camera's frame, its normal towards the camera: height = world z - 0.7."""


def _box(x: float, y: float, z: float, recording: str = "kitchen") -> FrameObject:
    return FrameObject(
        position=np.array([x, y, z]),
        frame=WORLD_FRAME,
        dimensions=np.array([0.1, 0.1, 0.1]),
        evidence=[Evidence("class", "Box", 0.9, "KnowledgeClassifier", 0.0)],
        sources={"KnowledgeClassifier"},
        recording=recording,
    )


def _camera(recording: str = "kitchen") -> CameraModel:
    return CameraModel(intrinsics=INTRINSICS, to_frame=POSE, frame=WORLD_FRAME, recording=recording)


def _asking(name: str) -> BeliefFilter:
    return BeliefFilter(object_class="Box", selection=SelectionRequest(SELECTIONS[name]), limit=1)


# left in the image (world +y), on the table, stacked on another box, right in the image (world -y)
BOXES = [_box(1.5, 0.3, 0.75), _box(1.5, 0.0, 0.75), _box(1.5, 0.0, 0.85), _box(1.4, -0.3, 0.75)]


@pytest.mark.parametrize("write_behind", [0, 2])
def test_memory_measures_world_beliefs_from_the_last_camera_pose_and_plane(tmp_path: Path, write_behind: int) -> None:
    """Memory answers the leftmost, rightmost, closest and top box as the frame measured them (the same values),
    where it could measure none of left, right or distance before (no camera pose was kept)."""
    with BeliefStore(tmp_path / "b.sqlite", write_behind=write_behind) as store:
        step = store.integrate(BOXES, 1.0, camera=_camera(), plane=TABLE)
        left, _, stacked, right = step.assigned
        beliefs = store.query(BeliefFilter(object_class="Box"))
        for name, expected, basis in (
            ("leftmost", left, "camera frame"),
            ("rightmost", right, "camera frame"),
            ("closest", right, "camera frame"),
            ("top", stacked, "above the support plane"),
        ):
            live = select(beliefs, _asking(name).selection, Viewpoint(cam_to_world=POSE, plane=TABLE), 1)[1]
            remembered = answer_from_memory(store, _asking(name))
            assert [o.id for o in remembered.objects] == [expected], name
            note = remembered.selection
            assert note is not None and note.basis == basis and note.unmeasured == ()
            assert note.values == live.values
        assert remembered.selection.values[0][1] == pytest.approx(0.85 - 0.7)


def test_memory_without_a_recorded_view_says_what_it_could_not_measure(tmp_path: Path) -> None:
    """Beliefs integrated without a camera have no view: left and right are not measured (the answer names them),
    height falls back to world z."""
    with BeliefStore(tmp_path / "b.sqlite") as store:
        ids = store.integrate(BOXES, 1.0).assigned
        leftmost = answer_from_memory(store, _asking("leftmost"))
        assert leftmost.objects == () and sorted(leftmost.selection.unmeasured) == sorted(ids)
        top = answer_from_memory(store, _asking("top"))
        assert top.selection.basis == "world z" and [o.id for o in top.objects] == [ids[2]]


def test_the_last_view_is_kept_per_recording_and_world_beliefs_are_measured_from_the_latest(tmp_path: Path) -> None:
    """A later frame replaces its recording's view, an older timestamp does not; the world frame is shared, so world
    beliefs are measured from the latest view of any recording; a camera-frame recording keeps its own view."""
    turned = POSE.copy()
    turned[:3, :3] = POSE[:3, :3] @ np.diag([-1.0, -1.0, 1.0])  # rolled half a turn: left and right swap
    kitchen = ("kitchen", WORLD_FRAME)
    with BeliefStore(tmp_path / "b.sqlite") as store:
        ids = store.integrate(BOXES, 2.0, camera=_camera(), plane=TABLE).assigned
        store.integrate([], 1.0, camera=CameraModel(INTRINSICS, turned, WORLD_FRAME, recording="kitchen"))
        camera_frame = CameraModel(INTRINSICS, np.eye(4), "camera", recording="scene")
        store.integrate([], 1.5, camera=camera_frame, plane=TABLE)
        views = store.viewpoints([kitchen, ("scene", "camera"), ("nowhere", "camera")])
        assert set(views) == {kitchen, ("scene", "camera")}
        assert np.array_equal(views[kitchen].cam_to_world, POSE) and np.array_equal(views[kitchen].plane, TABLE)
        assert views[("scene", "camera")].cam_to_world is None
        assert [o.id for o in answer_from_memory(store, _asking("leftmost")).objects] == [ids[0]]
        store.integrate([], 3.0, camera=CameraModel(INTRINSICS, turned, WORLD_FRAME, recording="lab"))
        assert np.array_equal(store.viewpoints([kitchen])[kitchen].cam_to_world, turned)
        assert [o.id for o in answer_from_memory(store, _asking("leftmost")).objects] == [ids[3]]
        assert store.clear() == 4 and store.viewpoints([kitchen]) == {}


def _as_schema_4(path: Path) -> None:
    with sqlite3.connect(path) as conn:  # what robokudo with schema version 4 wrote: no views
        conn.execute("DROP TABLE views")
        conn.execute("UPDATE meta SET value = '4' WHERE key = 'version'")


def test_a_schema_4_store_is_upgraded_when_opened(tmp_path: Path) -> None:
    """Opened, a schema-4 store gets the views table and keeps its beliefs; its selections measure as before until
    a frame is seen again, then as that frame did."""
    path = tmp_path / "old.sqlite"
    with BeliefStore(path) as store:
        ids = store.integrate(BOXES, 1.0, camera=_camera(), plane=TABLE).assigned
    _as_schema_4(path)
    with BeliefStore(path) as store:
        assert store.count() == 4 and store.integrity_check() == "ok"
        assert answer_from_memory(store, _asking("top")).selection.basis == "world z"
        assert answer_from_memory(store, _asking("leftmost")).objects == ()
        store.integrate(BOXES, 2.0, camera=_camera(), plane=TABLE)
        assert [o.id for o in answer_from_memory(store, _asking("leftmost")).objects] == [ids[0]]
        assert answer_from_memory(store, _asking("top")).selection.basis == "above the support plane"
    with sqlite3.connect(path) as conn:
        assert conn.execute("SELECT value FROM meta WHERE key = 'version'").fetchone()[0] == str(SCHEMA_VERSION) == "5"


def test_a_robokudo_of_schema_4_refuses_a_schema_5_store_untouched(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "new.sqlite"
    with BeliefStore(path) as store:
        store.integrate(BOXES, 1.0, camera=_camera(), plane=TABLE)
    content = path.read_bytes()
    monkeypatch.setattr(store_module, "SCHEMA_VERSION", 4)
    with pytest.raises(BeliefStoreError, match="schema version 5, newer than this robokudo"):
        BeliefStore(path)
    assert path.read_bytes() == content
