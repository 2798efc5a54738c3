"""The waist form cue (issue 15, item 6): a drill standing on its battery is narrower across its grip than across
its body above and its battery below; cans, boxes, mugs and bowls never are. Measured on synthetic shapes (with a
property over random upright boxes and cylinders), on the real uoc frames' objects, and weighed by the knowledge
classifier with the ontology's profiles."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from annotators.classification.knowledge_classifier import Cues, Profile, score
from annotators.cloud.clutter import ClutterParameters
from annotators.cloud.form import WAIST_RATIO, measure_form, waist_evidence, waist_ratio
from annotators.geometry.support_frame import SupportFrame, plane_frame
from reasoning.evaluation.object_verdicts import load_labelled_objects
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.query_planner import class_profiles
from tests.annotators.guard_frames import LABELS, frame_points, segment_points, support_plane

CAMERA_TO_FRAME = np.eye(4)
CAMERA_TO_FRAME[2, 3] = 0.5
FRAME = SupportFrame(CAMERA_TO_FRAME, on_plane=True, guessed=False)
"""Upright frame with the camera 0.5 m above its origin; objects stand around y = 0.8 m."""


def box_face(x: tuple[float, float], z: tuple[float, float], y: float, rng: np.random.Generator, n: int) -> np.ndarray:
    """Points of the face of a box toward the camera: x and z ranges (metres) at depth ``y``."""
    return np.column_stack([rng.uniform(*x, n), np.full(n, y), rng.uniform(*z, n)])


def box_top(x: tuple[float, float], y: tuple[float, float], z: float, rng: np.random.Generator, n: int) -> np.ndarray:
    return np.column_stack([rng.uniform(*x, n), rng.uniform(*y, n), np.full(n, z)])


def standing_drill(rng: np.random.Generator) -> np.ndarray:
    """A drill on its battery seen from the side: a 12 cm battery (0-5 cm high), a 4 cm grip (5-13 cm) and a 20 cm
    body lying across the top (13-18 cm), each seen on its face toward the camera and its top."""
    battery = box_face((-0.06, 0.06), (0.0, 0.05), 0.76, rng, 600)
    battery_top = box_top((-0.06, 0.06), (0.76, 0.81), 0.05, rng, 200)
    grip = box_face((-0.02, 0.02), (0.05, 0.13), 0.77, rng, 500)
    body = box_face((-0.06, 0.14), (0.13, 0.18), 0.765, rng, 700)
    body_top = box_top((-0.06, 0.14), (0.765, 0.815), 0.18, rng, 300)
    return np.vstack([battery, battery_top, grip, body, body_top])


def near_half_cylinder(radius: float, height: float, rng: np.random.Generator, n: int = 1500) -> np.ndarray:
    angles = rng.uniform(np.pi, 2 * np.pi, n)
    z = rng.uniform(0.0, height, n)
    return np.column_stack([radius * np.cos(angles), 0.8 + radius * np.sin(angles), z])


def flaring_bowl(rng: np.random.Generator, n: int = 1500) -> np.ndarray:
    """The near half of a bowl's outer wall: 5 cm across at its foot, 16 cm at its rim 7 cm up."""
    z = rng.uniform(0.0, 0.07, n)
    radius = 0.025 + z * (0.055 / 0.07)
    angles = rng.uniform(np.pi, 2 * np.pi, n)
    return np.column_stack([radius * np.cos(angles), 0.8 + radius * np.sin(angles), z])


@pytest.mark.parametrize("seed", range(3))
def test_a_drill_standing_on_its_battery_is_waisted(seed: int) -> None:
    form = measure_form(standing_drill(np.random.default_rng(seed)), FRAME)
    assert form is not None and form.waisted and form.waist_confidence > 0.9


@pytest.mark.parametrize("seed", range(3))
def test_cans_bowls_and_mugs_are_not(seed: int) -> None:
    rng = np.random.default_rng(seed)
    for points in (near_half_cylinder(0.035, 0.1, rng), flaring_bowl(rng), near_half_cylinder(0.04, 0.09, rng)):
        form = measure_form(points, FRAME)
        assert form is not None and not form.waisted and form.waist_confidence > 0.9


def test_a_drill_lying_on_its_side_shows_no_waist() -> None:
    """Lying, the drill's parts all rest on the table: every height band spans its whole length."""
    rng = np.random.default_rng(0)
    lying = np.vstack(
        [
            box_top((-0.06, 0.14), (0.76, 0.81), 0.05, rng, 700),  # the body's side, 5 cm up
            box_top((-0.02, 0.02), (0.81, 0.89), 0.035, rng, 300),  # the grip's
            box_top((-0.06, 0.06), (0.89, 0.94), 0.06, rng, 400),  # the battery's
            box_face((-0.06, 0.14), (0.0, 0.05), 0.76, rng, 600),  # the body's near face down to the table
        ]
    )
    form = measure_form(lying, FRAME)
    assert form is not None and not form.waisted


