"""Object-by-object verdicts of a segmentation against a pixel and a box per object."""

from __future__ import annotations

import numpy as np

from reasoning.evaluation.object_verdicts import LabelledObject, object_verdicts

MUG = LabelledObject("mug", (15, 15), (10, 10, 30, 40))
CAN = LabelledObject("can", (55, 15), (50, 10, 70, 40))


def image() -> np.ndarray:
    return np.zeros((60, 90), dtype=np.int32)


def test_objects_with_their_own_segment_each_are_whole() -> None:
    labels = image()
    labels[10:40, 10:30] = 1
    labels[10:40, 50:70] = 2
    verdicts = object_verdicts(labels, [MUG, CAN])
    assert {name: v.kind for name, v in verdicts.items()} == {"mug": "whole", "can": "whole"}


def test_two_objects_in_one_segment_are_merged() -> None:
    labels = image()
    labels[10:40, 10:70] = 1
    verdicts = object_verdicts(labels, [MUG, CAN])
    assert verdicts["mug"].kind == "merged" and "can" in verdicts["mug"].detail
    assert verdicts["can"].kind == "merged"


def test_a_second_piece_inside_the_box_cuts_the_object() -> None:
    labels = image()
    labels[10:25, 10:30] = 1  # the mug's top half holds its pixel
    labels[25:40, 10:30] = 2  # its bottom half is a segment of its own: 300 px
    labels[10:40, 50:70] = 3
    verdicts = object_verdicts(labels, [MUG, CAN])
    assert verdicts["mug"].kind == "cut"
    assert verdicts["can"].kind == "whole"


def test_a_segment_reaching_far_beyond_the_box_spills_over() -> None:
    labels = image()
    labels[10:60, 10:85] = 1  # the mug with table round it
    assert object_verdicts(labels, [MUG])["mug"].kind == "spills over"


def test_no_segment_at_the_pixel_is_missed() -> None:
    labels = image()
    labels[10:40, 50:70] = 1
    assert object_verdicts(labels, [MUG, CAN])["mug"].kind == "missed"


def test_small_crumbs_in_the_box_do_not_cut_an_object() -> None:
    labels = image()
    labels[10:40, 10:30] = 1
    labels[38:40, 12:20] = 2  # 16 px of noise
    assert object_verdicts(labels, [MUG])["mug"].kind == "whole"
