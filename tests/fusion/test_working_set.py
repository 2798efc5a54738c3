"""The belief store's working set: beliefs kept decoded between frames give exactly what reading the file gives.

Two stores integrate the same random frames, one keeping its working set and one with none (every frame reads
and decodes its candidates from the file); every step and every stored belief must be equal, field by field.
Another connection's commit drops the working set; a failed integration leaves nothing changed in memory.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from reasoning.beliefs.store import BeliefStore
from reasoning.fusion.association import CameraModel
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import Evidence
from reasoning.fusion.tracking import BeliefTracker, ObjectBelief, TrackerConfig
from robokudo.core.regions import RegionBox
from robokudo.core.types import CameraIntrinsics

CLASSES = ("Milk", "LactoseFreeMilk", "Cup", "Bowl")
COLORS = ("red", "blue", "white")
TABLE = RegionBox("table", "TableRegion", "world", (0.5, 0.5, 0.8), (0.0, 0.0, 0.0, 1.0), (1.0, 1.0, 0.5))
CAMERA = CameraIntrinsics(500.0, 500.0, 320.0, 240.0, 640, 480)


def is_subclass(a: str, b: str) -> bool:
    return a == b or (a, b) == ("LactoseFreeMilk", "Milk")


def camera_looking_at_the_grid() -> CameraModel:
    """A camera 2 m in front of the grid, looking along +y (optical z) at table height."""
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = (1, 0, 0), (0, 0, -1), (0, 1, 0), (0.5, -2.0, 0.8)
    return CameraModel(CAMERA, pose)


sighting = st.tuples(
    st.integers(0, 5),  # grid column: objects 0.3 m apart, so they are re-associated across frames
    st.integers(0, 3),
    st.floats(-0.02, 0.02),  # noise
    st.sampled_from(CLASSES),
    st.sampled_from(COLORS),
    st.floats(0.3, 0.95),  # class confidence
    st.booleans(),  # with an appearance histogram
)
frames = st.lists(
    st.tuples(st.lists(sighting, max_size=8), st.booleans(), st.floats(0.1, 3.0)), min_size=2, max_size=12
)


def frame_of(items: list[tuple]) -> list[FrameObject]:
    objects = []
    for column, row, noise, cls, color, confidence, histogram in items:
        appearance = None
        if histogram:
            values = np.arange(1.0, 9.0) * (column + 1) + row * noise * 100
            appearance = np.abs(values) / np.abs(values).sum()
        objects.append(
            FrameObject(
                position=np.array([column * 0.3 + noise, row * 0.3 - noise, 0.8]),
                frame="world",
                dimensions=np.array([0.2, 0.07 + abs(noise), 0.07]),
                appearance=appearance,
                evidence=[Evidence("class", cls, confidence, "Detector"), Evidence("color", color, 0.7, "Colors")],
                sources={"Segmenter", "Detector", "Colors"},
                roi=(column, row, column + 10, row + 10),
                confidence=0.9,
            )
        )
    return objects


def fields(belief: ObjectBelief) -> dict[str, object]:
    """Every field, arrays as lists of floats (bit-exact comparison)."""
    out = {}
    for f in dataclasses.fields(belief):
        value = getattr(belief, f.name)
        out[f.name] = value.tolist() if isinstance(value, np.ndarray) else value
    return out


def step_fields(step: object) -> tuple:
    return (
        [fields(b) for b in step.changed],  # type: ignore[attr-defined]
        step.assigned,  # type: ignore[attr-defined]
        step.created,  # type: ignore[attr-defined]
        step.missed,  # type: ignore[attr-defined]
        step.gone,  # type: ignore[attr-defined]
    )


def tracker() -> BeliefTracker:
    return BeliefTracker(TrackerConfig(gone_after=4.0), class_test=is_subclass, regions=(TABLE,))


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(sequence=frames)
def test_the_working_set_gives_the_same_beliefs_as_reading_the_file(tmp_path_factory, sequence) -> None:
    folder = tmp_path_factory.mktemp("working")
    camera = camera_looking_at_the_grid()
    with (
        BeliefStore(folder / "kept.sqlite", tracker=tracker()) as kept,
        BeliefStore(folder / "read.sqlite", tracker=tracker(), working_set=0) as read,
    ):
        time = 0.0
        for items, with_camera, elapsed in sequence:
            time += elapsed
            seen = camera if with_camera else None
            a = kept.integrate(frame_of(items), time, camera=seen)
            b = read.integrate(frame_of(items), time, camera=seen)
            assert step_fields(a) == step_fields(b)
        assert [fields(x) for x in kept.beliefs(include_gone=True)] == [
            fields(x) for x in read.beliefs(include_gone=True)
        ]
        if any(items for items, _, _ in sequence):
            assert kept._working, "the working set was used"


def test_a_commit_of_another_connection_drops_the_working_set(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    cup = frame_of([(0, 0, 0.0, "Cup", "red", 0.8, False)])
    with BeliefStore(path) as engine, BeliefStore(path) as editor:
        engine.integrate(cup, 1.0)
        engine.integrate(cup, 2.0)
        changed = editor.get(1)
        assert changed is not None
        changed.observations = 40
        changed.position = changed.position + 0.01
        editor.put([changed])
        step = engine.integrate(cup, 3.0)
        assert step.changed[0].observations == 41  # the editor's belief, not the one kept in memory
        assert engine.get(1).observations == 41  # type: ignore[union-attr]


def test_a_failed_integration_leaves_no_changed_belief_in_memory(tmp_path: Path) -> None:
    path = tmp_path / "beliefs.sqlite"
    cup = frame_of([(0, 0, 0.0, "Cup", "red", 0.8, False)])
    with BeliefStore(path) as store:
        store.integrate(cup, 1.0)
        broken = frame_of([(0, 0, 0.0, "Cup", "red", 0.8, False)])
        broken[0].roi = ("not", "a", "box", 0)  # type: ignore[assignment]  # fails while writing, after the update
        with pytest.raises(ValueError):
            store.integrate(broken, 2.0)
        assert not store._working
        step = store.integrate(cup, 3.0)
        assert step.changed[0].observations == 2  # the failed frame left no trace


def test_a_negative_working_set_is_refused(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="working_set"):
        BeliefStore(tmp_path / "b.sqlite", working_set=-1)
