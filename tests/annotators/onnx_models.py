"""Tiny ONNX detection models built with onnx.helper for the detector tests (no model ships with the project).

Each model reads a 1x3xSxS image and outputs fixed detections (the image only passes through a zero-weighted
sum, so the real input feeding and output decoding code runs).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper


def detection_model(
    path: Path,
    table: np.ndarray,
    size: int = 64,
    names: dict[int, str] | None = None,
) -> Path:
    """A model whose single output is ``table`` (e.g. 1 x (4 + C) x N, YOLOv8 layout) for any input image."""
    image = helper.make_tensor_value_info("images", TensorProto.FLOAT, [1, 3, size, size])
    output = helper.make_tensor_value_info("output0", TensorProto.FLOAT, list(table.shape))
    constant = numpy_helper.from_array(table.astype(np.float32), name="table")
    zero = numpy_helper.from_array(np.zeros((), np.float32), name="zero")
    nodes = [
        helper.make_node("ReduceSum", ["images"], ["total"], keepdims=0),
        helper.make_node("Mul", ["total", "zero"], ["nothing"]),
        helper.make_node("Add", ["table", "nothing"], ["output0"]),
    ]
    graph = helper.make_graph(nodes, "tiny_detector", [image], [output], initializer=[constant, zero])
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", 13)])
    model.ir_version = 8
    if names is not None:
        helper.set_model_props(model, {"names": repr(names)})
    onnx.checker.check_model(model)
    path.parent.mkdir(parents=True, exist_ok=True)
    onnx.save(model, str(path))
    return path


def one_box_model(path: Path, names: dict[int, str] | None = None) -> Path:
    """A 64x64-input YOLOv8-style model with two classes that detects class 1 at centre (32, 32), 20x10 input px
    (score 0.9), a weaker overlapping duplicate (0.6, removed by NMS) and a class-0 box below the threshold."""
    anchors = np.array(
        [
            [32.0, 32.0, 20.0, 10.0, 0.05, 0.9],
            [33.0, 32.0, 20.0, 10.0, 0.05, 0.6],
            [10.0, 10.0, 8.0, 8.0, 0.2, 0.1],
        ]
    )
    return detection_model(path, anchors.T[None], names=names if names is not None else {0: "cup", 1: "milk carton"})
