"""The beliefs a store keeps decoded between frames change nothing: a store that keeps them and one that decodes
every row afresh write the very same rows and take the same steps, through re-sightings, conflicting statements,
appearance blending, misses and gone marks, another connection's writes, and a frame that failed and rolled back."""

from __future__ import annotations

import sqlite3
from pathlib import Path

import numpy as np
import pytest

from reasoning.beliefs.store import BeliefStore
from reasoning.fusion.association import CameraModel
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import Evidence
from reasoning.fusion.tracking import BeliefTracker, TrackerConfig
from robokudo.core.types import CameraIntrinsics

TABLES = ("objects", "objects_place", "attribute_index", "observations", "classes", "meta")
PARENT = {"LactoseFreeMilk": "Milk"}
CLASSES = ("Milk", "LactoseFreeMilk", "Cup", "Bowl")
COLORS = ("red", "white", "blue")


def is_subclass(a: str, b: str) -> bool:
    return a == b or PARENT.get(a) == b


def contents(path: Path) -> dict[str, list[tuple]]:
    with sqlite3.connect(path) as conn:
        return {table: sorted(conn.execute(f"SELECT * FROM {table}").fetchall(), key=repr) for table in TABLES}


def frame(rng: np.random.Generator, k: int) -> list[FrameObject]:
    """Objects on a 4 x 2 grid seen with noise, a few of them each frame, with drifting statements and (every
    third frame) colour histograms; now and then one far away (a new object)."""
    seen = []
    for place in rng.choice(8, size=int(rng.integers(1, 6)), replace=False).tolist():
        position = np.array([place % 4 * 0.5, place // 4 * 0.5, 0.8]) + rng.normal(0, 0.01, 3)
        evidence = [
            Evidence("class", CLASSES[(place + int(rng.integers(2))) % 4], float(rng.uniform(0.4, 0.95)), "Detector"),
            Evidence("color", COLORS[(place + k // 20) % 3], float(rng.uniform(0.5, 0.9)), "ColorExpert"),
        ]
        histogram = rng.dirichlet(np.ones(8)) if k % 3 == 0 else None
        seen.append(
            FrameObject(
                position,
                "world",
                dimensions=np.array([0.2, 0.1, 0.07]) * rng.uniform(0.9, 1.1),
                appearance=histogram,
                evidence=evidence,
                sources={"Segmenter", "Detector", "ColorExpert"},
                roi=(place, 0, place + 10, 10),
                confidence=float(rng.uniform(0.5, 1.0)),
            )
        )
    if k % 7 == 0:
        seen.append(FrameObject(np.array([5.0 + k, 0.0, 0.8]), "world", evidence=[Evidence("class", "Bowl", 0.8, "D")]))
    return seen


def camera_over_the_grid() -> CameraModel:
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = (1, 0, 0), (0, 0, -1), (0, 1, 0), (0.75, -2.0, 0.8)
    return CameraModel(CameraIntrinsics(500.0, 500.0, 320.0, 240.0, 640, 480), pose)


class FailingError(Exception):
    pass


@pytest.mark.parametrize("seed", [1, 2])
def test_kept_beliefs_write_what_decoded_ones_write(tmp_path: Path, seed: int) -> None:
    paths = tmp_path / "kept.sqlite", tmp_path / "decoded.sqlite"
    config = TrackerConfig(gone_after=3.0)
    kept = BeliefStore(paths[0], tracker=BeliefTracker(config, class_test=is_subclass), history_limit=20)
    decoded = BeliefStore(
        paths[1], tracker=BeliefTracker(config, class_test=is_subclass), history_limit=20, working_copies=0
    )
    camera = camera_over_the_grid()
    rng = np.random.default_rng(seed)
    reused = 0
    for k in range(80):
        objects = frame(rng, k)
        time = 1.0 + k * 0.4
        seen_by = camera if k % 4 == 0 else None
        if k == 30:  # another connection changes a belief both stores hold
            for path in paths:
                with BeliefStore(path) as other:
                    changed = other.get(1)
                    assert changed is not None
                    changed.position = changed.position + 0.02
                    changed.existence = -1.0
                    other.put([changed], is_subclass)
        if k == 50:  # a frame fails after the tracker changed the beliefs: nothing of it is stored
            for store in (kept, decoded):
                original = store._write_observations

                def fail(*args: object, _original: object = original) -> None:
                    raise FailingError

                store._write_observations = fail  # type: ignore[method-assign]
                with pytest.raises(FailingError):
                    store.integrate(objects, time, camera=seen_by)
                del store._write_observations
            assert contents(paths[0]) == contents(paths[1])
        before = {i: entry[1] for i, entry in kept._working.items()}
        a, b = (store.integrate(objects, time, camera=seen_by) for store in (kept, decoded))
        reused += sum(1 for belief in a.changed if before.get(belief.id) is belief)
        assert (a.assigned, a.created, a.missed, a.gone) == (b.assigned, b.created, b.missed, b.gone)
        assert contents(paths[0]) == contents(paths[1])
    assert reused > 100  # the kept beliefs were used, not decoded again
    kept.close()
    decoded.close()
