"""join_unsupported: a piece that could not stand by itself joins the object whose footprint holds it;
join_jointly_held: such a piece that two touching neighbours hold only together joins both, when the three
touch in 3-D; join_appendages: a small piece touching a larger one in 3-D along most of their border, within its
heights, joins it."""

from __future__ import annotations

import numpy as np

from annotators.geometry.support import (
    AppendageRules,
    JointRules,
    SupportRules,
    appendage_owners,
    join_appendages,
    join_jointly_held,
    join_unsupported,
    jointly_held,
    unsupported_holders,
)

CELL = 0.005  # metres per grid pixel in these plane coordinates


def scene(parts: dict[int, tuple[tuple[int, int, int, int], tuple[float, float]]], shape=(40, 60)):
    """Labels and (u, v, height) plane coordinates: each part a box of grid pixels (x0, y0, x1, y1) whose feet lie
    under the pixels and whose heights run from ``low`` (top row) to ``high`` (bottom row) of the box."""
    labels = np.zeros(shape, dtype=np.int32)
    points = np.full((*shape, 3), np.nan, dtype=np.float32)
    rows, cols = np.mgrid[0 : shape[0], 0 : shape[1]]
    points[..., 0], points[..., 1] = cols * CELL, rows * CELL
    for label, ((x0, y0, x1, y1), (low, high)) in parts.items():
        labels[y0:y1, x0:x1] = label
        points[y0:y1, x0:x1, 2] = np.linspace(low, high, y1 - y0, dtype=np.float32)[:, None]
    return labels, points


def test_a_smaller_piece_above_the_table_inside_a_standing_footprint_joins_it() -> None:
    # a body 1-8 cm high, and touching it a piece over the body's footprint 3.5-9 cm high (a mug's inside and rim)
    labels, points = scene({1: ((10, 10, 40, 30), (0.01, 0.08)), 2: ((20, 30, 30, 36), (0.035, 0.09))})
    points[30:36, 20:30, 1] = np.linspace(0.06, 0.12, 6, dtype=np.float32)[:, None]  # its feet within the body's
    assert unsupported_holders(labels, points, SupportRules()) == [(2, 1)]
    joined = join_unsupported(labels, points)
    assert joined.max() == 1 and np.array_equal(joined > 0, labels > 0)


def test_objects_standing_beside_on_or_in_others_stay_apart() -> None:
    body = ((10, 10, 40, 30), (0.01, 0.08))
    # beside: reaches the table like the body; its footprint beside the body's
    labels, points = scene({1: body, 2: ((40, 10, 50, 30), (0.01, 0.06))})
    assert unsupported_holders(labels, points, SupportRules()) == []
    # stacked: over the body's footprint, but starting at the body's top
    labels, points = scene({1: body, 2: ((20, 30, 30, 36), (0.08, 0.12))})
    points[30:36, 20:30, 1] = np.linspace(0.06, 0.12, 6, dtype=np.float32)[:, None]
    assert unsupported_holders(labels, points, SupportRules()) == []
    # held, but larger than what holds it (a can standing in a bowl beside a piece of the bowl's outside)
    labels, points = scene({1: ((20, 30, 30, 36), (0.01, 0.08)), 2: body})
    points[10:30, 10:40, 2] = np.linspace(0.035, 0.09, 20, dtype=np.float32)[:, None]
    points[30:36, 20:30, 1] = np.linspace(0.06, 0.12, 6, dtype=np.float32)[:, None]
    points[10:30, 10:40, 1] = np.linspace(0.07, 0.10, 20, dtype=np.float32)[:, None]
    points[30:36, 20:30, 0] = np.linspace(0.04, 0.21, 10, dtype=np.float32)[None, :]  # its feet around the can's
    assert unsupported_holders(labels, points, SupportRules()) == []


