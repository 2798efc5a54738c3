"""The depth people detector on ray-cast scenes: a level camera, a floor, a tall back wall and 1-4 people
(vertical cylinders of person size) at random places; every person is found once, near its axis, and the wall
never is. The thresholds were set on the real five_people frame; these scenes are held out."""

from __future__ import annotations

import numpy as np
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from annotators.cloud.people import IMAGE_UP, find_people

ROWS, COLS, F = 240, 320, 260.0
CAMERA_HEIGHT = 1.3
WALL_DEPTH = 6.0


def render(people: list[tuple[float, float, float, float]]) -> np.ndarray:
    """The organized cloud (camera frame, y down) of the floor, the wall and the cylinders (x, z, radius, height)."""
    v, u = np.mgrid[0:ROWS, 0:COLS].astype(np.float64)
    dx, dy = (u - COLS / 2) / F, (v - ROWS / 2) / F
    depth = np.full((ROWS, COLS), np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        floor = np.where(dy > 0, CAMERA_HEIGHT / dy, np.inf)
    depth = np.minimum(depth, floor)
    wall_y = WALL_DEPTH * dy
    depth = np.where((wall_y > CAMERA_HEIGHT - 3.0) & (depth > WALL_DEPTH), WALL_DEPTH, depth)
    for x, z, radius, height in people:
        # |t*(dx, 1) - (x, z)| = radius along the ray's ground projection, t being the depth
        a = dx**2 + 1.0
        b = -2.0 * (dx * x + z)
        c = x**2 + z**2 - radius**2
        disc = b**2 - 4 * a * c
        with np.errstate(invalid="ignore"):
            t = (-b - np.sqrt(disc)) / (2 * a)
        y = t * dy
        hit = (disc >= 0) & (t > 0) & (y <= CAMERA_HEIGHT) & (y >= CAMERA_HEIGHT - height)
        depth = np.where(hit & (t < depth), t, depth)
    depth[~np.isfinite(depth)] = np.nan
    return np.stack([dx * depth, dy * depth, depth], axis=-1).astype(np.float32)


@st.composite
def scenes(draw: st.DrawFn) -> list[tuple[float, float, float, float]]:
    count = draw(st.integers(1, 4))
    z = draw(st.floats(1.8, 3.5))
    gaps = [draw(st.floats(0.75, 1.1)) for _ in range(count - 1)]
    xs = np.cumsum([0.0, *gaps])
    xs = xs - xs.mean() + draw(st.floats(-0.3, 0.3))
    people = [
        (float(x), z + draw(st.floats(-0.2, 0.2)), draw(st.floats(0.17, 0.25)), draw(st.floats(1.5, 1.95))) for x in xs
    ]
    half_view = COLS / 2 / F
    assume(all(abs(x) + radius < half_view * depth for x, depth, radius, _ in people))  # everyone in the image
    return people


@settings(max_examples=15, deadline=None)
@given(scenes())
def test_every_person_is_found_once_near_its_axis_and_the_wall_never(
    people: list[tuple[float, float, float, float]],
) -> None:
    points = render(people)
    found = find_people(points, np.isfinite(points[..., 2]), IMAGE_UP)
    assert len(found) == len(people), ([p.centroid.round(2) for p in found], people)
    for segment, (x, z, radius, _) in zip(found, sorted(people), strict=True):
        horizontal = np.hypot(segment.centroid[0] - x, segment.centroid[2] - z)
        assert horizontal < radius + 0.05, (segment.centroid.round(2), x, z)
        assert segment.centroid[2] < WALL_DEPTH - 1.0
