"""claim_container_floors: the floor of an open container, at table level, joins the container where its
footprint holds it and no part of it hangs over the floor; the table beside an object, and under an overhanging
part, stays unlabelled."""

from __future__ import annotations

import cv2
import numpy as np
from scipy import ndimage

from annotators.geometry import floor_loops
from annotators.geometry.container_floors import (
    FloorRules,
    Footprint,
    claim_container_floors,
    core_feet,
    core_hull,
    enclosing_labels,
    may_lie_within,
    overhung,
    touches_other_labels,
    touches_other_labels_numpy,
)

CELL = 0.005  # metres per grid pixel in these plane coordinates


def flat_table(shape: tuple[int, int] = (60, 60)) -> tuple[np.ndarray, np.ndarray]:
    """Empty labels and (u, v, height) plane coordinates of a table seen straight from above (feet under pixels)."""
    rows, cols = np.mgrid[0 : shape[0], 0 : shape[1]]
    points = np.zeros((*shape, 3), dtype=np.float32)
    points[..., 0], points[..., 1] = cols * CELL, rows * CELL
    return np.zeros(shape, dtype=np.int32), points


def bowl(labels: np.ndarray, points: np.ndarray, centre: tuple[int, int], inner: int, outer: int) -> np.ndarray:
    """Draw a bowl's wall (label 1): a ring of pixels between radii ``inner`` and ``outer`` rising from 1 cm at
    the inner edge to 5 cm at the outer one; the disc inside (its floor, 4 mm high) is returned as a mask."""
    rows, cols = np.mgrid[0 : labels.shape[0], 0 : labels.shape[1]]
    radius = np.hypot(rows - centre[0], cols - centre[1])
    wall = (radius >= inner) & (radius < outer)
    labels[wall] = 1
    points[..., 2][wall] = 0.01 + 0.04 * (radius[wall] - inner) / (outer - inner)
    floor = radius < inner
    points[..., 2][floor] = 0.004
    return floor


def test_the_floor_inside_a_bowl_joins_the_bowl_and_the_table_around_it_does_not() -> None:
    labels, points = flat_table()
    floor = bowl(labels, points, (30, 30), 10, 20)
    joined, claimed = claim_container_floors(labels, np.ones(labels.shape, bool), points)
    assert np.array_equal(claimed, floor)
    assert np.array_equal(joined == 1, (labels == 1) | floor)


def test_the_floor_of_a_bowl_whose_near_side_is_not_seen_joins_it_within_the_far_walls_footprint() -> None:
    # the near half of the wall is missing (out of the frame, or its depth lost): the floor within the hull of the
    # far half joins, up to the cut, and the table beyond it stays out
    labels, points = flat_table()
    floor = bowl(labels, points, (30, 30), 10, 20)
    labels[31:] = 0
    _, claimed = claim_container_floors(labels, np.ones(labels.shape, bool), points)
    assert claimed[floor & (np.arange(60)[:, None] < 30)].all()
    assert not claimed[31:].any()


def test_the_table_under_an_overhanging_part_and_beside_solid_objects_stays_unlabelled() -> None:
    labels, points = flat_table()
    # a battery standing 1-8 cm high, and from its top a chuck reaching over the table 10-12 cm high
    labels[10:30, 10:20] = 1
    points[10:30, 10:20, 2] = 0.05
    labels[10:14, 20:45] = 1
    points[10:14, 20:45, 2] = 0.11
    # a solid box of its own beside
    labels[40:55, 40:55] = 2
    points[40:55, 40:55, 2] = 0.06
    # the table seen in the image below the chuck lies right under it on the plane (inside the drill's hull)
    points[14:30, 20:45, :2] = points[12:13, 20:45, :2]
    joined, claimed = claim_container_floors(labels, np.ones(labels.shape, bool), points)
    assert not claimed.any()
    assert np.array_equal(joined, labels)


def test_a_foots_depth_in_a_footprint_is_its_distance_to_the_outline_to_the_cell() -> None:
    square = np.array([[0, 0], [0.1, 0], [0.1, 0.1], [0, 0.1]], dtype=np.float32)
    feet = np.array([[0.05, 0.05], [0.09, 0.05], [0.15, 0.05], [-0.01, 0.0]], dtype=np.float32)
    for hull in (square, square[::-1]):
        depth = Footprint(hull, CELL).depth(feet)
        assert np.allclose(depth, [0.05, 0.01, 0.0, 0.0], atol=1.5 * CELL)


