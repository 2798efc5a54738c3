"""The row-level update of :meth:`BeliefStore.integrate` gives what the general way gives (decode every candidate,
``BeliefTracker.step``, encode every changed belief): the same steps, the same changed beliefs (log-odds not
rounded), and the same store, table by table, on random frames with the uncommon cases mixed in (histograms,
conflicting values, missing sizes, cameras that miss beliefs, doubted objects, time going back)."""

from __future__ import annotations

import sqlite3
from pathlib import Path

import numpy as np
import pytest

from reasoning.beliefs.row_update import RowUpdate
from reasoning.beliefs.store import BeliefStore
from reasoning.fusion.association import CameraModel
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import Evidence
from reasoning.fusion.tracking import BeliefTracker, ChangedBeliefs, ObjectBelief, TrackerConfig, TrackStep
from robokudo.core.types import CameraIntrinsics

SUBCLASSES = {("LactoseFreeMilk", "Milk"), ("Milk", "Drink"), ("LactoseFreeMilk", "Drink")}
CLASSES = ("Milk", "LactoseFreeMilk", "Drink", "Cup", "Bowl")
COLORS = ("red", "blue", "white")
INTRINSICS = CameraIntrinsics(500.0, 500.0, 320.0, 240.0, 640, 480)
TABLES = ("objects", "objects_place", "attribute_index", "observations", "classes", "interned", "meta")


def is_subclass(a: str, b: str) -> bool:
    return a == b or (a, b) in SUBCLASSES


class GeneralTracker(BeliefTracker):
    """The plain tracker, taken the general way (the row-level update applies to :class:`BeliefTracker` only)."""


def camera_at(eye: np.ndarray) -> CameraModel:
    """A camera at ``eye`` looking along +y (optical z forward, x right, y down)."""
    pose = np.eye(4)
    pose[:3, :3] = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]]).T
    pose[:3, 3] = eye
    return CameraModel(INTRINSICS, pose)


def random_frame(rng: np.random.Generator, places: np.ndarray, quirks: bool) -> list[FrameObject]:
    """Sightings of some of ``places`` (1 cm noise) and a new object or two; with ``quirks``, the uncommon cases."""
    chosen = rng.choice(len(places), size=int(rng.integers(0, len(places) + 1)), replace=False)
    seen = [(places[i] + rng.normal(0.0, 0.01, 3), CLASSES[i % 5], COLORS[i % 3]) for i in chosen.tolist()]
    for _ in range(int(rng.integers(0, 3))):
        place = rng.uniform([-2.0, 0.0, 0.7], [2.0, 4.0, 0.9])
        seen.append((place, CLASSES[int(rng.integers(len(CLASSES)))], COLORS[int(rng.integers(len(COLORS)))]))
    objects = []
    for k, (position, cls, color) in enumerate(seen):
        odd = quirks and rng.random() < 0.3
        evidence = [
            Evidence("class", cls, float(rng.choice([0.1, 0.3, 0.5, 0.6, 0.9])), "Detector"),
            Evidence("color", color, 0.7, "ColorExpert" if rng.random() < 0.9 else "OtherColors"),
            Evidence("shape", "box", 0.6, "ShapeExpert"),
        ]
        if rng.random() < 0.3:
            evidence.append(Evidence("region", "fridge" if k % 2 or odd else "table", 0.8, "Regions"))
        if odd and rng.random() < 0.5:
            evidence.append(Evidence("class", CLASSES[int(rng.integers(len(CLASSES)))], 0.8, "Detector2"))
        dimensions = np.array([0.2, 0.1, 0.07]) * rng.uniform(0.9, 1.1)
        objects.append(
            FrameObject(
                position=position,
                frame="world",
                orientation=np.array([0.0, 0.0, float(rng.uniform(-1, 1)), 1.0]),
                dimensions=None if odd and rng.random() < 0.3 else dimensions,
                appearance=rng.dirichlet(np.ones(8)) if odd and rng.random() < 0.3 else None,
                evidence=evidence,
                sources={"Segmenter", *(e.source for e in evidence)},
                roi=(k, 0, k + 5, 5),
                confidence=float(rng.uniform(0.3, 1.0)),
                doubt="unsure" if odd and rng.random() < 0.1 else "",
            )
        )
    return objects