def test_too_few_points_in_a_band_say_nothing() -> None:
    rng = np.random.default_rng(1)
    tall_thin = near_half_cylinder(0.03, 0.1, rng, n=30)
    assert waist_evidence(tall_thin, 0.0, 0.1) == (False, 0.0)
    assert waist_ratio(tall_thin, 0.0, 0.0) is None


@settings(max_examples=60, deadline=None)
@given(
    width=st.floats(0.03, 0.4),
    depth=st.floats(0.02, 0.3),
    height=st.floats(0.02, 0.4),
    turn=st.floats(0.0, np.pi),
    round_=st.booleans(),
    seed=st.integers(0, 2**16),
)
def test_an_upright_box_or_cylinder_is_never_waisted(
    width: float, depth: float, height: float, turn: float, round_: bool, seed: int
) -> None:
    """A prism standing upright has one cross-section at every height, seen from any side."""
    rng = np.random.default_rng(seed)
    if round_:
        points = near_half_cylinder(width / 2, height, rng)
    else:
        front = box_face((-width / 2, width / 2), (0.0, height), -depth / 2, rng, 800)
        top = box_top((-width / 2, width / 2), (-depth / 2, depth / 2), height, rng, 400)
        points = np.vstack([front, top])
        rotation = np.array([[np.cos(turn), -np.sin(turn), 0.0], [np.sin(turn), np.cos(turn), 0.0], [0.0, 0.0, 1.0]])
        points = points @ rotation.T + [0.0, 0.8, 0.0]
    measured = waist_ratio(points, 0.0, height)
    assert measured is None or measured[0] > WAIST_RATIO


@pytest.fixture(scope="module")
def profiles() -> dict[str, Profile]:
    return {p["class"]: Profile.from_mapping(p) for p in class_profiles(KnowledgeBase.load())}


def test_the_ontology_says_which_classes_have_a_waist(profiles: dict[str, Profile]) -> None:
    assert profiles["PowerDrill"].waisted is True
    assert profiles["WineGlass"].waisted is True
    for never in ("Crackers", "Milk", "Mug", "Cup", "Bowl", "Bottle", "Spam", "Kettle", "ToyBlock"):
        assert profiles[never].waisted is False, never
    assert profiles["Glass"].waisted is None  # a tumbler has none, a wine glass one


def test_a_waist_seen_speaks_for_a_drill_and_none_seen_says_nothing(profiles: dict[str, Profile]) -> None:
    """The cues of an orange printed medium object about as high as it is wide (a box of crackers or a drill)."""
    common = {
        "color": ("orange", 0.4),
        "size": ("medium", 1.0),
        "height_to_width": 1.2,
        "open_top": (False, 1.0),
        "printed": (True, 1.0),
    }
    drill, crackers = profiles["PowerDrill"], profiles["Crackers"]
    unseen = Cues(**common)
    none_seen = Cues(**common, waist=(False, 1.0))
    seen = Cues(**common, waist=(True, 1.0))
    assert score(drill, none_seen).score == score(drill, unseen).score
    assert score(crackers, none_seen).score == score(crackers, unseen).score
    assert score(drill, seen).score > score(drill, unseen).score
    assert score(crackers, seen).score < score(crackers, unseen).score
    assert score(drill, seen).score > score(crackers, seen).score
    globe = profiles["Globe"]  # says nothing about a waist: its score does not move
    assert score(globe, seen).score == score(globe, unseen).score


@pytest.mark.real_data
def test_on_the_real_uoc_frames_only_the_drills_standing_on_their_batteries_are_waisted(uoc_folder: Path) -> None:
    """Every labelled object of the uoc frames, on the default segmenter's segment, measured as the form expert
    does (in the supporting plane's frame); the drills of frames 2 and 3 lie on their sides."""
    waisted = set()
    for (input_name, index), objects in load_labelled_objects(LABELS).items():
        points, colors = frame_points(input_name, index)
        labels = segment_points(points, colors, ClutterParameters())
        frame = SupportFrame(plane_frame(support_plane(points)[1].model), on_plane=True, guessed=False)
        for labelled in objects:
            x, y = labelled.pixel
            own = points[labels == labels[y, x]]
            form = measure_form(frame.points(own[np.isfinite(own).all(axis=1)].astype(np.float64)), frame)
            assert form is not None, labelled.name
            if form.waisted:
                waisted.add((index, labelled.name))
    assert waisted == {(0, "power drill"), (1, "power drill")}
