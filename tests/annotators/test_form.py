"""Form features (issue 15, item 6): a handle, an open top and height over width, measured on synthetic shapes,
and the knowledge classifier telling a mug from a cup by them with the ontology's profiles."""

from __future__ import annotations

import numpy as np
import pytest

from annotators.classification.knowledge_classifier import Cues, Profile, score
from annotators.cloud.form import measure_form
from annotators.geometry.support_frame import SupportFrame

CAMERA_TO_FRAME = np.eye(4)
CAMERA_TO_FRAME[2, 3] = 0.5
FRAME = SupportFrame(CAMERA_TO_FRAME, on_plane=True, guessed=False)
"""Upright frame with the camera 0.5 m above its origin; objects stand at y = 0.8 m, looking away from the camera."""
CENTRE = np.array([0.0, 0.8])


def side(radius: float, height: float, rng: np.random.Generator, n: int = 1500) -> np.ndarray:
    """Points of the near half of an upright cylinder's side (the half facing the camera at the origin)."""
    angles = rng.uniform(np.pi, 2 * np.pi, n)  # facing -y, toward the camera
    z = rng.uniform(0.0, height, n)
    return np.column_stack([CENTRE[0] + radius * np.cos(angles), CENTRE[1] + radius * np.sin(angles), z])


def handle(radius: float, height: float, rng: np.random.Generator, n: int = 200) -> np.ndarray:
    """A loop handle on the +x side, from 30 % to 85 % of the height, reaching 2.5 cm out."""
    t = rng.uniform(0.0, np.pi, n)
    reach = radius + 0.025 * np.sin(t)
    z = height * (0.575 + 0.275 * np.cos(t))
    return np.column_stack([CENTRE[0] + reach + 0.003, CENTRE[1] + rng.uniform(-0.005, 0.005, n), z])


def inner_far_wall(radius: float, height: float, rng: np.random.Generator, n: int = 400) -> np.ndarray:
    """The inside of the far half of an open cylinder, seen over its near rim (upper half of the height)."""
    angles = rng.uniform(0.1, np.pi - 0.1, n)
    z = rng.uniform(0.4 * height, height, n)
    inner = radius - 0.003
    return np.column_stack([CENTRE[0] + inner * np.cos(angles), CENTRE[1] + inner * np.sin(angles), z])


def lid(radius: float, height: float, rng: np.random.Generator, n: int = 400) -> np.ndarray:
    r = radius * np.sqrt(rng.uniform(0, 1, n))
    a = rng.uniform(0, 2 * np.pi, n)
    return np.column_stack([CENTRE[0] + r * np.cos(a), CENTRE[1] + r * np.sin(a), np.full(n, height)])


@pytest.mark.parametrize("seed", range(5))
def test_a_mug_has_a_handle_and_is_open_a_can_has_neither(seed: int) -> None:
    rng = np.random.default_rng(seed)
    mug = measure_form(np.vstack([side(0.04, 0.1, rng), handle(0.04, 0.1, rng), inner_far_wall(0.04, 0.1, rng)]), FRAME)
    cup = measure_form(np.vstack([side(0.04, 0.1, rng), inner_far_wall(0.04, 0.1, rng)]), FRAME)
    can = measure_form(np.vstack([side(0.035, 0.1, rng), lid(0.035, 0.1, rng)]), FRAME)
    assert mug is not None and cup is not None and can is not None
    assert mug.has_handle and mug.handle_confidence > 0.5 and mug.open_top
    assert not cup.has_handle and cup.open_top
    assert not can.has_handle
    assert cup.height_to_width == pytest.approx(0.1 / 0.08, rel=0.1)
    assert mug.height_to_width < cup.height_to_width  # the handle widens it


@pytest.mark.parametrize("seed", range(3))
def test_a_closed_can_and_box_are_not_open(seed: int) -> None:
    rng = np.random.default_rng(seed)
    can = measure_form(np.vstack([side(0.035, 0.1, rng), lid(0.035, 0.1, rng)]), FRAME)
    assert can is not None and not can.open_top and can.open_confidence > 0.5
    near = np.column_stack([rng.uniform(-0.05, 0.05, 800), np.full(800, 0.76), rng.uniform(0.0, 0.2, 800)])
    top = np.column_stack([rng.uniform(-0.05, 0.05, 800), rng.uniform(0.76, 0.84, 800), np.full(800, 0.2)])
    box = measure_form(np.vstack([near, top]), FRAME)
    assert box is not None and not box.open_top and box.height_to_width > 1.5


def test_a_wide_base_is_no_handle_and_a_bowl_is_flat_for_its_width() -> None:
    rng = np.random.default_rng(7)
    base = side(0.06, 0.02, rng, 600)  # a foot wider than the body, e.g. a vase
    body = side(0.04, 0.12, rng)
    body = body[body[:, 2] > 0.02]
    vase = measure_form(np.vstack([base, body]), FRAME)
    assert vase is not None and not vase.has_handle
    bowl = measure_form(np.vstack([side(0.08, 0.06, rng), inner_far_wall(0.08, 0.06, rng)]), FRAME)
    assert bowl is not None and bowl.height_to_width < 0.5 and bowl.open_top


