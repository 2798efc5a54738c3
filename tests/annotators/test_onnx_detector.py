"""The generic ONNX detector on tiny models built with onnx.helper: loading, letterboxing, decoding, NMS, class
names and their ontology classes, and the planner condition that keeps it out of plans without a model."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from py_trees.common import Status

from annotators.image.onnx_detector import Detections, OnnxDetector, camel_case, decode_outputs, letterbox
from reasoning.knowledge.model import Conditions
from robokudo.application.knowledge import load_knowledge_base
from robokudo.core.annotator import Annotator
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import Classification, ColorImage, ObjectHypothesis
from tests.annotators.onnx_models import detection_model, one_box_model

IMAGE = np.zeros((480, 640, 3), np.uint8)  # letterboxed into 64x64: scale 0.1, 8 px padding top and bottom


def hypothesis(roi: tuple[int, int, int, int]) -> ObjectHypothesis:
    mask = np.zeros(IMAGE.shape[:2], bool)
    x0, y0, x1, y1 = roi
    mask[y0:y1, x0:x1] = True
    return ObjectHypothesis(point_indices=np.flatnonzero(mask), mask=mask, roi=roi)


class _Scene(Annotator):
    outputs = (ColorImage, ObjectHypothesis)

    def __init__(self, hypotheses: list[ObjectHypothesis]) -> None:
        super().__init__(name="scene")
        self.hypotheses = hypotheses

    def analyse(self) -> None:
        self.write(ColorImage(IMAGE))
        for item in self.hypotheses:
            self.write(item)


def run(detector: OnnxDetector, hypotheses: list[ObjectHypothesis]) -> OnnxDetector:
    Pipeline("detect", [_Scene(hypotheses), detector]).tick_once()
    return detector


def test_the_known_box_is_found_in_image_pixels_after_nms(tmp_path: Path) -> None:
    detector = OnnxDetector(str(one_box_model(tmp_path / "m.onnx")))
    found = detector.detect(IMAGE)
    assert found.boxes.shape == (1, 4)  # the duplicate is suppressed, the weak box thresholded away
    assert np.allclose(found.boxes[0], (220, 190, 420, 290))
    assert found.class_ids.tolist() == [1] and found.scores[0] == pytest.approx(0.9)


def test_hypotheses_under_the_box_get_the_mapped_class(tmp_path: Path) -> None:
    under, elsewhere = hypothesis((230, 180, 410, 300)), hypothesis((10, 10, 60, 60))
    detector = run(OnnxDetector(str(one_box_model(tmp_path / "m.onnx"))), [under, elsewhere])
    assert detector.status is Status.SUCCESS, detector.feedback_message
    found = under.first(Classification)
    assert found is not None and found.class_name == "MilkCarton" and found.confidence == pytest.approx(0.9)
    assert elsewhere.first(Classification) is None
    mapped = run(OnnxDetector(str(one_box_model(tmp_path / "m.onnx")), class_map={"milk carton": "Milk"}), [under])
    assert mapped.status is Status.SUCCESS and under.find(Classification)[-1].class_name == "Milk"


def test_class_names_from_a_list_a_file_or_the_metadata(tmp_path: Path) -> None:
    plain = detection_model(tmp_path / "plain.onnx", np.array([[32, 32, 20, 10, 0.1, 0.9]]).T[None])
    assert OnnxDetector(str(plain), ["bowl", "cup"]).names() == ["bowl", "cup"]
    (tmp_path / "names.txt").write_text("bowl\nwine glass\n")
    by_file = OnnxDetector(str(plain), str(tmp_path / "names.txt"))
    assert by_file.names() == ["bowl", "wine glass"] and by_file.ontology_class(1) == "WineGlass"
    assert OnnxDetector(str(one_box_model(tmp_path / "m.onnx"))).names() == ["cup", "milk carton"]
    ignored = OnnxDetector(str(plain), ["bowl", "cup"], class_map={"cup": ""})
    assert ignored.ontology_class(1) is None and ignored.ontology_class(7) is None
    assert camel_case("milk_carton") == "MilkCarton"


def test_yolov5_and_end_to_end_layouts_decode() -> None:
    v5 = np.array([[32, 32, 20, 10, 0.5, 0.2, 0.8]])[None]  # x, y, w, h, objectness, two class scores
    found = decode_outputs([v5], class_count=2)
    assert found.class_ids.tolist() == [1] and found.scores[0] == pytest.approx(0.4)
    assert np.allclose(found.boxes[0], (22, 27, 42, 37))
    boxes, scores, ids = np.array([[[1, 2, 3, 4]]]), np.array([[0.7]]), np.array([[3]])
    end_to_end = decode_outputs([boxes, scores, ids], class_count=5)
    assert isinstance(end_to_end, Detections) and end_to_end.class_ids.tolist() == [3]


def test_letterbox_keeps_the_aspect_and_maps_boxes_back() -> None:
    tensor, fit = letterbox(np.full((100, 200, 3), 255, np.uint8), 64, 64)
    assert tensor.shape == (1, 3, 64, 64) and tensor.dtype == np.float32
    assert fit.scale == pytest.approx(0.32) and fit.pad_y == 16 and fit.pad_x == 0
    assert tensor[0, 0, 0, 0] == pytest.approx(114 / 255) and tensor[0, 0, 32, 32] == pytest.approx(1.0)
    assert np.allclose(fit.to_image(np.array([[0.0, 16.0, 64.0, 48.0]])), [[0, 0, 200, 100]])


@pytest.mark.parametrize(
    ("make", "reason"),
    [
        (lambda tmp: OnnxDetector(str(tmp / "none.onnx")), "does not exist"),
        (lambda tmp: OnnxDetector(str((tmp / "bad.onnx", (tmp / "bad.onnx").write_text("x"))[0])), "cannot load"),
    ],
)
def test_a_missing_or_malformed_model_fails_with_the_reason(tmp_path: Path, make, reason: str) -> None:
    detector = run(make(tmp_path), [hypothesis((230, 180, 410, 300))])
    assert detector.status is Status.FAILURE and reason in detector.feedback_message


def test_plans_include_the_detector_only_when_a_model_is_configured(tmp_path: Path) -> None:
    kb = load_knowledge_base(tmp_path / "user.ttl")
    assert "NeedsDetectorModel" in kb.annotator("OnnxDetector").preconditions
    default = [spec.name for spec in kb.providers("Classification", value="Milk")]
    configured = [spec.name for spec in kb.providers("Classification", value="Milk", conditions=Conditions(model=True))]
    assert "OnnxDetector" not in default and "KnowledgeClassifier" in default
    assert "OnnxDetector" in configured
