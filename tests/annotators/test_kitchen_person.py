"""The person in the built-in kitchen: scripted poses, rendering, and the real people detectors see it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from annotators.cloud.people import find_people
from annotators.image.human_pose import LANDMARKS, PoseModelError, detect_landmarks, load_pose_model
from annotators.readers.frame_readers import KitchenSceneReader
from annotators.simulation.kitchen_person import (
    PERSON_OBJECT_ID,
    Motion,
    PersonScript,
    Posture,
    person_spec_pose,
    person_view,
    pose_person,
    target_point,
)
from annotators.simulation.kitchen_scene import render_kitchen


def _cloud(scene):
    k = scene.intrinsics
    z = scene.depth.astype(np.float32).copy()
    z[z == 0] = np.nan
    u, v = np.meshgrid(np.arange(k.width), np.arange(k.height))
    return np.dstack([(u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z]).astype(np.float32)


def _camera(scene, world: np.ndarray) -> np.ndarray:
    return (scene.world_to_cam @ np.r_[world, 1.0])[:3]


def test_without_a_person_the_kitchen_renders_exactly_as_before() -> None:
    plain, none = render_kitchen("table"), render_kitchen("table", person=None)
    assert np.array_equal(plain.color, none.color) and np.array_equal(plain.depth, none.depth)
    assert plain.person is None and not (plain.object_ids == PERSON_OBJECT_ID).any()


@pytest.mark.parametrize("target", ["red_cup", "bowl", "cereal_box", "fridge"])
def test_a_pointing_arm_is_straight_and_its_ray_passes_through_the_target(target: str) -> None:
    pose = person_spec_pose(f"point:{target}@0.3,0.8")
    moved = [  # the raised arm: its elbow is no longer below its shoulder
        s
        for s in ("left", "right")
        if np.linalg.norm((pose.joint(f"{s}_elbow") - pose.joint(f"{s}_shoulder"))[:2]) > 0.06
    ]
    assert len(moved) == 1
    shoulder, elbow, wrist = (pose.joint(f"{moved[0]}_{n}") for n in ("shoulder", "elbow", "wrist"))
    ray = (wrist - shoulder) / np.linalg.norm(wrist - shoulder)
    goal = target_point(target) - shoulder
    assert np.linalg.norm(np.cross(ray, goal)) < 1e-9 and ray @ goal > 0
    assert np.linalg.norm(np.cross(elbow - shoulder, ray)) < 1e-9
    assert pose.activity == "pointing" and pose.target_name == target


@settings(max_examples=30, deadline=None)
@given(
    x=st.floats(-1.0, 1.0),
    y=st.floats(0.55, 1.0),
    yaw=st.floats(-math.pi, math.pi),
    arm=st.sampled_from(["hang", "wave"]),
)
def test_limbs_keep_their_lengths_in_every_posture(x: float, y: float, yaw: float, arm: str) -> None:
    pose = pose_person(Posture(x, y, yaw, arm, phase=yaw))
    for side in ("left", "right"):
        upper = np.linalg.norm(pose.joint(f"{side}_elbow") - pose.joint(f"{side}_shoulder"))
        fore = np.linalg.norm(pose.joint(f"{side}_wrist") - pose.joint(f"{side}_elbow"))
        assert upper == pytest.approx(0.29, abs=0.04) and fore == pytest.approx(0.26, abs=0.04)
    assert np.allclose(pose.position[:2], (x, y))


def test_the_script_stands_points_walks_and_points_at_a_region() -> None:
    script = PersonScript.storage_mission("bowl", "fridge")
    kinds = [script.pose_at(t) for t in (1.0, 3.5, 7.0, 10.5)]
    assert [p.activity for p in kinds] == ["standing", "pointing", "walking", "pointing"]
    assert (kinds[1].target_name, kinds[3].target_name) == ("bowl", "fridge")
    walk = script.motions[2]
    start, end = script.pose_at(5.0).position[:2], script.pose_at(9.0).position[:2]
    assert np.allclose(start, walk.path[0]) and np.allclose(end, walk.path[-1])
    path = np.array([script.pose_at(t).position[:2] for t in np.linspace(5.0, 9.0, 9)])
    steps = np.linalg.norm(np.diff(path, axis=0), axis=1)
    assert np.allclose(steps, steps[0], atol=1e-6)  # constant speed along the path


@pytest.mark.parametrize("spec", ["point", "point:sofa", "jump", "stand@1", "stand:red_cup", "point:red_cup@a,b"])
def test_a_bad_spec_is_refused_with_the_reason(spec: str) -> None:
    with pytest.raises(ValueError, match=r"person spec|unknown pointing target"):
        person_spec_pose(spec)


def test_bad_motions_are_refused() -> None:
    with pytest.raises(ValueError, match="two waypoints"):
        Motion("walk", 1.0, ((0.0, 0.8),))
    with pytest.raises(ValueError, match="names its target"):
        Motion("point", 1.0, ((0.0, 0.8),))
    with pytest.raises(ValueError, match="at least one motion"):
        PersonScript(())


@pytest.mark.parametrize("spec", ["stand", "point:red_cup@-0.4,0.8", "point:fridge@0.3,0.75"])
def test_the_depth_people_detector_finds_the_person_where_it_stands(spec: str) -> None:
    pose = person_spec_pose(spec)
    scene = render_kitchen(person_view("room"), person=pose)  # with the floor in view to stand people on
    up = scene.world_to_cam[:3, :3] @ np.array([0.0, 0.0, 1.0])
    people = find_people(_cloud(scene), scene.depth > 0, up)
    truth = scene.object_ids == PERSON_OBJECT_ID
    best = max(people, key=lambda p: np.count_nonzero(p.mask & truth))
    assert np.count_nonzero(best.mask & truth) > 0.8 * np.count_nonzero(truth)
    seen = _cloud(scene)[truth]  # the person's visible surface, from the ground-truth pixels
    assert np.linalg.norm(best.centroid[[0, 2]] - seen.mean(axis=0)[[0, 2]]) < 0.05  # on the floor: x and depth
    # the body axis lies behind its visible surface
    standing = _camera(scene, pose.position + np.array([0.0, 0.0, 0.9]))
    assert abs(best.centroid[0] - standing[0]) < 0.1 and 0.0 < standing[2] - best.centroid[2] < 0.25


@pytest.mark.parametrize("spec", ["stand", "point:cereal_box@0.5,0.8", "point:fridge@-0.3,0.8", "wave"])
def test_the_pose_model_sees_the_figure_with_its_keypoints_on_the_right_joints(spec: str) -> None:
    try:
        model = load_pose_model()
    except PoseModelError as error:
        pytest.skip(str(error))
    pose = person_spec_pose(spec)
    scene = render_kitchen(person_view(), person=pose)
    found = detect_landmarks(model, scene.color)
    assert found is not None
    pixels, _ = found
    for joint in ("nose", "left_shoulder", "right_shoulder", "left_wrist", "right_wrist"):
        truth = scene.intrinsics.project(_camera(scene, pose.joint(joint))[None])[0]
        assert np.linalg.norm(pixels[LANDMARKS.index(joint)] - truth) < 30, joint


def test_the_kitchen_reader_renders_a_person_from_the_person_view() -> None:
    reader = KitchenSceneReader(person="point:bowl")
    assert reader.choose_view() == "person"
    assert KitchenSceneReader().choose_view() == "table"
