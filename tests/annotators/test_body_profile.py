"""The body profile (one axis, a radius per height band) and the grazing stray points the handle cue leaves out."""

from __future__ import annotations

import numpy as np
import pytest

from annotators.cloud.body_profile import BANDS, body_profile
from annotators.cloud.form import profile_handle
from annotators.geometry.grazing import grazing_pixels


def half_cone(bottom_radius: float, top_radius: float, height: float, rng: np.random.Generator) -> np.ndarray:
    """The near half of an upright truncated cone's side about the axis (0.1, 0.7), widening upwards."""
    z = rng.uniform(0.0, height, 3000)
    angles = rng.uniform(np.pi, 2.0 * np.pi, z.size)
    radius = bottom_radius + (top_radius - bottom_radius) * z / height
    return np.column_stack([0.1 + radius * np.cos(angles), 0.7 + radius * np.sin(angles), z])


@pytest.mark.parametrize("seed", range(3))
def test_the_profile_follows_a_tapered_body_seen_as_a_half_arc(seed: int) -> None:
    rng = np.random.default_rng(seed)
    points = half_cone(0.035, 0.045, 0.1, rng)
    points[:, :2] += rng.normal(0.0, 0.001, (points.shape[0], 2))
    stray = np.column_stack([rng.uniform(0.16, 0.2, 60), rng.uniform(0.6, 0.65, 60), rng.uniform(0.0, 0.02, 60)])
    profile = body_profile(np.vstack([points, stray]), 0.0, 0.1)
    assert profile is not None
    assert profile.centre == pytest.approx([0.1, 0.7], abs=0.003)
    expected = 0.035 + 0.01 * (np.arange(BANDS) + 0.5) / BANDS
    assert profile.radii == pytest.approx(expected, abs=0.003)


def test_a_handle_sticks_out_of_the_profile_of_a_tapered_mug_and_a_plain_one_has_none() -> None:
    rng = np.random.default_rng(0)
    body = half_cone(0.035, 0.045, 0.1, rng)
    t = rng.uniform(0.0, np.pi, 200)
    handle = np.column_stack(
        [0.1 - 0.045 - 0.025 * np.sin(t), 0.7 + rng.uniform(-0.005, 0.005, t.size), 0.06 + 0.025 * np.cos(t)]
    )  # a loop on the -x side, reaching 2.5 cm out from 35 % to 85 % of the height
    assert profile_handle(np.vstack([body, handle]), 0.0, 0.1)[0]
    assert not profile_handle(body, 0.0, 0.1)[0]


def test_points_along_a_line_of_sight_are_grazing_and_a_facing_surface_is_not() -> None:
    # a 20x20 grid: a plane facing the camera 0.6 m away, and one row whose points run away along their lines of
    # sight (a streak of mixed depths past an outline)
    rows, cols = np.mgrid[0:20, 0:20]
    rays = np.stack([(cols - 10) * 0.0016, (rows - 10) * 0.0016, np.ones(rows.shape)], axis=2)
    depth = np.full(rows.shape, 0.6)
    depth[15, :] = 0.6 + 0.02 * np.arange(20)
    points = (rays * depth[:, :, None]).astype(np.float32)
    flags = grazing_pixels(points, np.arange(400)).reshape(20, 20)
    assert not flags[:13].any()
    assert flags[15, 1:].all()
