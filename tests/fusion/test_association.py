"""Association cost, gates, optimal assignment, visibility and the belief life cycle (unit level).

Observations here come from the kitchen scene's ground truth (object masks back-projected with the depth
image): they test the association logic alone. The identity tests on the real experts' output are in
``test_identity.py``.
"""

from __future__ import annotations

import numpy as np
import pytest

from reasoning.fusion.association import (
    INFEASIBLE,
    AssociationConfig,
    CameraModel,
    assign,
    associate,
    bhattacharyya_distance,
    pair_cost,
    visible_from,
)
from reasoning.fusion.frame import FrameObject
from reasoning.fusion.rule import Evidence
from reasoning.fusion.tracking import GONE, PRESENT, BeliefTracker, TrackerConfig

kitchen_scene = pytest.importorskip("annotators.simulation.kitchen_scene")


def obs(x: float, y: float = 0.0, z: float = 0.0, **kwargs: object) -> FrameObject:
    return FrameObject(position=np.array([x, y, z]), frame="world", **kwargs)  # type: ignore[arg-type]


class Ids:
    def __init__(self) -> None:
        self.next = 1

    def __call__(self) -> int:
        self.next += 1
        return self.next - 1


def test_optimal_assignment_beats_greedy_nearest_neighbour() -> None:
    beliefs = [obs(0.0), obs(0.12)]
    observations = [obs(0.01), obs(-0.04)]  # greedy would give b0 to o0 and leave o1 without a partner
    result = associate(observations, beliefs)
    assert sorted((i, j) for i, j, _ in result.matches) == [(0, 1), (1, 0)]
    assert result.new == () and result.unmatched == ()


def test_gates_reject_far_other_frame_other_size_other_appearance_and_penalise_other_class() -> None:
    config = AssociationConfig()
    base = obs(0.0, dimensions=np.array([0.2, 0.1, 0.1]))
    assert pair_cost(obs(0.3), base, config) == INFEASIBLE
    camera_frame = FrameObject(position=np.zeros(3), frame="camera")
    assert pair_cost(camera_frame, base, config) == INFEASIBLE
    assert pair_cost(obs(0.01, dimensions=np.array([0.9, 0.5, 0.1])), base, config) == INFEASIBLE
    assert pair_cost(obs(0.01, dimensions=np.array([0.21, 0.1, 0.1])), base, config) < 1.0
    # issue 13: a disjoint class is no gate (one object classified two ways stays one belief), only a penalty
    other_class = pair_cost(obs(0.0), base, config, observation_classes={"Cup"}, belief_class="Milk")
    assert other_class == pytest.approx(config.class_penalty)
    subclass = {("LactoseFreeMilk", "Milk")}
    assert pair_cost(
        obs(0.0),
        base,
        config,
        observation_classes={"LactoseFreeMilk"},
        belief_class="Milk",
        class_test=lambda a, b: a == b or (a, b) in subclass,
    ) == pytest.approx(0.0)
    red = np.array([1.0, 0.0, 0.0, 0.0])
    blue = np.array([0.0, 0.0, 0.0, 1.0])
    assert bhattacharyya_distance(red, red) == pytest.approx(0.0)
    assert bhattacharyya_distance(red, blue) == pytest.approx(1.0)
    assert pair_cost(obs(0.0, appearance=red), obs(0.0, appearance=blue), config) == INFEASIBLE
    assert pair_cost(obs(0.0), obs(0.0), config, observation_colors={"red"}, belief_color="blue") == pytest.approx(
        config.color_penalty
    )


def test_assignment_of_empty_and_single_problems() -> None:
    empty = assign(np.zeros((0, 3)))
    assert empty.matches == () and empty.unmatched == (0, 1, 2)
    single = assign(np.array([[5.0, 1.0, INFEASIBLE]]))
    assert single.matches == ((0, 1, 1.0),)
    none = assign(np.array([[INFEASIBLE], [INFEASIBLE]]))
    assert none.matches == () and none.new == (0, 1) and none.unmatched == (0,)