def test_a_cell_is_overhung_only_where_all_of_the_objects_points_over_it_are_high() -> None:
    # a wall running down to 1 cm and a ledge 10 cm high beside it
    wall = np.array([[0.0025, 0.0025, 0.01], [0.0025, 0.0025, 0.05], [0.0125, 0.0025, 0.10]], dtype=np.float32)
    feet = np.array([[0.0025, 0.0025], [0.0125, 0.0025]], dtype=np.float32)
    assert overhung(feet, wall, 0.02, FloorRules().cell).tolist() == [False, True]


def test_the_table_at_the_foot_of_a_solid_object_stays_unlabelled_though_the_hull_reaches_over_it() -> None:
    # a box 6 cm high whose image box holds a band of table along its foot, the band's feet (noise, mixed pixels)
    # 0.5-1 cm within the box's footprint: within the hull, but no part of the band lies well inside it
    labels, points = flat_table()
    labels[20:40, 20:40] = 1
    points[20:40, 20:40, 2] = 0.06
    labels[38:40, 22:38] = 0
    points[38:40, 22:38, 2] = 0.0
    points[38:40, 22:38, 1] = 37.0 * CELL
    joined, claimed = claim_container_floors(labels, np.ones(labels.shape, bool), points)
    assert not claimed.any()
    assert np.array_equal(joined, labels)


def test_a_pixel_is_enclosed_by_the_label_it_meets_first_on_three_of_its_four_sides() -> None:
    labels = np.zeros((7, 9), dtype=np.int32)
    labels[1:6, 1] = labels[1:6, 5] = labels[1, 1:6] = 1  # a horseshoe open at the bottom
    labels[3, 7] = 2
    enclosing = enclosing_labels(labels)
    assert enclosing[3, 3] == 1 and enclosing[5, 3] == 1  # wall left, right and above
    assert enclosing[3, 0] == 0 and enclosing[6, 3] == 0 and enclosing[0, 3] == 0  # beside, below, above it
    assert enclosing[3, 6] == 0  # between the horseshoe and another object


def test_the_hull_of_an_object_leaves_out_its_outlines_mixed_pixels() -> None:
    labels, points = flat_table()
    labels[20:40, 20:40] = 1
    points[20:40, 39, 0] += 0.05  # the right outline's pixels mixed with what lies 5 cm behind
    hull = core_hull(labels == 1, points)
    assert hull[:, 0].max() <= 38 * CELL + 1e-6 and hull[:, 0].min() >= 21 * CELL - 1e-6


def test_the_compiled_seed_pass_gives_what_the_numpy_forms_give() -> None:
    rng = np.random.default_rng(5)
    for _ in range(20):
        labels = np.where(rng.random((40, 50)) < 0.3, rng.integers(1, 7, (40, 50)), 0).astype(np.int32)
        valid = rng.random((40, 50)) < 0.9
        heights = rng.uniform(-0.02, 0.02, (40, 50)).astype(np.float32)
        heights[rng.random((40, 50)) < 0.05] = np.nan
        heights[rng.random((40, 50)) < 0.05] = np.float32(0.01)  # on the bound: not within it
        level, enclosing, boxes, enclosed = floor_loops.floor_seeds(labels, valid, heights, np.float32(0.01))
        with np.errstate(invalid="ignore"):
            expected_level = valid & (labels == 0) & (np.abs(heights) < 0.01)
        assert np.array_equal(level, expected_level)
        expected = np.where(expected_level, enclosing_labels(labels), 0)
        assert np.array_equal(enclosing, expected)
        assert np.flatnonzero(enclosed).tolist() == np.unique(expected[expected > 0]).tolist()
        for label, window in enumerate(ndimage.find_objects(labels), start=1):
            if window is not None:
                rows, cols = window
                assert boxes[label].tolist() == [rows.start, rows.stop, cols.start, cols.stop]


def test_the_compiled_touch_test_gives_what_the_numpy_form_gives() -> None:
    rng = np.random.default_rng(6)
    outcomes = set()
    for _ in range(200):
        labels = np.where(rng.random((8, 9)) < 0.3, rng.integers(1, 4, (8, 9)), 0).astype(np.int32)
        marked = rng.random((8, 9)) < 0.03
        expected = touches_other_labels_numpy(labels, marked)
        assert touches_other_labels(labels, marked) == expected
        outcomes.add(expected)
    assert outcomes == {False, True}


