"""A generic ONNX object detector: runs a user-supplied YOLO-style model and names the hypotheses it overlaps.

No model ships with the project. The model is loaded lazily (once per annotator instance) with onnxruntime on the
CPU. Pre-processing letterboxes the RGB image into the model's input size (``DEFAULT_INPUT_SIZE`` when the input
is dynamic), scales it to [0, 1] and feeds it as NCHW float32. Outputs understood:

* one tensor ``(1, 4 + C, N)`` or ``(1, N, 4 + C)`` (YOLOv8 style: centre x, centre y, width, height, C class
  scores) or ``(1, N, 5 + C)`` (YOLOv5 style, with an objectness score before the class scores), told apart by the
  number of class names;
* three tensors: boxes ``(N, 4)`` as x0, y0, x1, y1, scores ``(N,)`` and class ids ``(N,)`` (models with NMS
  built in; a leading batch axis of 1 is allowed).

Boxes are in the model's input pixels; they are mapped back to the image, kept above ``score_threshold``, and
thinned by non-maximum suppression per class (``iou_threshold``). Class names come from ``class_names`` (a list,
or the path of a text file with one name per line), else from the model's metadata (``names``, as Ultralytics
writes it). Each name is mapped to an ontology class by ``class_map`` (a name mapped to "" is ignored), else
written in CamelCase ("wine glass" -> "WineGlass"). Each hypothesis gets the Classification of the best
detection whose box overlaps its image box with IoU >= ``overlap_threshold`` (confidence = detection score).
"""

from __future__ import annotations

import ast
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

import cv2
import numpy as np

from annotators.image.pixel_expert import image_and_hypotheses
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CasType, Classification, ColorImage, ObjectHypothesis

DEFAULT_INPUT_SIZE = 640
"""Input side (pixels) used when the model's input size is dynamic."""

PAD_VALUE = 114
"""Grey level of the letterbox padding (the YOLO convention)."""


class DetectorError(Exception):
    """The model or its output cannot be used; the message says why."""


@dataclass(frozen=True, eq=False)
class Detections:
    """Detected boxes (Nx4 x0, y0, x1, y1 in image pixels), scores (N) and class ids (N)."""

    boxes: np.ndarray
    scores: np.ndarray
    class_ids: np.ndarray


@dataclass(frozen=True)
class Letterbox:
    """How an image was fitted into the model input: scale, then padding (x, y) in input pixels."""

    scale: float
    pad_x: float
    pad_y: float

    def to_image(self, boxes: np.ndarray) -> np.ndarray:
        """Boxes (Nx4 x0, y0, x1, y1) from model input pixels back to image pixels."""
        return (boxes - (self.pad_x, self.pad_y, self.pad_x, self.pad_y)) / self.scale


def letterbox(image: np.ndarray, width: int, height: int) -> tuple[np.ndarray, Letterbox]:
    """The RGB image resized (aspect kept) and padded to ``width`` x ``height``, as 1x3xHxW float32 in [0, 1]."""
    rows, cols = image.shape[:2]
    scale = min(width / cols, height / rows)
    new_w, new_h = max(1, round(cols * scale)), max(1, round(rows * scale))
    pad_x, pad_y = (width - new_w) // 2, (height - new_h) // 2
    canvas = np.full((height, width, 3), PAD_VALUE, dtype=np.uint8)
    canvas[pad_y : pad_y + new_h, pad_x : pad_x + new_w] = cv2.resize(
        image, (new_w, new_h), interpolation=cv2.INTER_LINEAR
    )
    tensor = canvas.transpose(2, 0, 1)[None].astype(np.float32) * np.float32(1 / 255)
    return tensor, Letterbox(scale, pad_x, pad_y)