def camera_points(labels: np.ndarray, depths: dict[int, float]) -> tuple[np.ndarray, np.ndarray]:
    """Camera-frame points and normals of a wall facing the camera: each label's pixels at its depth (metres)."""
    rows, cols = np.mgrid[0 : labels.shape[0], 0 : labels.shape[1]].astype(np.float32)
    depth = np.ones(labels.shape, dtype=np.float32)
    for label, z in depths.items():
        depth[labels == label] = z
    points = np.stack([(cols - 30) * 0.002 * depth, (rows - 20) * 0.002 * depth, depth], axis=-1)
    normals = np.zeros_like(points)
    normals[..., 2] = -1.0
    return points, normals


def test_a_small_piece_touching_a_larger_one_along_its_border_within_its_heights_joins_it() -> None:
    # a body 1-5 cm high and a chuck an eighth of its size, 1.5-4.5 cm high, its surface going on into the body's
    labels, plane_points = scene({1: ((10, 10, 40, 30), (0.01, 0.05)), 2: ((40, 15, 46, 25), (0.015, 0.045))})
    points, normals = camera_points(labels, {1: 1.0, 2: 1.0})
    assert appendage_owners(labels, points, normals, plane_points, AppendageRules()) == [(2, 1)]
    assert join_appendages(labels, points, normals, plane_points).max() == 1


def test_pieces_hidden_behind_taller_or_as_large_stay_apart() -> None:
    body = ((10, 10, 40, 30), (0.01, 0.05))
    chuck = ((40, 15, 46, 25), (0.015, 0.045))
    # 20 cm behind the body: the body hides it, their surfaces do not touch
    labels, plane_points = scene({1: body, 2: chuck})
    points, normals = camera_points(labels, {1: 1.0, 2: 1.2})
    assert appendage_owners(labels, points, normals, plane_points, AppendageRules()) == []
    # taller than the body: an object standing beside it, not a part sticking out of it
    labels, plane_points = scene({1: body, 2: ((40, 15, 46, 25), (0.015, 0.09))})
    points, normals = camera_points(labels, {1: 1.0, 2: 1.0})
    assert appendage_owners(labels, points, normals, plane_points, AppendageRules()) == []
    # half the body's size: an object of its own
    labels, plane_points = scene({1: body, 2: ((40, 10, 55, 30), (0.015, 0.045))})
    points, normals = camera_points(labels, {1: 1.0, 2: 1.0})
    assert appendage_owners(labels, points, normals, plane_points, AppendageRules()) == []


def cut_mug(depths: dict[int, float]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A mug cut in three: its front (1) and its side (2), both 1-8 cm high and side by side, and its inside seen
    over the rim (3), 3.5-9 cm high, whose feet lie half over each and reach past their far edge; ``depths`` per
    label as :func:`camera_points`."""
    labels, plane_points = scene(
        {1: ((10, 10, 30, 30), (0.01, 0.08)), 2: ((30, 10, 50, 30), (0.01, 0.08)), 3: ((15, 30, 45, 36), (0.035, 0.09))}
    )
    plane_points[30:36, 15:45, 0] = np.linspace(0.04, 0.255, 30, dtype=np.float32)[None, :]
    plane_points[30:36, 15:45, 1] = np.linspace(0.10, 0.16, 6, dtype=np.float32)[:, None]
    points, normals = camera_points(labels, depths)
    return labels, plane_points, points, normals


def test_a_piece_two_touching_neighbours_hold_only_together_joins_both() -> None:
    labels, plane_points, points, normals = cut_mug({1: 1.0, 2: 1.0, 3: 1.0})
    assert unsupported_holders(labels, plane_points, SupportRules()) == []  # neither holds it alone
    assert jointly_held(labels, points, normals, plane_points, JointRules()) == [(3, 1, 2)]
    joined = join_jointly_held(labels, points, normals, plane_points)
    assert joined.max() == 1 and np.array_equal(joined > 0, labels > 0)


def test_a_piece_held_together_by_neighbours_apart_in_depth_stays_apart() -> None:
    # the side 20 cm behind the front and the inside: one hides the other, their surfaces do not touch
    labels, plane_points, points, normals = cut_mug({1: 1.0, 2: 1.2, 3: 1.0})
    assert jointly_held(labels, points, normals, plane_points, JointRules()) == []
    assert np.array_equal(join_jointly_held(labels, points, normals, plane_points), labels)