def test_the_footprint_box_rules_out_no_foot_that_lies_margin_inside_the_footprint() -> None:
    rng = np.random.default_rng(7)
    rules = FloorRules()
    ruled_out = 0
    for _ in range(300):
        corners = rng.uniform(0.0, 0.08, (int(rng.integers(3, 9)), 2)).astype(np.float32)
        hull = cv2.convexHull(corners).reshape(-1, 2)
        if hull.shape[0] < 3:
            continue
        feet = rng.uniform(-0.01, 0.09, (int(rng.integers(1, 6)), 2)).astype(np.float32)
        inside = (Footprint(hull, rules.cell).depth(feet) >= rules.margin).any()
        possible = may_lie_within(feet, corners, rules.margin, rules.cell)
        assert possible or not inside
        ruled_out += not possible
    assert ruled_out > 0


def test_a_marked_pixel_touches_other_labels_only_beside_a_pixel_of_another_label() -> None:
    labels = np.array([[1, 1, 0, 2], [1, 1, 0, 2]], dtype=np.int32)
    marked = np.zeros(labels.shape, dtype=bool)
    marked[0, 1] = True
    assert not touches_other_labels(labels, marked)
    labels[0, 2] = 2
    assert touches_other_labels(labels, marked)


def random_scene(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Blobby labels on a tilted, noisy table with some unmeasured pixels: labels and float32 plane coordinates."""
    labels, points = flat_table((30, 40))
    for label in range(1, 4):
        y, x = rng.integers(0, 25), rng.integers(0, 35)
        labels[y : y + rng.integers(3, 12), x : x + rng.integers(3, 14)] = label
    labels[rng.random(labels.shape) < 0.05] = 0
    points[..., :2] += rng.normal(0.0, 0.002, (*labels.shape, 2)).astype(np.float32)
    points[..., 2] = np.where(labels > 0, rng.uniform(0.0, 0.05, labels.shape), 0.0).astype(np.float32)
    points[rng.random(labels.shape) < 0.03] = np.nan
    return labels, points


def test_the_compiled_candidate_pass_gives_the_core_feet_enclosed_pixels_and_box_test_of_the_numpy_forms() -> None:
    rng = np.random.default_rng(8)
    rules = FloorRules()
    for _ in range(60):
        labels, points = random_scene(rng)
        level = rng.random(labels.shape) < 0.5
        enclosing = np.where(level & (labels == 0), enclosing_labels(labels), 0).astype(np.int32)
        windows = ndimage.find_objects(labels)
        boxes = np.zeros((len(windows) + 1, 4), dtype=np.int64)
        for label, window in enumerate(windows, start=1):
            if window is not None:
                boxes[label] = window[0].start, window[0].stop, window[1].start, window[1].stop
        enclosed = np.zeros(len(windows) + 1, dtype=bool)
        enclosed[np.unique(enclosing[enclosing > 0])] = True
        counts, screened = floor_loops.candidate_screen(
            labels, enclosing, points, boxes, enclosed, rules.sample_step, np.float32(rules.cell)
        )
        for label, window in enumerate(windows, start=1):
            if window is None:
                continue
            box = boxes[label]
            core, seed_rows, seed_cols, feet, possible = floor_loops.floor_candidate(
                labels, enclosing, points, label, box, rules.sample_step, np.float32(rules.cell)
            )
            expected = core_feet(labels[window] == label, points[window], rules.sample_step)
            assert np.array_equal(core, expected)
            expected_rows, expected_cols = np.nonzero(enclosing[window] == label)
            assert np.array_equal(seed_rows, expected_rows) and np.array_equal(seed_cols, expected_cols)
            assert np.array_equal(feet, points[window][expected_rows, expected_cols, :2], equal_nan=True)
            if core.shape[0]:
                assert possible == may_lie_within(feet, core, rules.margin, rules.cell)
            if enclosed[label]:
                assert counts[label] == core.shape[0] and screened[label] == possible


def test_the_compiled_overhang_pass_gives_what_the_numpy_form_gives() -> None:
    rng = np.random.default_rng(9)
    both = set()
    for _ in range(60):
        labels, points = random_scene(rng)
        label = int(rng.integers(1, 4))
        window = ndimage.find_objects(labels)[label - 1] if label <= labels.max() else None
        if window is None:
            continue
        rows, cols = window
        box = np.array([rows.start, rows.stop, cols.start, cols.stop], dtype=np.int64)
        feet = points[rows, cols][labels[window] == 0][:, :2]
        feet = feet[np.isfinite(feet).all(axis=1)]
        if feet.shape[0] == 0:
            continue
        compiled = floor_loops.overhung(feet, labels, points, label, box, np.float32(0.02), np.float32(CELL))
        expected = overhung(feet, points[window][labels[window] == label], 0.02, CELL)
        assert np.array_equal(compiled, expected)
        both.update(expected.tolist())
    assert both == {False, True}