def box_iou(box: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """IoU of one box (4,) with each of N boxes (Nx4), all x0, y0, x1, y1."""
    x0 = np.maximum(box[0], boxes[:, 0])
    y0 = np.maximum(box[1], boxes[:, 1])
    x1 = np.minimum(box[2], boxes[:, 2])
    y1 = np.minimum(box[3], boxes[:, 3])
    inter = np.clip(x1 - x0, 0, None) * np.clip(y1 - y0, 0, None)
    area = (box[2] - box[0]) * (box[3] - box[1])
    areas = (boxes[:, 2] - boxes[:, 0]) * (boxes[:, 3] - boxes[:, 1])
    return inter / np.maximum(area + areas - inter, 1e-9)


def non_maximum_suppression(detections: Detections, iou_threshold: float) -> Detections:
    """The detections left after greedy per-class non-maximum suppression, best first."""
    keep: list[int] = []
    for class_id in np.unique(detections.class_ids):
        members = np.flatnonzero(detections.class_ids == class_id)
        members = members[np.argsort(-detections.scores[members], kind="stable")]
        while members.size:
            best, members = members[0], members[1:]
            keep.append(int(best))
            if members.size:
                members = members[box_iou(detections.boxes[best], detections.boxes[members]) < iou_threshold]
    order = np.array(sorted(keep, key=lambda i: -detections.scores[i]), dtype=np.int64)
    return Detections(detections.boxes[order], detections.scores[order], detections.class_ids[order])


def decode_outputs(outputs: Sequence[np.ndarray], class_count: int | None) -> Detections:
    """Boxes (x0, y0, x1, y1, model input pixels), scores and class ids from the model outputs (see the module)."""
    if len(outputs) >= 3:
        boxes, scores, ids = (np.asarray(o) for o in outputs[:3])
        boxes, scores, ids = boxes.reshape(-1, 4), scores.reshape(-1), ids.reshape(-1)
        if not boxes.shape[0] == scores.shape[0] == ids.shape[0]:
            raise DetectorError(f"boxes {boxes.shape}, scores {scores.shape} and class ids {ids.shape} disagree")
        return Detections(boxes.astype(np.float64), scores.astype(np.float64), ids.astype(np.int64))
    if len(outputs) != 1:
        raise DetectorError(f"expected one YOLO output tensor or three (boxes, scores, class ids), got {len(outputs)}")
    raw = np.asarray(outputs[0], dtype=np.float64)
    if raw.ndim == 3 and raw.shape[0] == 1:
        raw = raw[0]
    if raw.ndim != 2:
        raise DetectorError(f"cannot decode a detection output of shape {np.shape(outputs[0])}")
    rows, cols = raw.shape
    if class_count is not None and {rows, cols} & {4 + class_count, 5 + class_count}:
        attributes = rows if rows in (4 + class_count, 5 + class_count) else cols
    else:
        attributes = min(rows, cols)  # anchors outnumber attributes
    if attributes < 5:
        raise DetectorError(f"cannot decode a detection output of shape {np.shape(outputs[0])}")
    table = raw.T if rows == attributes else raw
    objectness = None
    if class_count is not None and attributes == 5 + class_count:
        objectness = table[:, 4]
        class_scores = table[:, 5:]
    else:
        class_scores = table[:, 4:]
    ids = np.argmax(class_scores, axis=1)
    scores = class_scores[np.arange(table.shape[0]), ids]
    if objectness is not None:
        scores = scores * objectness
    cx, cy, w, h = table[:, 0], table[:, 1], table[:, 2], table[:, 3]
    boxes = np.column_stack([cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2])
    return Detections(boxes, scores, ids.astype(np.int64))


def camel_case(name: str) -> str:
    """An ontology-style class name from a detector label: "wine glass" -> "WineGlass"."""
    return "".join(part[:1].upper() + part[1:] for part in name.replace("_", " ").replace("-", " ").split())


def names_from_metadata(metadata: Mapping[str, str]) -> list[str] | None:
    """Class names from a model's ``names`` metadata (a dict or list literal), or None."""
    text = metadata.get("names")
    if not text:
        return None
    try:
        value = ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return None
    if isinstance(value, Mapping):
        return [str(value[key]) for key in sorted(value, key=int)]
    if isinstance(value, list | tuple):
        return [str(v) for v in value]
    return None


class OnnxDetector(Annotator):
    """Runs a user-supplied ONNX detection model and attaches its classes to the hypotheses its boxes overlap."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage, ObjectHypothesis)
    outputs: ClassVar[tuple[type[CasType], ...]] = (Classification,)
    capability: ClassVar[Capability] = Capability(
        label="ONNX object detector",
        description="Runs a user-supplied YOLO-style ONNX detection model and names the hypotheses its boxes overlap.",
        preconditions=("NeedsDetectorModel",),
        cost_ms=80.0,
        reliability=0.8,
    )

    def __init__(
        self,
        model_path: str,
        class_names: Sequence[str] | str | None = None,
        score_threshold: float = 0.4,
        iou_threshold: float = 0.5,
        class_map: Mapping[str, str] | None = None,
        overlap_threshold: float = 0.3,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        self.model_path = Path(model_path)
        self.class_names = class_names
        self.score_threshold = score_threshold
        self.iou_threshold = iou_threshold
        self.class_map = dict(class_map or {})
        self.overlap_threshold = overlap_threshold
        self._names: list[str] | None = None

    # ------------------------------------------------------------------ model

    def session(self) -> Any:
        """The onnxruntime session (loaded on first use, shared through this annotator's resources with every
        detector of the same model file); raises DetectorError with the reason."""
        if not self.model_path.is_file():
            raise DetectorError(f"model file {self.model_path} does not exist")
        modified = self.model_path.stat().st_mtime_ns

        def load() -> Any:
            import onnxruntime

            try:
                return onnxruntime.InferenceSession(str(self.model_path), providers=["CPUExecutionProvider"])
            except Exception as error:  # onnxruntime raises its own types for malformed models
                raise DetectorError(f"cannot load ONNX model {self.model_path}: {error}") from None

        return self.resources.get(("onnx", str(self.model_path.resolve()), modified), load)

    def names(self) -> list[str]:
        """The model's class names: given, read from a file, or from the model's metadata."""
        if self._names is None:
            given = self.class_names
            if isinstance(given, str):
                path = Path(given)
                if not path.is_file():
                    raise DetectorError(f"class name file {path} does not exist")
                names = [line.strip() for line in path.read_text().splitlines() if line.strip()]
            elif given is not None:
                names = [str(n) for n in given]
            else:
                metadata = self.session().get_modelmeta().custom_metadata_map
                names = names_from_metadata(metadata) or []
            if not names:
                raise DetectorError("no class names: give class_names or use a model with 'names' metadata")
            self._names = names
        return self._names

    def input_size(self) -> tuple[int, int]:
        """(width, height) of the model's image input (DEFAULT_INPUT_SIZE for dynamic dimensions)."""
        shape = self.session().get_inputs()[0].shape
        if len(shape) != 4:
            raise DetectorError(f"the model's input must be NCHW, it has shape {shape}")
        height, width = (d if isinstance(d, int) and d > 0 else DEFAULT_INPUT_SIZE for d in shape[2:])
        return width, height

    def detect(self, image: np.ndarray) -> Detections:
        """The detections in an RGB image (image pixels), after thresholding and non-maximum suppression."""
        session = self.session()
        width, height = self.input_size()
        tensor, fit = letterbox(image, width, height)
        try:
            outputs = session.run(None, {session.get_inputs()[0].name: tensor})
        except Exception as error:  # onnxruntime's own error types
            raise DetectorError(f"the model failed to run: {error}") from None
        found = decode_outputs(outputs, len(self.names()))
        keep = found.scores >= self.score_threshold
        found = Detections(fit.to_image(found.boxes[keep]), found.scores[keep], found.class_ids[keep])
        return non_maximum_suppression(found, self.iou_threshold)

    def ontology_class(self, class_id: int) -> str | None:
        """The ontology class of a class id (None when unknown or mapped to "")."""
        names = self.names()
        if not 0 <= class_id < len(names):
            return None
        label = names[class_id]
        mapped = self.class_map.get(label, camel_case(label))
        return mapped or None

    # ------------------------------------------------------------------ annotator

    def analyse(self) -> None:
        """Detect, then attach the best overlapping detection's class to each hypothesis."""
        image, hypotheses = image_and_hypotheses(self, "name")
        try:
            detections = self.detect(image)
        except DetectorError as error:
            self.fail(str(error))
        if detections.scores.size == 0:
            self.fail(f"the model detected nothing with a score of at least {self.score_threshold}")
        named = 0
        for hypothesis in hypotheses:
            overlap = box_iou(np.asarray(hypothesis.roi, dtype=np.float64), detections.boxes)
            candidates = np.flatnonzero(overlap >= self.overlap_threshold)
            candidates = [i for i in candidates if self.ontology_class(int(detections.class_ids[i]))]
            if not candidates:
                continue
            best = max(candidates, key=lambda i: detections.scores[i] * overlap[i])
            class_name = self.ontology_class(int(detections.class_ids[best]))
            self.attach(
                hypothesis, Classification(class_name=str(class_name), confidence=float(detections.scores[best]))
            )
            named += 1
        if named == 0:
            self.fail(f"{detections.scores.size} detections, none overlaps a hypothesis with a known class")
