"""The inner-wall axis: a wall concave toward the camera (the back of a container's inside) has an axis in front of
it, a convex (a solid's front) or flat wall none, and floor points are no wall; a round outer wall holds its own
inside within its circle, not the inside of a bowl an object stands in. The join itself is tested on real frames in
test_segmentation_real.py (the blue mug; the can in the teal bowl) and test_clutter_camera_resolution_real.py (the
stereo camera's mug)."""

from __future__ import annotations

import cv2
import numpy as np

from annotators.geometry.inner_walls import (
    InnerWallRules,
    inside_candidates,
    one_wall,
    outer_wall_circle,
    wall_axis,
    wall_points,
    within_outer_wall,
)


def arc(centre: tuple[float, float], radius: float, start: float, stop: float, inward: bool) -> np.ndarray:
    """Nx3 points and Nx3 normals (horizontal) of a vertical wall on a circular arc from angle ``start`` to
    ``stop``, normals toward the centre (``inward``) or away from it, at two heights."""
    angles = np.linspace(start, stop, 40)
    ring = np.column_stack([np.cos(angles), np.sin(angles)])
    points = np.concatenate([np.column_stack([centre + radius * ring, np.full(40, h)]) for h in (0.02, 0.06)])
    normals = np.concatenate([np.column_stack([-ring if inward else ring, np.zeros(40)])] * 2)
    return points, normals


# the camera looks along +u: the front of a container faces -u, its back wall's inside faces -u as well
def test_a_back_inner_wall_has_its_axis_in_front_of_it() -> None:
    points, normals = arc((0.6, 0.1), 0.035, -np.pi / 3, np.pi / 3, inward=True)  # back arc, normals to the centre
    found = wall_axis(*wall_points(points, normals, InnerWallRules()), InnerWallRules())
    assert found is not None
    axis, radius = found
    assert np.allclose(axis, (0.6, 0.1), atol=1e-6) and abs(radius - 0.035) < 1e-6


def test_a_convex_front_wall_has_no_axis_in_front_of_it() -> None:
    points, normals = arc((0.6, 0.1), 0.035, 2 * np.pi / 3, 4 * np.pi / 3, inward=False)  # front arc, outward
    assert wall_axis(*wall_points(points, normals, InnerWallRules()), InnerWallRules()) is None


def test_a_flat_wall_has_no_axis() -> None:
    v = np.linspace(0.0, 0.08, 40)
    points = np.column_stack([np.full(40, 0.6), v, np.full(40, 0.05)])
    normals = np.tile([-1.0, 0.0, 0.0], (40, 1))
    assert wall_axis(*wall_points(points, normals, InnerWallRules()), InnerWallRules()) is None


def test_floor_points_are_no_wall() -> None:
    points, normals = arc((0.6, 0.1), 0.035, -np.pi / 3, np.pi / 3, inward=True)
    normals = np.tile([0.0, 0.0, 1.0], (points.shape[0], 1))  # a horizontal surface: normals straight up
    wall, _ = wall_points(points, normals, InnerWallRules())
    assert wall.shape[0] == 0


def test_an_inside_larger_than_its_outside_or_ending_high_up_is_a_candidate() -> None:
    # piece 1: a wide mug's inside seen from above, larger than the outside and ending 5.7 cm up (the front rim hides
    # the rest); piece 2: the outside, down to the table; piece 3: something beside it on the table
    low = np.array([0.0, 0.057, 0.014, 0.012])
    pairs = np.array([[1, 2], [2, 3]])
    candidates = inside_candidates(pairs, low, InnerWallRules().support.tolerance).tolist()
    assert [1, 2] in candidates
    assert [2, 3] not in candidates and [3, 2] not in candidates  # both reach the table
    assert [2, 1] not in candidates


def test_two_halves_of_one_inner_wall_are_one_wall_and_a_neighbouring_inside_is_not() -> None:
    rules = InnerWallRules()

    def axis_of(centre: tuple[float, float], radius: float, start: float, stop: float) -> tuple[np.ndarray, float]:
        found = wall_axis(*wall_points(*arc(centre, radius, start, stop, inward=True), rules), rules)
        assert found is not None
        return found

    left = axis_of((0.7, 0.3), 0.075, -np.pi / 2, 0.0)  # the back of a bowl's inside, cut in two
    right = axis_of((0.7, 0.3), 0.075, 0.0, np.pi / 2)
    assert one_wall(left, right, rules.same_axis) and one_wall(right, left, rules.same_axis)
    beside = axis_of((0.7, 0.46), 0.075, -np.pi / 2, np.pi / 2)  # the inside of a second bowl standing beside it
    assert not one_wall(left, beside, rules.same_axis)
    nested = axis_of((0.7, 0.3), 0.03, -np.pi / 2, np.pi / 2)  # a cup standing in the bowl's middle
    assert not one_wall(left, nested, rules.same_axis)
    assert not one_wall(left, None, rules.same_axis)


def footprint(centre: tuple[float, float], radius: float) -> np.ndarray:
    """The float32 Kx1x2 polygon of a disc's footprint, as the join's floor."""
    angles = np.linspace(0.0, 2 * np.pi, 24, endpoint=False)
    ring = np.column_stack([np.cos(angles), np.sin(angles)]) * radius + centre
    return cv2.convexHull(ring.astype(np.float32))


def test_a_round_front_wall_curves_around_its_axis_behind_it() -> None:
    rules = InnerWallRules()
    points, normals = arc((0.6, 0.1), 0.045, 2 * np.pi / 3, 4 * np.pi / 3, inward=False)  # a mug's outer front
    found = outer_wall_circle(*wall_points(points, normals, rules), rules)
    assert found is not None
    axis, radius = found
    assert np.allclose(axis, (0.6, 0.1), atol=1e-6) and abs(radius - 0.045) < 1e-6
    back, back_normals = arc((0.6, 0.1), 0.04, -np.pi / 3, np.pi / 3, inward=True)  # its inside: concave
    assert outer_wall_circle(*wall_points(back, back_normals, rules), rules) is None


def test_a_mugs_outer_wall_holds_its_inside_and_a_can_in_a_bowl_does_not_hold_the_bowls() -> None:
    rules = InnerWallRules()
    outside = wall_points(*arc((0.6, 0.1), 0.045, 2 * np.pi / 3, 4 * np.pi / 3, inward=False), rules)
    inside, _ = wall_points(*arc((0.6, 0.1), 0.041, -np.pi / 3, np.pi / 3, inward=True), rules)
    assert within_outer_wall(inside, *outside, footprint((0.6, 0.1), 0.046), rules)
    # a can (radius 3.3 cm) standing in a bowl (inner radius 7 cm), off its middle: the bowl's inside lies outside it
    can = wall_points(*arc((0.58, 0.12), 0.033, 2 * np.pi / 3, 4 * np.pi / 3, inward=False), rules)
    bowl_inside, _ = wall_points(*arc((0.6, 0.1), 0.07, -np.pi / 3, np.pi / 3, inward=True), rules)
    assert not within_outer_wall(bowl_inside, *can, footprint((0.6, 0.1), 0.08), rules)
    # a round body whose axis lies outside the floor the two pieces stand on holds nothing
    assert not within_outer_wall(inside, *outside, footprint((0.8, 0.3), 0.02), rules)
