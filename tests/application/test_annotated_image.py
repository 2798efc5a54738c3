"""``--annotated-image`` for every query kind, on the built-in kitchen: the pictures are checked where a user looks
(the pointing ray runs from the hand to the pointed object, placements cover only free shelf, keypoint dots sit on
the person's joints, the tracked cup is marked). Ground truth (the scripted person, the storage layout) only scores.
Every picture is saved in ``test-artifacts/``."""

from __future__ import annotations

import json
import threading
from collections.abc import Iterator
from pathlib import Path

import cv2
import numpy as np
import pytest

from annotators.readers.streams import KitchenCameraStream
from annotators.simulation.kitchen_person import person_spec_pose, person_view
from annotators.simulation.kitchen_scene import DEFAULT_INTRINSICS, FRIDGE_SHELF_HEIGHTS, kitchen_objects
from annotators.simulation.storage import covers, half_blocked_layout, on_shelf
from robokudo.application import cli
from robokudo.application.annotated_image import (
    ANSWER_COLOR,
    KEYPOINT_COLOR,
    PLACEMENT_COLOR,
    RAY_COLOR,
    TARGET_COLOR,
    TRACK_COLOR,
    draw_answer,
    write_image,
)
from robokudo.application.service import AnsweringService, TickProgress
from robokudo.core.cas import CAS
from robokudo.core.types import BodyKeypoints, CameraInfo, ColorImage, PersonHypothesis, QueryAnswer
from tests.annotators.test_free_space_kitchen import placements_tree
from tests.application.server.conftest import REPO
from tests.application.test_cli_query import query
from tests.kitchen_service import kitchen_service_with_pose, require_pose_model

ARTIFACTS = REPO / "test-artifacts" / "annotated_image"
POINT_AT_BOWL = "point:bowl@0.3,0.7"


def picture_of(path: Path) -> np.ndarray:
    image = cv2.imread(str(path))
    assert image is not None, path
    return cv2.cvtColor(image, cv2.COLOR_BGR2RGB)


def painted(picture: np.ndarray, rgb: tuple[int, int, int]) -> np.ndarray:
    """Pixel positions (x, y), Nx2, drawn in exactly ``rgb`` (not the text of a label on its black background)."""
    labels = cv2.dilate(np.all(picture == 0, axis=2).astype(np.uint8), np.ones((9, 9), np.uint8)).astype(bool)
    rows, columns = np.nonzero(np.all(picture == rgb, axis=2) & ~labels)
    return np.column_stack((columns, rows)).astype(np.float64)


def to_pixels(world: np.ndarray, cam_to_world: np.ndarray) -> np.ndarray:
    """Ground truth world points (Nx3) in a kitchen picture."""
    inverse = np.linalg.inv(cam_to_world)
    camera = np.asarray(world, dtype=np.float64).reshape(-1, 3) @ inverse[:3, :3].T + inverse[:3, 3]
    return DEFAULT_INTRINSICS.project(camera)


