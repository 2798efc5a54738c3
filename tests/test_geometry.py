"""Quaternions and matrices (robokudo.core.geometry): one convention for the whole project."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from robokudo.core.geometry import (
    IDENTITY_QUATERNION,
    pose_matrix,
    quaternion_from_matrix,
    rotation_matrices,
    rotation_matrix,
)
from robokudo.core.types import Pose

components = st.floats(min_value=-1.0, max_value=1.0, allow_nan=False)
quaternions = st.tuples(components, components, components, components).filter(
    lambda q: float(np.linalg.norm(q)) > 1e-3
)


def unit(q: tuple[float, float, float, float]) -> np.ndarray:
    vector = np.asarray(q, dtype=np.float64)
    return vector / np.linalg.norm(vector)


@given(quaternions)
def test_matrix_to_quaternion_to_matrix_round_trips(q: tuple[float, float, float, float]) -> None:
    rotation = rotation_matrix(unit(q))
    recovered = quaternion_from_matrix(rotation)
    assert abs(np.linalg.norm(recovered) - 1.0) < 1e-9
    assert recovered[3] >= 0.0
    np.testing.assert_allclose(rotation_matrix(recovered), rotation, atol=1e-9)


@given(st.lists(quaternions, min_size=1, max_size=5))
def test_many_quaternions_at_once_give_the_matrices_of_each(qs: list[tuple[float, float, float, float]]) -> None:
    units = np.array([unit(q) for q in qs])
    np.testing.assert_allclose(rotation_matrices(units), [rotation_matrix(q) for q in units], atol=1e-12)


@given(quaternions)
def test_the_quaternion_is_the_one_with_non_negative_w(q: tuple[float, float, float, float]) -> None:
    expected = unit(q) if unit(q)[3] >= 0 else -unit(q)
    recovered = quaternion_from_matrix(rotation_matrix(unit(q)))
    if abs(expected[3]) > 1e-6:  # at w = 0, q and -q both have w >= 0
        np.testing.assert_allclose(recovered, expected, atol=1e-7)


def test_half_turns_and_degenerate_matrices() -> None:
    for axis in np.eye(3):
        half_turn = 2.0 * np.outer(axis, axis) - np.eye(3)
        recovered = quaternion_from_matrix(half_turn)
        np.testing.assert_allclose(np.abs(recovered[:3]), axis, atol=1e-12)
        np.testing.assert_allclose(rotation_matrix(recovered), half_turn, atol=1e-12)
    np.testing.assert_array_equal(quaternion_from_matrix(np.full((3, 3), np.nan)), IDENTITY_QUATERNION)
    np.testing.assert_array_equal(quaternion_from_matrix(np.zeros((3, 3))), IDENTITY_QUATERNION)


def test_pose_matrix_is_the_annotations_transform() -> None:
    q = unit((0.1, -0.2, 0.3, 0.9))
    pose = Pose(position=np.array([1.0, 2.0, 3.0]), orientation=q)
    np.testing.assert_array_equal(pose.matrix(), pose_matrix((1.0, 2.0, 3.0), q))
    np.testing.assert_allclose(pose.matrix()[:3, 3], (1.0, 2.0, 3.0))
