"""ActivityRecognizer: pointing, standing and waving from keypoint geometry (checked on the kitchen figure's
ground-truth joints in every direction), and the optional ONNX image-text model, loaded from a tiny model built
with onnx.helper."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import onnx
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from onnx import TensorProto, helper, numpy_helper

from annotators.image.human_pose import LANDMARKS
from annotators.people.activity import ActivityRecognizer, activity_scores
from annotators.people.image_text import ImageTextModel, ImageTextModelError, byte_tokens
from annotators.people.keypoints import arms
from annotators.people.pointing import arm_ray, box_point_nearest_ray, ranked
from annotators.simulation.kitchen_person import Posture, pose_person
from robokudo.core.types import BodyKeypoints

UP = np.array([0.0, 0.0, 1.0])


def _keypoints(joints: dict[str, np.ndarray]) -> BodyKeypoints:
    """World joints as BodyKeypoints (the world frame stands in for the camera's; landmarks it lacks are NaN)."""
    points = np.array([joints.get(name, np.full(3, np.nan)) for name in LANDMARKS], dtype=np.float64)
    return BodyKeypoints(
        names=LANDMARKS, pixels=np.zeros((len(LANDMARKS), 2)), points=points, visibility=np.ones(len(LANDMARKS))
    )


places = {"x": st.floats(-1.0, 1.0), "y": st.floats(0.5, 1.0), "yaw": st.floats(-math.pi, math.pi)}


@settings(max_examples=40, deadline=None)
@given(**places, tx=st.floats(-1.0, 1.5), ty=st.floats(-0.4, 1.0), tz=st.floats(0.0, 1.4))
def test_an_arm_raised_away_from_the_body_towards_any_target_is_pointing(
    x: float, y: float, yaw: float, tx: float, ty: float, tz: float
) -> None:
    target = np.array([tx, ty, tz])
    pose = pose_person(Posture(x, y, yaw, "point", tuple(target)))
    side = max(  # the arm the figure points with: the one whose wrist is held farthest out from its shoulder
        ("left", "right"),
        key=lambda arm: np.linalg.norm((pose.joint(f"{arm}_wrist") - pose.joint(f"{arm}_shoulder"))[:2]),
    )
    reach = target - pose.joint(f"{side}_shoulder")
    if np.linalg.norm(reach[:2]) < math.sin(math.radians(45.0)) * np.linalg.norm(reach):
        return  # within 45 degrees of straight down: near the recognizer's 35-degree limit, hardly a gesture
    if np.linalg.norm(reach) < 0.8:
        return  # within the arm's reach the hand touches the target rather than points at it
    scores, arm = activity_scores(_keypoints(dict(pose.joints)), UP)
    assert max(scores, key=scores.get) == "pointing" and arm in ("left", "right")
    (moved,) = [a for a in arms(_keypoints(dict(pose.joints))) if a.side == arm]
    ray = arm_ray(moved)
    assert (
        np.degrees(
            np.arccos(np.clip(ray.direction @ (target - ray.origin) / np.linalg.norm(target - ray.origin), -1, 1))
        )
        < 1.0
    )


@settings(max_examples=30, deadline=None)
@given(**places, phase=st.floats(0.0, 2 * math.pi))
def test_standing_and_waving_are_told_apart(x: float, y: float, yaw: float, phase: float) -> None:
    standing = pose_person(Posture(x, y, yaw, "hang"))
    waving = pose_person(Posture(x, y, yaw, "wave", phase=phase))
    stand_scores, _ = activity_scores(_keypoints(dict(standing.joints)), UP)
    wave_scores, arm = activity_scores(_keypoints(dict(waving.joints)), UP)
    assert max(stand_scores, key=stand_scores.get) == "standing"
    assert max(wave_scores, key=wave_scores.get) == "waving" and arm == "right"
    # without the camera pose the body's own axis (shoulders to hips) serves as down
    assert max(activity_scores(_keypoints(dict(waving.joints)), None)[0].items(), key=lambda i: i[1])[0] == "waving"


def test_without_arm_depth_nothing_is_pointing() -> None:
    pose = pose_person(Posture(0.0, 0.7, 0.0, "point", (0.0, -0.1, 0.8)))
    joints = {k: v for k, v in pose.joints.items() if "wrist" not in k}
    scores, arm = activity_scores(_keypoints(joints), UP)
    assert scores["pointing"] == 0.0 and arm == ""


def test_the_ray_picks_the_nearest_direction_and_a_box_is_reached_at_its_nearest_point() -> None:
    pose = pose_person(Posture(0.0, 0.7, -math.pi / 2, "point", (0.26, 0.0, 0.785)))
    (arm,) = [a for a in arms(_keypoints(dict(pose.joints))) if np.linalg.norm((a.elbow - a.shoulder)[:2]) > 0.06]
    ray = arm_ray(arm)
    order = ranked(ray, [("cup", np.array([0.0, -0.12, 0.8])), ("bowl", np.array([0.26, 0.0, 0.785]))])
    assert order[0][1] == "bowl" and order[0][0] < math.radians(1.0) < order[1][0]
    box = np.eye(4)
    box[:3, 3] = (0.26, 0.0, 0.95)
    nearest = box_point_nearest_ray(ray, box, np.array([1.2, 0.8, 0.5]))
    # the ray enters the box: the nearest point is on the ray, inside the box
    assert np.all(np.abs(nearest - box[:3, 3]) <= np.array([0.6, 0.4, 0.25]) + 1e-9)
    along = nearest - ray.origin
    assert np.linalg.norm(along - (along @ ray.direction) * ray.direction) < 0.03


# ----------------------------------------------------------------------------------------- image-text model
def image_text_model(path: Path, size: int = 16, length: int = 32, dim: int = 4) -> Path:
    """A tiny CLIP-style model: image embedding = mean colour per channel (+ a constant), text embedding = a
    fixed linear map of the byte histogram - real input feeding, real output decoding."""
    image = helper.make_tensor_value_info("pixel_values", TensorProto.FLOAT, [1, 3, size, size])
    text = helper.make_tensor_value_info("input_ids", TensorProto.INT64, [1, length])
    image_out = helper.make_tensor_value_info("image_embeds", TensorProto.FLOAT, [1, dim])
    text_out = helper.make_tensor_value_info("text_embeds", TensorProto.FLOAT, [1, dim])
    rng = np.random.default_rng(3)
    weights = numpy_helper.from_array(rng.normal(size=(length, dim)).astype(np.float32), "w")
    pad = numpy_helper.from_array(np.ones((1, 1), np.float32), "one")
    axes = numpy_helper.from_array(np.array([2, 3], np.int64), "axes")
    shape = numpy_helper.from_array(np.array([1, 3], np.int64), "shape")
    nodes = [
        helper.make_node("ReduceMean", ["pixel_values", "axes"], ["mean"], keepdims=0),
        helper.make_node("Reshape", ["mean", "shape"], ["flat"]),
        helper.make_node("Concat", ["flat", "one"], ["image_embeds"], axis=1),
        helper.make_node("Cast", ["input_ids"], ["ids"], to=TensorProto.FLOAT),
        helper.make_node("MatMul", ["ids", "w"], ["text_embeds"]),
    ]
    graph = helper.make_graph(
        nodes, "tiny_clip", [image, text], [image_out, text_out], initializer=[weights, pad, axes, shape]
    )
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 18)])
    model.ir_version = 8
    onnx.checker.check_model(model)
    onnx.save(model, str(path))
    return path


