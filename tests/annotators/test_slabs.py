"""join_slab_pieces: touching pieces with the same lowest heights and tops and no depth jump along their shared
border are one object lying on the table; a depth jump, another top or another foot keeps them apart, and so does
standing taller than wide (a mug and a can side by side); heights are read from the trusted pixels when given."""

from __future__ import annotations

import numpy as np

from annotators.geometry.slabs import SlabRules, join_slab_pieces, slab_partners
from annotators.geometry.support import AppendageRules, appendage_owners
from tests.annotators.test_support import camera_points, scene

BODY = ((10, 10, 40, 30), (0.01, 0.05))  # a drill's body and grip lying on their side, 1-5 cm high


def test_a_piece_as_high_as_its_neighbour_meeting_it_without_a_depth_jump_joins_it() -> None:
    # the battery: a third of the body's size, 1-5 cm high like it, its edge 1.2 cm nearer (a step, not a jump)
    labels, plane_points = scene({1: BODY, 2: ((40, 12, 55, 28), (0.01, 0.05))})
    points, normals = camera_points(labels, {1: 1.0, 2: 0.988})
    assert appendage_owners(labels, points, normals, plane_points, AppendageRules()) == []  # too large for a part
    assert slab_partners(labels, points, normals, plane_points, SlabRules()) == [(1, 2)]
    joined = join_slab_pieces(labels, points, normals, plane_points)
    assert joined.max() == 1 and np.array_equal(joined > 0, labels > 0)


def test_pieces_behind_a_depth_jump_of_another_height_or_standing_on_top_stay_apart() -> None:
    beside = ((40, 12, 55, 28), (0.01, 0.05))
    # as high, but 5 cm behind: one object hides the other
    labels, plane_points = scene({1: BODY, 2: beside})
    points, normals = camera_points(labels, {1: 1.0, 2: 1.05})
    assert slab_partners(labels, points, normals, plane_points, SlabRules()) == []
    # touching without a jump, but taller: an object standing beside it
    labels, plane_points = scene({1: BODY, 2: ((40, 12, 55, 28), (0.01, 0.09))})
    points, normals = camera_points(labels, {1: 1.0, 2: 1.0})
    assert slab_partners(labels, points, normals, plane_points, SlabRules()) == []
    # starting at the body's top: an object standing on it
    labels, plane_points = scene({1: BODY, 2: ((40, 12, 55, 28), (0.05, 0.09))})
    points, normals = camera_points(labels, {1: 1.0, 2: 1.0})
    assert slab_partners(labels, points, normals, plane_points, SlabRules()) == []
    assert np.array_equal(join_slab_pieces(labels, points, normals, plane_points), labels)


def test_a_strip_grown_onto_a_neighbours_edge_does_not_lift_a_pieces_top() -> None:
    # the battery took a strip of a bowl's rim (6-7 cm high) by growth; its patches (trusted pixels) are 1-5 cm high
    labels, plane_points = scene({1: BODY, 2: ((40, 12, 55, 28), (0.01, 0.05))})
    plane_points[12:28, 52:55, 2] = np.linspace(0.06, 0.07, 16, dtype=np.float32)[:, None]
    points, normals = camera_points(labels, {1: 1.0, 2: 0.988})
    trusted = labels > 0
    trusted[12:28, 52:55] = False
    assert slab_partners(labels, points, normals, plane_points, SlabRules()) == []
    assert slab_partners(labels, points, normals, plane_points, SlabRules(), trusted=trusted) == [(1, 2)]
    # a piece without a trusted pixel is measured on all of its pixels
    assert slab_partners(labels, points, normals, plane_points, SlabRules(), trusted=labels == 1) == []
    trusted[:, 40:55] = False
    plane_points[12:28, 52:55, 2] = np.linspace(0.01, 0.05, 16, dtype=np.float32)[:, None]
    assert slab_partners(labels, points, normals, plane_points, SlabRules(), trusted=trusted) == [(1, 2)]


def test_two_objects_standing_side_by_side_as_tall_as_each_other_but_taller_than_wide_stay_apart() -> None:
    # a mug and a can, 7 cm across and 1-10 cm high, touching without a depth jump where a rim meets a side
    mug, can = ((10, 10, 24, 24), (0.01, 0.10)), ((24, 10, 38, 24), (0.01, 0.10))
    labels, plane_points = scene({1: mug, 2: can})
    points, normals = camera_points(labels, {1: 1.0, 2: 1.0})
    assert slab_partners(labels, points, normals, plane_points, SlabRules()) == []
    # the same two pieces 1-5 cm high lie flat: two pieces of one slab
    labels, plane_points = scene({1: (mug[0], (0.01, 0.05)), 2: (can[0], (0.01, 0.05))})
    assert slab_partners(labels, points, normals, plane_points, SlabRules()) == [(1, 2)]