def flaring_side(foot: float, rim: float, height: float, rng: np.random.Generator, n: int = 2000) -> np.ndarray:
    """Points of the near half of a bowl's wall, its radius growing from ``foot`` at the bottom to ``rim`` at the top
    (a truncated cone)."""
    angles = rng.uniform(np.pi, 2 * np.pi, n)
    z = rng.uniform(0.0, height, n)
    radius = foot + (rim - foot) * z / height
    return np.column_stack([CENTRE[0] + radius * np.cos(angles), CENTRE[1] + radius * np.sin(angles), z])


@pytest.mark.parametrize("seed", range(3))
def test_a_bowl_flaring_above_its_foot_surely_has_no_handle(seed: int) -> None:
    """A bowl's wall flares out of the circle of its foot all around (the white and teal bowls of the real uoc
    frames): that is its body, not a handle seen end-on, so the form cue is sure there is none (it was not sure at
    all, and the classifier could then not rule out a handle hidden behind)."""
    rng = np.random.default_rng(seed)
    points = np.vstack([flaring_side(0.03, 0.075, 0.06, rng), inner_far_wall(0.075, 0.06, rng)])
    bowl = measure_form(points, FRAME)
    assert bowl is not None and not bowl.has_handle and bowl.handle_confidence > 0.5


def test_too_few_points_measure_nothing() -> None:
    assert measure_form(np.zeros((5, 3)), FRAME) is None


MUG = Profile.from_mapping(
    {"class": "Mug", "shape": "cylinder", "handle": True, "open_top": True, "height_to_width": (0.7, 1.4)}
)
CUP = Profile.from_mapping(
    {"class": "Cup", "shape": "cylinder", "handle": False, "open_top": True, "height_to_width": (0.8, 1.6)}
)
BOWL = Profile.from_mapping(
    {"class": "Bowl", "shape": "sphere", "handle": False, "open_top": True, "height_to_width": (0.15, 0.8)}
)
CAN = Profile.from_mapping(
    {"class": "CannedFood", "shape": "cylinder", "handle": False, "open_top": False, "height_to_width": (0.5, 2.0)}
)


def best(cues: Cues) -> str:
    return max((score(p, cues) for p in (MUG, CUP, BOWL, CAN)), key=lambda m: m.score).profile.class_name


def test_the_form_cues_tell_a_mug_a_cup_a_bowl_and_a_can_apart_without_the_query() -> None:
    cylinder = {"shape": ("cylinder", 0.8), "color": ("green", 0.9)}
    assert best(Cues(**cylinder, handle=(True, 1.0), open_top=(True, 1.0), height_to_width=1.0)) == "Mug"
    assert best(Cues(**cylinder, handle=(False, 1.0), open_top=(True, 1.0), height_to_width=1.2)) == "Cup"
    assert best(Cues(**cylinder, handle=(False, 1.0), open_top=(False, 1.0), height_to_width=1.5)) == "CannedFood"
    assert best(Cues(shape=("cylinder", 0.5), handle=(False, 1.0), open_top=(True, 1.0), height_to_width=0.4)) == "Bowl"


def test_profiles_refuse_malformed_form_features() -> None:
    with pytest.raises(ValueError):
        Profile.from_mapping({"class": "Mug", "handle": "yes"})
    with pytest.raises(ValueError):
        Profile.from_mapping({"class": "Mug", "height_to_width": (1.4, 0.7)})


def seen(points: np.ndarray, centre: np.ndarray, radius: float, height: float) -> np.ndarray:
    """The points whose line of sight to the camera does not pass through the upright cylinder at ``centre``."""
    camera = CAMERA_TO_FRAME[:3, 3]
    steps = np.linspace(0.0, 1.0, 200)[1:-1]
    along = points[:, None, :] + steps[None, :, None] * (camera - points)[:, None, :]
    inside = (np.linalg.norm(along[..., :2] - centre, axis=2) < radius) & (along[..., 2] < height)
    return points[~inside.any(axis=1)]


@pytest.mark.parametrize("seed", range(3))
def test_a_can_seen_over_a_shorter_one_in_front_of_it_is_not_open(seed: int) -> None:
    """Two closed objects cut as one segment: the taller one's face shows over the shorter one, its line of sight
    runs through their common hull and leaves it high, like a cup's inside seen over its near rim; but it lies in
    front of the middle of the top, not in its far part (issue 15: a soup can and a pepper shaker read as open)."""
    rng = np.random.default_rng(seed)
    front = CENTRE + np.array([-0.01, -0.065])  # a 3 cm radius, 7.5 cm high can touching a 10 cm can in front
    short = np.vstack([side(0.03, 0.075, rng, 600), lid(0.03, 0.075, rng, 200)])
    short[:, :2] += front - CENTRE
    tall = seen(np.vstack([side(0.035, 0.1, rng), lid(0.035, 0.1, rng)]), front, 0.03, 0.075)
    both = measure_form(np.vstack([tall, short]), FRAME)
    assert both is not None and not both.open_top
