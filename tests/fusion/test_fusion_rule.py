"""The attribute fusion rule and the per-frame merging of duplicate hypotheses."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from reasoning.fusion.frame import FrameContext, duplicate_groups, frame_objects
from reasoning.fusion.rule import MAX_LOG_ODDS, AttributeBelief, Evidence, accumulate, fuse_evidence, logit
from robokudo.core.types import Classification, ObjectHypothesis, Pose, SemanticColor, Shape, Size

SUBCLASSES = {("LactoseFreeMilk", "Milk"), ("Milk", "Drink"), ("LactoseFreeMilk", "Drink"), ("Cup", "Container")}


def is_subclass(a: str, b: str) -> bool:
    return a == b or (a, b) in SUBCLASSES


def test_two_experts_disagreeing_on_colour_give_the_stronger_value_and_keep_the_other() -> None:
    fused = fuse_evidence([Evidence("color", "red", 0.9, "ColorA"), Evidence("color", "blue", 0.6, "ColorB")])["color"]
    assert fused.value == "red"
    # log-odds: red 9:1, blue 1.5:1, "something else" 1 -> p(red) = 9 / 11.5
    assert fused.confidence == pytest.approx(9 / 11.5)
    assert fused.confidence < 0.9  # the conflict lowers the confidence of the winner
    assert fused.conflict
    assert fused.sources == ("ColorA",)
    support = {s.value: s for s in fused.support}
    assert set(support) == {"red", "blue"}
    assert support["blue"].sources == ("ColorB",)
    assert support["blue"].confidence == pytest.approx(1.5 / 11.5)


def test_one_statement_gives_back_its_confidence_and_agreement_raises_it() -> None:
    single = fuse_evidence([Evidence("shape", "box", 0.7, "A")])["shape"]
    assert single.confidence == pytest.approx(0.7)
    assert not single.conflict
    both = fuse_evidence([Evidence("shape", "box", 0.7, "A"), Evidence("shape", "box", 0.8, "B")])["shape"]
    assert both.confidence == pytest.approx(1 / (1 + math.exp(-(logit(0.7) + logit(0.8)))))
    assert both.sources == ("A", "B")


def test_subsumption_milk_and_lactose_free_milk_agree() -> None:
    evidence = [Evidence("class", "Milk", 0.8, "Detector"), Evidence("class", "LactoseFreeMilk", 0.7, "Reader")]
    fused = fuse_evidence(evidence, is_subclass)["class"]
    assert not fused.conflict
    assert fused.value == "LactoseFreeMilk"  # the most specific class that is more likely than not
    assert set(fused.sources) == {"Detector", "Reader"}
    milk = next(s for s in fused.support if s.value == "Milk")
    # the subclass statement supports the superclass: both experts count for Milk
    assert milk.confidence == pytest.approx(1 / (1 + math.exp(-(logit(0.8) + logit(0.7)))))
    assert milk.confidence > 0.8


def test_without_subsumption_the_same_classes_conflict() -> None:
    evidence = [Evidence("class", "Milk", 0.8, "Detector"), Evidence("class", "LactoseFreeMilk", 0.7, "Reader")]
    fused = fuse_evidence(evidence)["class"]
    assert fused.value == "Milk"
    assert fused.conflict


def test_a_weak_subclass_statement_does_not_refine_or_weaken_the_superclass() -> None:
    evidence = [Evidence("class", "Milk", 0.8, "Detector"), Evidence("class", "LactoseFreeMilk", 0.4, "Reader")]
    fused = fuse_evidence(evidence, is_subclass)["class"]
    assert fused.value == "Milk"
    assert fused.confidence == pytest.approx(0.8)


def test_incompatible_classes_conflict_even_with_subsumption() -> None:
    evidence = [
        Evidence("class", "LactoseFreeMilk", 0.7, "A"),
        Evidence("class", "Milk", 0.6, "B"),
        Evidence("class", "Cup", 0.9, "C"),
    ]
    fused = fuse_evidence(evidence, is_subclass)["class"]
    assert fused.conflict
    assert {s.value for s in fused.support} == {"LactoseFreeMilk", "Milk", "Cup"}


def test_repeated_frames_accumulate_but_stay_bounded() -> None:
    belief = AttributeBelief("color")
    for frame in range(200):
        belief.add(Evidence("color", "red", 0.95, "ColorA", float(frame)))
    support = belief.values["red"]
    assert support.count == 200
    assert support.log_odds == pytest.approx(MAX_LOG_ODDS)
    assert (support.first_seen, support.last_seen) == (0.0, 199.0)
    fused = belief.fuse()
    assert fused is not None and 0.99 < fused.confidence < 1.0


def test_merging_frame_beliefs_equals_accumulating_all_statements() -> None:
    frames = [
        [Evidence("color", "red", 0.9, "A", 1.0), Evidence("color", "blue", 0.6, "B", 1.0)],
        [Evidence("color", "red", 0.7, "A", 2.0)],
    ]
    merged = AttributeBelief("color")
    for statements in frames:
        merged.merge(accumulate(statements)["color"])
    direct = accumulate([e for statements in frames for e in statements])["color"]
    assert {v: s.log_odds for v, s in merged.values.items()} == pytest.approx(
        {v: s.log_odds for v, s in direct.values.items()}
    )
    assert merged.values["red"].count == 2 and merged.values["red"].sources == {"A"}


def _hypothesis(indices: np.ndarray, shape: tuple[int, int], source: str) -> ObjectHypothesis:
    mask = np.zeros(shape, bool)
    mask.ravel()[indices] = True
    rows, cols = np.nonzero(mask)
    roi = (int(cols.min()), int(rows.min()), int(cols.max()) + 1, int(rows.max()) + 1)
    return ObjectHypothesis(point_indices=indices, mask=mask, roi=roi, source=source, confidence=0.9)


def _grid(shape: tuple[int, int]) -> np.ndarray:
    rows, cols = np.indices(shape)
    points = np.stack([cols * 0.01, rows * 0.01, np.ones(shape)], axis=-1).astype(np.float32)
    return points


def _block(shape: tuple[int, int], r0: int, r1: int, c0: int, c1: int) -> np.ndarray:
    rows, cols = np.meshgrid(np.arange(r0, r1), np.arange(c0, c1), indexing="ij")
    return np.ravel_multi_index((rows.ravel(), cols.ravel()), shape)


def test_duplicates_from_two_segmenters_are_merged_into_one_object() -> None:
    shape = (40, 60)
    cup_a = _hypothesis(_block(shape, 5, 20, 5, 20), shape, "PlaneClusterSegmenter")
    cup_b = _hypothesis(_block(shape, 6, 21, 6, 19), shape, "ColorSegmenter")  # nearly the same pixels
    box = _hypothesis(_block(shape, 5, 30, 35, 55), shape, "PlaneClusterSegmenter")
    cup_a.annotations += [SemanticColor(color="red", confidence=0.9, source="ColorA")]
    cup_b.annotations += [
        SemanticColor(color="Red", confidence=0.7, source="ColorB"),
        Classification(class_name="Cup", confidence=0.8, source="Detector"),
    ]
    box.annotations += [Shape(shape="box", confidence=0.8, source="ShapeA")]
    assert duplicate_groups([cup_a, box, cup_b]) == [[0, 2], [1]]

    objects = frame_objects([cup_a, box, cup_b], FrameContext(points=_grid(shape), time=3.0))
    assert len(objects) == 2
    cup = objects[0]
    assert cup.hypotheses == 2
    assert {"PlaneClusterSegmenter", "ColorSegmenter", "ColorA", "ColorB", "Detector"} <= cup.sources
    assert cup.values("color") == {"red"}  # values are normalised before fusion
    assert cup.roi == (5, 5, 20, 21)
    fused = fuse_evidence(cup.evidence)
    assert fused["color"].value == "red" and fused["color"].sources == ("ColorA", "ColorB")
    assert fused["class"].value == "Cup"
    assert cup.frame == "camera"
    np.testing.assert_allclose(cup.position, [0.12, 0.125, 1.0], atol=0.01)
    assert objects[1].values("shape") == {"box"}


def test_frame_objects_use_pose_and_size_annotations_in_the_world_frame() -> None:
    shape = (10, 10)
    hypothesis = _hypothesis(_block(shape, 2, 5, 2, 5), shape, "Seg")
    hypothesis.annotations += [
        Pose(position=np.array([0.0, 0.0, 1.0]), orientation=np.array([0.0, 0.0, 0.0, 1.0]), source="PoseA"),
        Size(dimensions=(0.1, 0.3, 0.2), size_class="large", source="SizeA"),
    ]
    cam_to_world = np.eye(4)
    cam_to_world[:3, 3] = [1.0, 2.0, 0.5]
    (item,) = frame_objects([hypothesis], FrameContext(cam_to_world=cam_to_world))
    assert item.frame == "world"
    np.testing.assert_allclose(item.position, [1.0, 2.0, 1.5])
    np.testing.assert_allclose(item.dimensions, [0.3, 0.2, 0.1])
    assert item.values("size") == {"large"}


def test_hypotheses_without_any_position_are_left_out() -> None:
    shape = (10, 10)
    assert frame_objects([_hypothesis(_block(shape, 2, 5, 2, 5), shape, "Seg")]) == []


STATEMENTS = st.lists(
    st.tuples(st.sampled_from(["Milk", "LactoseFreeMilk", "Drink", "Cup"]), st.floats(0.0, 1.0)), max_size=6
)


@given(statements=STATEMENTS)
def test_supported_value_is_the_fused_value_when_evidence_supports_it(statements: list[tuple[str, float]]) -> None:
    belief = AttributeBelief("class")
    for value, confidence in statements:
        belief.add(Evidence("class", value, confidence, "Expert"))
    for class_test in (None, is_subclass):
        fused = belief.fuse(class_test)
        expected = fused.value if fused is not None and fused.supported else None
        assert belief.supported_value(class_test) == expected