def pointing_hand(spec: str, cam_to_world: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The picture position of the scripted person's wrist nearer to the target's picture position."""
    pose = person_spec_pose(spec)
    wrists = to_pixels(np.stack([pose.joint(f"{side}_wrist") for side in ("left", "right")]), cam_to_world)
    return wrists[np.argmin(np.linalg.norm(wrists - target, axis=1))]


def ends(pixels: np.ndarray, near: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The two ends of a drawn line (along its main direction), the one nearer to ``near`` first."""
    centred = pixels - pixels.mean(axis=0)
    axis = np.linalg.svd(centred, full_matrices=False)[2][0]
    first, last = pixels[np.argmin(centred @ axis)], pixels[np.argmax(centred @ axis)]
    return (first, last) if np.linalg.norm(first - near) <= np.linalg.norm(last - near) else (last, first)


def distance_to_line(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    along = (b - a) / np.linalg.norm(b - a)
    offset = points - a
    return np.abs(offset[:, 0] * along[1] - offset[:, 1] * along[0])


@pytest.fixture(scope="module")
def service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[AnsweringService]:
    """One answering service on the kitchen for the module; each test puts its person in."""
    yield from kitchen_service_with_pose(tmp_path_factory, "pictures")


def test_run_numbers_every_hypothesis_of_a_hand_authored_tree(capsys: pytest.CaptureFixture[str]) -> None:
    path = ARTIFACTS / "run_tabletop.png"
    assert cli.main(["run", "tabletop", "--annotated-image", str(path)]) == 0
    assert f"annotated image: {path}" in capsys.readouterr().out
    picture = picture_of(path)
    boxes = painted(picture, ANSWER_COLOR)
    assert boxes.shape[0] > 300  # a box (2 px wide) around each of the three table objects
    assert boxes[:, 0].min() > 100 and boxes[:, 0].max() < 560


def test_pointing_at_an_object_draws_the_ray_from_the_hand_to_the_object(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    require_pose_model()
    path = ARTIFACTS / "pointing_object.png"
    status, out, err = query(
        capsys, "which object is the person pointing at", "--person", POINT_AT_BOWL, "--json",
        "--store", str(tmp_path / "b.sqlite"), "--annotated-image", str(path),
    )  # fmt: skip
    assert status == 0, err
    assert f"annotated image: {path}" in err
    answer = json.loads(out)
    x0, y0, x1, y1 = answer["objects"][0]["roi"]
    picture = picture_of(path)
    ray = painted(picture, RAY_COLOR)
    assert ray.shape[0] > 100
    hand = pointing_hand(POINT_AT_BOWL, person_view(), np.array([(x0 + x1) / 2, (y0 + y1) / 2]))
    start, end = ends(ray, hand)
    assert np.linalg.norm(start - hand) < 25  # it starts at the person's hand (the pose model's wrist)
    assert x0 - 6 <= end[0] <= x1 + 6 and y0 - 6 <= end[1] <= y1 + 6  # and ends on the pointed object
    assert np.all(distance_to_line(ray, start, end) < 5.5)  # straight between them (the hand's dot)
    target = painted(picture, TARGET_COLOR)  # the target box around the object's box
    assert target.shape[0] > 100
    assert target[:, 0].min() >= x0 - 5 and target[:, 0].max() <= x1 + 4
    assert target[:, 1].min() >= y0 - 5 and target[:, 1].max() <= y1 + 4


def test_pointing_at_a_region_outlines_the_region_and_the_ray_reaches_it(service: AnsweringService) -> None:
    service.person = "point:fridge@-0.2,0.7"
    outcome = service.answer("where is the person pointing")
    regions = service.kb.regions()
    picture = draw_answer(outcome.tree.cas, regions=regions)
    write_image(picture, ARTIFACTS / "pointing_region.png")
    assert outcome.answer.pointing is not None and outcome.answer.pointing.region == "fridge"
    (fridge,) = [r for r in regions if r.name == "fridge"]
    info = outcome.tree.cas.view(CameraInfo)
    assert info is not None and info.cam_to_world is not None
    outline = painted(picture, TARGET_COLOR)
    assert outline.shape[0] > 300
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64)
    box = signs * np.asarray(fridge.size) / 2 @ fridge.pose[:3, :3].T + fridge.pose[:3, 3]
    corners = to_pixels(box, info.cam_to_world)
    hull = cv2.convexHull(corners.astype(np.float32))
    inside = [cv2.pointPolygonTest(hull, (float(x), float(y)), True) for x, y in outline]
    assert min(inside) > -3  # the outline is the fridge box's outline, on screen
    ray = painted(picture, RAY_COLOR)
    hand = pointing_hand(service.person, info.cam_to_world, corners.mean(axis=0))
    _, far = ends(ray, hand)
    assert cv2.pointPolygonTest(hull, (float(far[0]), float(far[1])), True) > -3  # the ray reaches the fridge


def test_a_person_gets_keypoint_dots_on_the_joints_and_a_skeleton(service: AnsweringService) -> None:
    service.person = "wave@0.2,0.7"
    outcome = service.answer("detect { human: {} }")
    cas = outcome.tree.cas
    picture = draw_answer(cas)
    write_image(picture, ARTIFACTS / "human.png")
    (person,) = cas.annotations(PersonHypothesis)
    keypoints = person.first(BodyKeypoints)
    assert keypoints is not None
    rows, columns = np.nonzero(np.all(picture == KEYPOINT_COLOR, axis=2))  # (over a label too)
    dots = np.column_stack((columns, rows)).astype(np.float64)
    pixels = np.asarray(keypoints.pixels)
    height, width = picture.shape[:2]
    shown = (np.asarray(keypoints.visibility) >= 0.5) & np.all((pixels >= 0) & (pixels < (width, height)), axis=1)
    assert shown.sum() >= 15
    for pixel in pixels[shown]:  # a dot on every visible keypoint in the picture
        assert np.min(np.linalg.norm(dots - pixel, axis=1)) <= 1.0
    info = cas.view(CameraInfo)
    assert info is not None and info.cam_to_world is not None
    pose = person_spec_pose(service.person)
    for joint in ("nose", "left_shoulder", "right_shoulder", "left_elbow", "right_elbow", "left_wrist", "right_wrist"):
        truth = to_pixels(pose.joint(joint), info.cam_to_world)[0]  # and the dots sit on the figure's joints
        assert np.min(np.linalg.norm(dots - truth, axis=1)) < 30, joint
    original = cas.view(ColorImage)
    assert original is not None and not np.array_equal(original.image, picture)  # drawn on a copy
    print(outcome.answer.summary())
    # the waving person (an arm out to the side: broader than any object a robot handles) is answered
    (answered,) = outcome.answer.objects
    assert answered.class_label == "human"


def test_free_places_cover_only_free_shelf_and_are_numbered(service: AnsweringService, tmp_path: Path) -> None:
    layout = half_blocked_layout()
    cas, placements = placements_tree(service.kb, layout, tmp_path / "b.sqlite")
    picture = draw_answer(cas)
    write_image(picture, ARTIFACTS / "free_space_half_blocked.png")
    assert placements
    original = np.asarray(cas.view(ColorImage).image, dtype=np.float64)  # type: ignore[union-attr]
    blended = 0.35 * np.asarray(PLACEMENT_COLOR, dtype=np.float64) + 0.65 * original
    filled = np.all(np.abs(picture - blended) <= 1.5, axis=2) & np.any(picture != original, axis=2)
    filled = cv2.erode(filled.astype(np.uint8), np.ones((5, 5), np.uint8)).astype(bool)
    assert filled.sum() > 2000
    info = cas.view(CameraInfo)
    assert info is not None and info.cam_to_world is not None
    rows, columns = np.nonzero(filled)
    on_surface = shelf_points(columns, rows, info)
    assert on_shelf(on_surface).mean() > 0.99  # what is filled is the shelf ...
    for obj in layout.occupants():  # ... and never where an object stands
        assert not covers(obj, on_surface).any(), obj.name
    outlines = painted(picture, PLACEMENT_COLOR)
    assert outlines.shape[0] > 100


def shelf_points(columns: np.ndarray, rows: np.ndarray, info: CameraInfo) -> np.ndarray:
    """The world points on the upper shelf's top surface seen at the pixels."""
    k = info.intrinsics
    rays = np.column_stack(((columns - k.cx) / k.fx, (rows - k.cy) / k.fy, np.ones(columns.shape[0])))
    pose = np.asarray(info.cam_to_world)
    directions = rays @ pose[:3, :3].T
    t = (FRIDGE_SHELF_HEIGHTS[0] - pose[2, 3]) / directions[:, 2]
    return pose[:3, 3] + t[:, None] * directions


def test_tracking_marks_the_cup_and_its_trail(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    drawn: list[tuple[np.ndarray, CAS]] = []
    trail: list[tuple[float, float]] = []
    enough = threading.Event()
    with AnsweringService.open(tmp_path / "b.sqlite", hz=30, stream=KitchenCameraStream(rate_hz=30)) as service:
        service.run_in_background()
        handle = service.start("track the red cup")

        def after_tick(_: TickProgress) -> None:  # the engine thread: the run's CAS is complete and stays put
            pipeline = handle.pipeline
            answer = pipeline.cas.view(QueryAnswer)
            if pipeline.status.name != "SUCCESS" or answer is None or answer.answer.track is None:
                return
            if answer.answer.track.pixel is not None:
                trail.append(answer.answer.track.pixel)
            if len(trail) >= 3 and not enough.is_set():
                drawn.append((draw_answer(pipeline.cas, trail=trail), pipeline.cas))
                enough.set()

        handle.on_tick(after_tick)
        assert enough.wait(120), handle.reason
        handle.cancel()
    picture, cas = drawn[0]
    write_image(picture, ARTIFACTS / "track_red_cup.png")
    info = cas.view(CameraInfo)
    assert info is not None and info.cam_to_world is not None
    (cup,) = [o for o in kitchen_objects() if o.name == "red_cup"]
    truth = to_pixels(cup.position, info.cam_to_world)[0]
    marks = painted(picture, TRACK_COLOR)
    assert marks.shape[0] > 100  # the cup's box, the estimate's cross, the trail
    near = marks[np.linalg.norm(marks - truth, axis=1) < 10]
    assert near.shape[0] >= 10  # the cross on the cup's centre