def test_the_image_text_model_loads_and_scores_prompts(tmp_path: Path) -> None:
    model = ImageTextModel.load(image_text_model(tmp_path / "clip.onnx"))
    assert (model.size, model.length) == (16, 32)
    image = np.full((40, 30, 3), 200, np.uint8)
    scores = model.scores(image, ["a person pointing", "a person standing", "a person waving"])
    assert len(scores) == 3 and abs(sum(scores) - 1.0) < 1e-9 and all(0 <= s <= 1 for s in scores)
    # the scores follow the cosines the graph computes
    a, b = model._embed(image, "a person pointing")
    assert a.shape == (4,) and b.shape == (4,)
    assert list(byte_tokens("ab", 4)[0]) == [98, 99, 0, 0]
    with pytest.raises(ValueError, match="RGB"):
        model.scores(np.zeros((4, 4), np.uint8), ["x"])


def test_a_missing_or_unfit_model_is_refused(tmp_path: Path) -> None:
    with pytest.raises(ImageTextModelError, match="no image-text model"):
        ImageTextModel.load(tmp_path / "none.onnx")
    (tmp_path / "bad.onnx").write_bytes(b"not a model")
    with pytest.raises(ImageTextModelError, match="cannot be loaded"):
        ImageTextModel.load(tmp_path / "bad.onnx")
    from tests.annotators.onnx_models import one_box_model

    with pytest.raises(ImageTextModelError, match="needs one 4-D image input"):
        ImageTextModel.load(one_box_model(tmp_path / "detector.onnx"))
    with pytest.raises(ValueError, match="unknown activities"):
        ActivityRecognizer(prompts={"dancing": "a person dancing"})
