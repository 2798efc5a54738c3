"""Segmentation scores on small labellings whose figures are worked out by hand in each test."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from reasoning.evaluation.mosd import object_labels, scene_category
from reasoning.evaluation.segmentation import box_ious, count_box_matches, score_segmentation, summarize


def rectangle(labels: np.ndarray, value: int, rows: tuple[int, int], cols: tuple[int, int]) -> None:
    """Paint ``value`` on rows ``rows[0]..rows[1]`` and columns ``cols[0]..cols[1]`` (inclusive)."""
    labels[rows[0] : rows[1] + 1, cols[0] : cols[1] + 1] = value


def test_a_scene_where_every_object_is_found() -> None:
    truth = np.zeros((8, 10), dtype=int)
    rectangle(truth, 1, (1, 4), (1, 3))  # 12 pixels
    rectangle(truth, 2, (1, 4), (6, 8))  # 12 pixels
    predicted = np.zeros_like(truth)
    rectangle(predicted, 5, (1, 4), (1, 4))  # 16 pixels: object 1 and one column too many
    rectangle(predicted, 9, (2, 4), (6, 8))  # 9 pixels: object 2 without its top row
    score = score_segmentation(truth, predicted)
    # boxes: 12 / 16 and 9 / 12 -> both IoU 0.75 >= 0.5
    assert (score.objects, score.segments, score.matched) == (2, 2, 2)
    assert score.recall == 1.0 and score.precision == 1.0
    # overlap: (12 + 9) / (16 + 9) and (12 + 9) / (12 + 12); F = 2PR / (P + R) = 6/7
    assert score.overlap_precision == pytest.approx(21 / 25)
    assert score.overlap_recall == pytest.approx(21 / 24)
    assert score.overlap_f == pytest.approx(6 / 7)
    # pairwise F: 24 / 28 and 18 / 21, both 0.857 >= 0.75
    assert score.objects_f75 == 2
    # on an 8x10 image outlines match within ceil(0.003 * 12.8) = 1 pixel: every outline pixel of one is at most
    # one pixel from the other's
    assert (score.boundary_precision, score.boundary_recall, score.boundary_f) == (1.0, 1.0, 1.0)


def test_a_scene_where_two_touching_objects_come_out_as_one_segment() -> None:
    truth = np.zeros((6, 9), dtype=int)
    rectangle(truth, 1, (1, 4), (1, 3))  # 12 pixels
    rectangle(truth, 2, (1, 4), (4, 6))  # 12 pixels, touching object 1
    merged = np.zeros_like(truth)
    rectangle(merged, 1, (1, 4), (1, 7))  # 28 pixels: both objects and a column of table
    score = score_segmentation(truth, merged)
    # the segment's box (28 pixels) holds each object's box (12 pixels): IoU 12/28 < 0.5, nothing found
    assert (score.objects, score.segments, score.matched) == (2, 1, 0)
    assert score.recall == 0.0 and score.precision == 0.0
    # the segment is matched to one object (pairwise F 24/40 = 0.6 for both): P = 12/28, R = 12/24, F = 6/13
    assert score.overlap_precision == pytest.approx(3 / 7)
    assert score.overlap_recall == pytest.approx(1 / 2)
    assert score.overlap_f == pytest.approx(6 / 13)
    assert score.objects_f75 == 0

    separated = np.zeros_like(truth)
    rectangle(separated, 1, (1, 4), (1, 3))
    rectangle(separated, 2, (1, 4), (4, 7))  # object 2 and the column of table: 16 pixels, box IoU 12/16
    score = score_segmentation(truth, separated)
    assert (score.objects, score.segments, score.matched) == (2, 2, 2)
    # P = 24 / 28, R = 24 / 24, F = 2 * (6/7) / (6/7 + 1) = 12/13
    assert score.overlap_precision == pytest.approx(6 / 7)
    assert score.overlap_recall == 1.0
    assert score.overlap_f == pytest.approx(12 / 13)


def test_pixels_without_measurement_do_not_count() -> None:
    truth = np.zeros((4, 4), dtype=int)
    rectangle(truth, 1, (0, 1), (0, 1))
    predicted = np.zeros_like(truth)
    rectangle(predicted, 1, (0, 3), (0, 1))  # half of it lies where there is no measurement
    valid = np.zeros(truth.shape, dtype=bool)
    valid[:2] = True
    assert score_segmentation(truth, predicted, valid).overlap_f == 1.0
    assert score_segmentation(truth, predicted).overlap_precision == pytest.approx(0.5)


def test_box_matches_are_one_to_one() -> None:
    # two segments both overlapping the one object well: only one of them finds it
    ious = box_ious(np.array([[0, 0, 10, 10]]), np.array([[0, 0, 10, 9], [0, 1, 10, 10]]))
    assert ious.tolist() == [[0.9, 0.9]]
    assert count_box_matches(ious) == 1
    # the most pairs, not the best single pair: object A fits both segments, object B only the first
    ious = np.array([[0.9, 0.6], [0.7, 0.0]])
    assert count_box_matches(ious) == 2


def test_summary_sums_counts_and_averages_overlap() -> None:
    truth = np.zeros((6, 9), dtype=int)
    rectangle(truth, 1, (1, 4), (1, 3))
    rectangle(truth, 2, (1, 4), (4, 6))
    merged_labels = np.zeros_like(truth)
    rectangle(merged_labels, 1, (1, 4), (1, 7))
    perfect = score_segmentation(truth, truth)
    merged = score_segmentation(truth, merged_labels)
    summary = summarize([perfect, merged])
    assert (summary.scenes, summary.objects, summary.segments, summary.matched) == (2, 4, 3, 2)
    assert summary.recall == 0.5 and summary.precision == pytest.approx(2 / 3)
    assert summary.overlap_f == pytest.approx((1.0 + merged.overlap_f) / 2)


@settings(max_examples=60, deadline=None)
@given(arrays(np.int8, (12, 15), elements=st.integers(0, 4)), st.permutations([1, 2, 3, 4]))
def test_a_labelling_scored_against_itself_is_perfect_whatever_its_numbers(labels: np.ndarray, order) -> None:
    relabelled = np.where(labels > 0, np.array([0, *order])[labels], 0)
    score = score_segmentation(labels, relabelled)
    assert score.matched == score.objects == score.segments
    if score.objects:
        assert score.overlap_f == 1.0 and score.boundary_f == 1.0 and score.objects_f75 == score.objects


def test_mosd_labels_and_categories() -> None:
    labels = np.array([[0, 1, 3, 20], [21, 30, 39, 45]])
    assert object_labels(labels).tolist() == [[0, 0, 0, 1], [1, 2, 2, 3]]
    assert [scene_category(f"learn/learn{n}.pcd") for n in (0, 16, 17, 24, 25, 32, 33, 44)] == [
        "boxes", "boxes", "stacked", "stacked", "occluded", "occluded", "cylindric", "cylindric",
    ]  # fmt: skip
    assert scene_category("test/test50.pcd") == "mixed"
    assert scene_category("/data/clutter/scene3.pcd") == "clutter"
