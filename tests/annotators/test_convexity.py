"""Connection votes of the convexity grouping (annotators/geometry/convexity.py) between hand-placed patch planes:
a patch seen nearly edge-on that bends inward into its neighbour - the wall of a step, or the stereo depth ramp
between an occluding edge and the surface behind it - casts no convex vote with ``grazing_degrees``; a round
object's limb, bending outward, still does. Across a crease, a connection bending inward - two boxes' faces
meeting at right angles across the depth gap between them - is told from a box's edge, which bends outward, even
when it bends too gently for the concave limit. A grid cell holding two pieces of one surface that meet only outside
it - the two sides of a depth seam the surface runs around - gives a patch to each piece. Patches grown into the gaps
between them touch only on their own surfaces, so no growth across a depth seam makes a box touch the box behind it
as the image's scan order happens to break a tie."""

from __future__ import annotations

import numpy as np

from annotators.geometry.convexity import (
    ConvexityRules,
    ConvexObjects,
    PatchPlanes,
    bridge_gaps,
    connection_votes,
    grazing_patches,
    grid_patches,
    inward_creases,
    join_faces,
)
from annotators.geometry.grid_segmentation import seed_distances, touching_pairs

PAIR = np.array([[1, 2]])


def normal(degrees: float) -> np.ndarray:
    """A unit normal in the x-z plane, ``degrees`` from the line of sight along +z, facing the camera."""
    angle = np.radians(degrees)
    return np.array([np.sin(angle), 0.0, -np.cos(angle)])


def two_patches(first: tuple[float, np.ndarray], second: tuple[float, np.ndarray]) -> PatchPlanes:
    """Two trusted patches of 12 points: (degrees off the line of sight, centroid) each."""
    (first_degrees, first_centroid), (second_degrees, second_centroid) = first, second
    return PatchPlanes(
        counts=np.array([12, 12]),
        centroids=np.array([first_centroid, second_centroid], dtype=float),
        normals=np.array([normal(first_degrees), normal(second_degrees)]),
        thickness=np.zeros(2),
        width=np.ones(2),
    )


def test_a_patch_is_grazing_when_its_normal_is_far_from_its_line_of_sight() -> None:
    planes = two_patches((75.0, np.array([0.0, 0.0, 0.9])), (35.0, np.array([0.02, 0.0, 0.9])))
    assert grazing_patches(planes, 70.0).tolist() == [False, True, False]
    assert grazing_patches(planes, 80.0).tolist() == [False, False, False]


def test_a_ramp_meeting_the_surface_behind_it_gently_inward_casts_no_convex_vote() -> None:
    # the ramp seen 75 degrees off its line of sight, the far surface (35 degrees) 3 cm on and 1 cm deeper
    planes = two_patches((75.0, np.array([0.0, 0.0, 0.9])), (35.0, np.array([0.03, 0.0, 0.91])))
    _, convex, concave = connection_votes(planes, PAIR, ConvexityRules())
    assert convex.tolist() == [True] and concave.tolist() == [False]  # too gentle for the concave limit
    _, convex, concave = connection_votes(planes, PAIR, ConvexityRules(grazing_degrees=70.0))
    assert convex.tolist() == [False] and concave.tolist() == [False]


def test_a_limb_bending_outward_from_the_face_beside_it_still_votes_convex() -> None:
    planes = two_patches((30.0, np.array([0.0, 0.0, 0.9])), (75.0, np.array([0.02, 0.0, 0.92])))
    _, convex, _ = connection_votes(planes, PAIR, ConvexityRules(grazing_degrees=70.0))
    assert convex.tolist() == [True]


def test_without_a_grazing_patch_the_votes_are_those_of_the_plain_rules() -> None:
    planes = two_patches((35.0, np.array([0.0, 0.0, 0.9])), (50.0, np.array([0.03, 0.0, 0.91])))
    plain = connection_votes(planes, PAIR, ConvexityRules())
    grazing = connection_votes(planes, PAIR, ConvexityRules(grazing_degrees=70.0))
    assert all(a.tolist() == b.tolist() for a, b in zip(plain, grazing, strict=True))


def test_two_boxes_faces_meeting_across_a_gap_are_an_inward_crease_too_gentle_for_the_concave_limit() -> None:
    # a face turned 45 degrees right and one turned 45 degrees left, 8 cm apart, the right one 5 cm deeper
    planes = two_patches((45.0, np.array([-0.04, 0.0, 0.90])), (-45.0, np.array([0.04, 0.0, 0.95])))
    _, convex, concave = connection_votes(planes, PAIR, ConvexityRules())
    assert convex.tolist() == [True] and concave.tolist() == [False]
    assert inward_creases(planes, PAIR, ConvexityRules().crease_degrees).tolist() == [True]


def test_a_box_edge_bends_outward_and_is_no_inward_crease() -> None:
    # the two side faces of a box whose edge points at the camera
    planes = two_patches((-45.0, np.array([-0.02, 0.0, 0.92])), (45.0, np.array([0.02, 0.0, 0.92])))
    assert inward_creases(planes, PAIR, 45.0).tolist() == [False]
    assert connection_votes(planes, PAIR, ConvexityRules())[1].tolist() == [True]


