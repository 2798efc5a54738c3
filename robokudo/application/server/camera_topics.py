"""The camera topics ``/robokudo/image`` and ``/robokudo/depth``: the frame a task analysed (with its hypotheses'
boxes and labels), or the live frame while no task runs.

After each tick the engine thread asks :class:`FramePicker` which frame to show, which only takes references (no
copy, nothing encoded on the engine thread); the server encodes the picked frame as JPEG on a worker thread
(:func:`image_messages`). A task's analysed frame is shown as soon as its run ends; a live frame at most every
:data:`LIVE_PERIOD` seconds, and not within :data:`HOLD_ANALYSED` seconds after an analysed one (so a person sees
what the task found). The message is ``robokudo_msgs/AnnotatedImage``: a ``sensor_msgs/CompressedImage`` (header,
``format``, base64 ``data``) plus ``width``, ``height``, ``kind`` ("analysed" or "live") and ``hypotheses`` (each
``roi`` ``[x0, y0, x1, y1]`` in pixels and a ``label``).
"""

from __future__ import annotations

import base64
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np

from robokudo.application.annotated_image import Box, answer_boxes
from robokudo.core.cas import CAS
from robokudo.core.types import CameraInfo, ColorImage, DepthImage

LIVE_PERIOD = 0.5
"""Seconds between two live frames (the page needs no video rate; encoding costs the server CPU)."""
HOLD_ANALYSED = 3.0
"""Seconds an analysed frame stays before live frames replace it."""
JPEG_QUALITY = 80
DEPTH_RANGE_M = (0.3, 4.0)
"""Depths mapped onto the colour scale of the depth image."""


@dataclass(frozen=True, eq=False)
class ShownFrame:
    """A frame to publish: references to the CAS's images (not copies), its stamp, frame id and boxes."""

    color: np.ndarray
    depth: np.ndarray | None
    stamp: float
    frame_id: str
    kind: str
    boxes: tuple[Box, ...]


def frame_of(cas: CAS, kind: str, boxes: tuple[Box, ...] = ()) -> ShownFrame | None:
    """The CAS's colour frame (and depth) to show, None when it has no colour image."""
    color = cas.view(ColorImage)
    if color is None:
        return None
    depth = cas.view(DepthImage)
    camera = cas.view(CameraInfo)
    stamp = camera.timestamp if camera is not None and camera.timestamp > 0 else time.time()
    frame_id = camera.frame_id if camera is not None else "camera"
    return ShownFrame(color.image, depth.depth if depth is not None else None, stamp, frame_id, kind, boxes)


class FramePicker:
    """Decides after each tick which frame to publish, if any (see the module)."""

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        self._clock = clock
        self._last_cas: CAS | None = None
        self._analysed_at = -math.inf
        self._live_at = -math.inf

    def pick(self, finished_task: CAS | None, perceived: CAS | None) -> ShownFrame | None:
        """The frame to publish after this tick: ``finished_task`` is the CAS of a task run that ended this tick
        (None when none did), ``perceived`` the perception pipeline's CAS."""
        now = self._clock()
        if finished_task is not None and finished_task is not self._last_cas:
            self._last_cas = finished_task
            shown = frame_of(finished_task, "analysed", answer_boxes(finished_task))
            if shown is not None:
                self._analysed_at = now
                return shown
        if perceived is None or now - self._analysed_at < HOLD_ANALYSED or now - self._live_at < LIVE_PERIOD:
            return None
        shown = frame_of(perceived, "live")
        if shown is not None:
            self._live_at = now
        return shown


def _jpeg(rgb_or_grey: np.ndarray) -> str:
    ok, encoded = cv2.imencode(".jpg", rgb_or_grey, [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY])
    if not ok:
        raise ValueError("the frame could not be encoded as JPEG")
    return base64.b64encode(encoded.tobytes()).decode("ascii")


def depth_colours(depth: np.ndarray) -> np.ndarray:
    """A BGR picture of ``depth`` (metres): near is warm, far is cool, no data is black."""
    near, far = DEPTH_RANGE_M
    valid = np.isfinite(depth) & (depth > 0)
    scaled = np.zeros(depth.shape, np.uint8)
    scaled[valid] = (255 * (1 - np.clip((depth[valid] - near) / (far - near), 0, 1))).astype(np.uint8)
    picture = cv2.applyColorMap(scaled, cv2.COLORMAP_TURBO)
    picture[~valid] = 0
    return picture


def _message(shown: ShownFrame, data: str, boxes: tuple[Box, ...]) -> dict[str, Any]:
    seconds = math.floor(shown.stamp)
    height, width = shown.color.shape[:2]
    return {
        "header": {
            "stamp": {"sec": int(seconds), "nanosec": int((shown.stamp - seconds) * 1e9)},
            "frame_id": shown.frame_id,
        },
        "format": "jpeg",
        "data": data,
        "width": int(width),
        "height": int(height),
        "kind": shown.kind,
        "hypotheses": [{"roi": list(box.roi), "label": box.label} for box in boxes],
    }


def image_messages(shown: ShownFrame) -> tuple[dict[str, Any], dict[str, Any] | None]:
    """The ``/robokudo/image`` message of ``shown`` and its ``/robokudo/depth`` message (None without depth)."""
    color = _message(shown, _jpeg(cv2.cvtColor(shown.color, cv2.COLOR_RGB2BGR)), shown.boxes)
    depth = None if shown.depth is None else _message(shown, _jpeg(depth_colours(shown.depth)), ())
    return color, depth