def gt_observations(scene: object, min_pixels: int = 200) -> tuple[list[FrameObject], list[str]]:
    """Per-object observations from the renderer's ground truth (masks + depth back-projection)."""
    k = scene.intrinsics
    rows, cols = np.indices(scene.depth.shape)
    z = scene.depth
    camera_points = np.stack([(cols - k.cx) / k.fx * z, (rows - k.cy) / k.fy * z, z], axis=-1)
    world = camera_points @ scene.cam_to_world[:3, :3].T + scene.cam_to_world[:3, 3]
    observations, names = [], []
    for item in scene.objects:
        mask = (scene.object_ids == item.object_id) & (z > 0)
        if mask.sum() < min_pixels:
            continue
        points = world[mask]
        r, c = np.nonzero(mask)
        observations.append(
            FrameObject(
                position=points.mean(axis=0),
                frame="world",
                dimensions=np.sort(np.percentile(points, 98, axis=0) - np.percentile(points, 2, axis=0))[::-1],
                evidence=[Evidence("color", item.color, 0.8, "GroundTruthColor")],
                sources={"GroundTruthSegmenter"},
                roi=(int(c.min()), int(r.min()), int(c.max()) + 1, int(r.max()) + 1),
            )
        )
        names.append(item.name)
    return observations, names


def camera_of(scene: object) -> CameraModel:
    k = scene.intrinsics
    return CameraModel(k, scene.cam_to_world, depth=scene.depth)


def test_visibility_prediction_in_the_kitchen() -> None:
    scene = kitchen_scene.render_kitchen("table", noise=False)
    camera = camera_of(scene)
    cup = scene.object("red_cup").position
    assert visible_from(cup, camera)
    assert not visible_from(np.array([0.0, 1.6, 1.0]), camera)  # behind the back wall
    assert not visible_from(np.array([0.0, -3.0, 1.0]), camera)  # behind the camera
    assert not visible_from(np.array([3.0, 0.0, 0.8]), camera)  # outside the image


def test_ground_truth_tracking_over_five_views_and_a_moved_cup() -> None:
    tracker = BeliefTracker(TrackerConfig(gone_after=1.5))
    beliefs: dict[int, object] = {}
    ids = Ids()
    identity: dict[str, set[int]] = {}
    for t, view in enumerate(kitchen_scene.orbit_views(5)):
        scene = kitchen_scene.render_kitchen(view, seed=t)
        observations, names = gt_observations(scene)
        step = tracker.step(list(beliefs.values()), observations, float(t), ids, camera_of(scene))
        beliefs.update({b.id: b for b in step.changed})
        for name, belief_id in zip(names, step.assigned, strict=True):
            identity.setdefault(name, set()).add(belief_id)
    assert {"cereal_box", "red_cup", "bowl"} <= set(identity)
    assert all(len(found) == 1 for found in identity.values()), identity
    cup_id = next(iter(identity["red_cup"]))
    assert beliefs[cup_id].observations == 5 and beliefs[cup_id].confidence > 0.95
    confidence_before = beliefs[cup_id].confidence

    moved = {"red_cup": np.array([0.0, 0.25, 0.0])}
    for t in (5.0, 6.0, 7.0):
        scene = kitchen_scene.render_kitchen("table", seed=int(t), moved=moved)
        observations, names = gt_observations(scene)
        step = tracker.step(list(beliefs.values()), observations, t, ids, camera_of(scene))
        beliefs.update({b.id: b for b in step.changed})
        assigned = dict(zip(names, step.assigned, strict=True))
        assert assigned["cereal_box"] in identity["cereal_box"]
        assert assigned["bowl"] in identity["bowl"]
        assert assigned["red_cup"] != cup_id
    old_cup = beliefs[cup_id]
    # missed where it should have been visible at t=5 and t=6; gone once 1.5 s passed since t=4
    assert old_cup.misses == 2 and old_cup.confidence < confidence_before
    assert old_cup.status == GONE
    new_cup = beliefs[assigned["red_cup"]]
    assert new_cup.status == PRESENT and new_cup.observations == 3
    np.testing.assert_allclose(new_cup.position[:2], scene.object("red_cup").position[:2], atol=0.03)


def test_unseen_objects_outside_the_view_keep_their_confidence() -> None:
    tracker = BeliefTracker(TrackerConfig(gone_after=0.0))
    ids = Ids()
    table = kitchen_scene.render_kitchen("table", noise=False)
    observations, _ = gt_observations(table)
    far = obs(1.3, 0.8, 1.05)  # where the milk stands in the fridge, out of the table view
    step = tracker.step([], [*observations, far], 0.0, ids, camera_of(table))
    beliefs = list(step.changed)
    milk = next(b for b in beliefs if b.position[0] > 1.0)
    before = milk.existence
    step = tracker.step(beliefs, observations, 10.0, ids, camera_of(table))
    assert milk.id not in step.missed and milk.status == PRESENT and milk.existence == before