def test_a_gentle_inward_turn_is_no_crease() -> None:
    # normals 20 degrees apart bending slightly inward: a dent in one surface, left to the concave limit
    planes = two_patches((10.0, np.array([-0.02, 0.0, 0.90])), (-10.0, np.array([0.02, 0.0, 0.905])))
    assert inward_creases(planes, PAIR, 45.0).tolist() == [False]


def test_two_large_faces_meeting_in_one_sharp_inward_crease_stay_apart_though_a_small_face_agrees_with_both() -> None:
    # a can's side (patch 2) against a bowl's inner wall (patch 1), normals 120 degrees apart, facing each other 1.5 cm
    # apart; a small patch (3) between them, facing the camera, meets each gently enough to vote convex
    planes = PatchPlanes(
        counts=np.array([100, 100, 12]),
        centroids=np.array([[-0.0075, 0.0, 0.9], [0.0075, 0.0, 0.9], [0.0, 0.0, 0.89]]),
        normals=np.array([normal(60.0), normal(-60.0), normal(0.0)]),
        thickness=np.zeros(3),
        width=np.ones(3),
    )
    pairs = np.array([[1, 2], [1, 3], [2, 3]])
    _, convex, concave = connection_votes(planes, pairs, ConvexityRules())
    assert convex.tolist() == [False, True, True] and concave.tolist() == [True, False, False]
    faces = np.arange(4)  # each patch a face of its own
    objects = join_faces(faces, pairs, convex, concave, planes, ConvexityRules())
    assert objects[1] != objects[2] and objects[3] in (objects[1], objects[2])
    # one vote alone, bending inward more gently than decisive_bending, decides nothing: the small face joins all
    gentle = ConvexityRules(decisive_bending=200.0)
    objects = join_faces(faces, pairs, convex, concave, planes, gentle)
    assert objects[1] == objects[2] == objects[3]


def test_a_cell_across_a_seam_gives_a_patch_to_each_side() -> None:
    # one surface: two bands joined at the right, around the end of a seam (rows 2-3) that cuts the left cell
    surfaces = np.ones((6, 12), dtype=np.int32)
    surfaces[2:4, :9] = 0
    patches = grid_patches(surfaces, 6)
    left = patches[:, :6]
    assert left[0, 0] != left[5, 0] and left[0, 0] > 0 and left[5, 0] > 0  # two strips: two patches
    right = patches[:, 6:]
    assert len(np.unique(right[right > 0])) == 1  # the band's end joins both sides within the right cell
    assert sorted(np.unique(patches[patches > 0]).tolist()) == [1, 2, 3]


def _front_box_and_box_behind() -> tuple[ConvexObjects, np.ndarray]:
    """A front box (label 1, columns 0-9) beside the box behind it (label 2, columns 10-19), each its own
    depth-continuous surface (1 and 2); each label was grown two pixels onto the other's surface."""
    labels = np.zeros((10, 20), dtype=np.int32)
    labels[:, :12], labels[:, 12:] = 1, 2
    labels[:, 8:10] = 2  # the box behind's label grown onto the front box
    surfaces = np.where(np.arange(20) < 10, 1, 2)[None, :].repeat(10, axis=0).astype(np.int32)
    seeded = np.zeros(labels.shape, dtype=bool)
    seeded[:, :8], seeded[:, 12:] = True, True
    return ConvexObjects(labels, seeded), surfaces


def test_a_label_grown_across_its_objects_outline_onto_another_surface_is_spilled() -> None:
    objects, surfaces = _front_box_and_box_behind()
    spilled = objects.spilled(surfaces)
    assert spilled[:, 8:12].all()  # each label on the other box's surface, behind or in front
    assert not spilled[:, :8].any() and not spilled[:, 12:].any()  # seeded pixels


def test_a_label_grown_on_its_own_surface_is_not_spilled() -> None:
    objects, surfaces = _front_box_and_box_behind()
    one_surface = np.ones_like(surfaces)  # no depth seam: the grown pixels lie on a surface the label has seeds on
    assert not objects.spilled(one_surface).any()


def test_patches_grown_into_a_gap_touch_only_on_their_own_surface() -> None:
    # the box behind (surface 2, rows 0-2) above a depth seam (row 3, no surface) and the box in front (surface 1,
    # rows 4-9); patch 1 holds rows 0-1 of the box behind, patch 2 rows 8-9 of the box in front. Row 4, in front,
    # lies 3 pixels from patch 1 straight through the seam and 4 from its own patch
    surfaces = np.zeros((10, 8), dtype=np.int32)
    surfaces[:3], surfaces[4:] = 2, 1
    kept = np.zeros((10, 8), dtype=np.int32)
    kept[:2], kept[8:] = 1, 2
    seeds = seed_distances(kept, surfaces > 0, 4.0)
    bridged = bridge_gaps(kept, seeds, 4.0, surfaces)
    assert (bridged[2] == 1).all() and (bridged[4] == 0).all() and (bridged[5:8] == 2).all()
    assert touching_pairs(bridged).shape[0] == 0  # the box in front does not touch the box behind
    for turns in range(1, 4):  # the same whichever way up the image lies
        turned_kept, turned_surfaces = (np.ascontiguousarray(np.rot90(a, turns)) for a in (kept, surfaces))
        grown = bridge_gaps(turned_kept, seed_distances(turned_kept, turned_surfaces > 0, 4.0), 4.0, turned_surfaces)
        assert np.array_equal(np.rot90(grown, -turns), bridged)