def belief_state(belief: ObjectBelief) -> tuple:
    """Everything a belief holds, comparable (arrays as lists, sets sorted, log-odds exact)."""
    attributes = [
        (name, value, s.log_odds, s.count, sorted(s.sources), s.first_seen, s.last_seen)
        for name, a in belief.attributes.items()
        for value, s in a.values.items()
    ]
    arrays = [None if x is None else np.asarray(x).tolist() for x in (belief.position, belief.orientation)]
    arrays += [None if x is None else np.asarray(x).tolist() for x in (belief.dimensions, belief.appearance)]
    return (
        belief.id,
        belief.frame,
        *arrays,
        attributes,
        belief.position_variance,
        belief.existence,
        belief.status,
        belief.first_seen,
        belief.last_seen,
        belief.misses,
        belief.region,
        belief.region_class,
        belief.roi,
        sorted(belief.sources),
        belief.observations,
        belief.class_name,
        belief.recording,
    )


def step_state(step: TrackStep) -> tuple:
    return (
        [belief_state(b) for b in step.changed],
        step.assigned,
        step.created,
        step.missed,
        step.gone,
        step.association,
    )


def tables(path: Path) -> dict[str, list[tuple]]:
    conn = sqlite3.connect(path)
    try:
        return {name: sorted(conn.execute(f"SELECT * FROM {name}").fetchall(), key=repr) for name in TABLES}
    finally:
        conn.close()


@pytest.mark.parametrize("seed", range(6))
def test_row_level_update_gives_the_steps_and_the_store_of_the_general_way(
    tmp_path: Path, seed: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    rng = np.random.default_rng(seed)
    quirks = seed % 2 == 1
    places = rng.uniform([-2.0, 0.0, 0.7], [2.0, 4.0, 0.9], size=(12, 3))
    config = TrackerConfig(gone_after=3.0)
    tracker = BeliefTracker(config, class_test=is_subclass)
    row_level = BeliefStore(tmp_path / "rows.sqlite", tracker=tracker)
    general = BeliefStore(tmp_path / "general.sqlite", tracker=GeneralTracker(config, class_test=is_subclass))
    on_rows, decoded = [], []
    row_update, update = RowUpdate.update, BeliefTracker.update

    def counted_row_update(self: RowUpdate, *args: object) -> tuple | None:
        row = row_update(self, *args)  # type: ignore[arg-type]
        if row is not None:
            on_rows.append(1)
        return row

    def counted_update(*args: object) -> None:
        decoded.append(1)
        update(tracker, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(RowUpdate, "update", counted_row_update)
    monkeypatch.setattr(tracker, "update", counted_update)
    at = 0.0
    frames = 40
    for index in range(frames):
        objects = random_frame(rng, places, quirks)
        camera = camera_at(np.array([0.0, -1.0, 0.8])) if quirks and index % 3 == 0 else None
        at += float(rng.choice([0.0, 0.5, 1.0, 2.0, -0.5] if quirks else [0.5, 1.0]))
        stamp: float = int(at) if at == int(at) and index % 5 == 0 else at  # integer times as callers may pass
        mine = row_level.integrate(objects, stamp, camera=camera)
        theirs = general.integrate(objects, stamp, camera=camera)
        assert step_state(mine) == step_state(theirs), f"frame {index}"
    row_level.close()
    general.close()
    assert tables(tmp_path / "rows.sqlite") == tables(tmp_path / "general.sqlite")
    assert len(on_rows) >= 10  # the row-level update did the common case
    assert len(decoded) >= (5 if quirks else 0)  # and the general way the others


def test_changed_beliefs_are_made_once_on_first_read_and_compare_as_a_tuple() -> None:
    made: list[int] = []
    stored = ObjectBelief(id=1, frame="world", position=np.zeros(3))

    def make() -> ObjectBelief:
        made.append(2)
        return ObjectBelief(id=2, frame="world", position=np.ones(3))

    changed = ChangedBeliefs([stored, make])
    assert len(changed) == 2 and made == []
    assert changed[0] is stored and made == []
    second = changed[1]
    assert [b.id for b in changed] == [1, 2] and changed[1] is second and made == [2]
    assert changed[:1] == (stored,) and changed == (stored, second) and changed != (stored,)
