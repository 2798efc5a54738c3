"""One recorded view as other cameras would see it, shared by the tests and bench/bench_camera_resolution.py: the same
scene through finer pixels (each pixel repeated, focal length multiplied) or coarser ones (every few pixels kept,
focal length divided), through the camera rolled by quarter turns about its axis or through a noisier sensor, and a
reader that hands such a frame to a tree."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from annotators.readers.frame_io import Frame
from annotators.readers.frame_readers import FileFrameReader, PcdReader
from robokudo.core.types import CameraIntrinsics, CasType


class GivenFrame(FileFrameReader):
    """A reader of one frame already in memory, with its organized cloud."""

    outputs: ClassVar[tuple[type[CasType], ...]] = PcdReader.outputs

    def __init__(self, frame: Frame) -> None:
        super().__init__()
        self.frame = frame

    def decode(self) -> Frame:
        return self.frame

    def recording(self) -> str:
        return self.frame.source


def resampled(frame: Frame, factor: int, finer: bool) -> Frame:
    """``frame`` (with its organized cloud) seen by a camera with ``factor`` times finer pixels (each pixel repeated)
    or coarser ones (every ``factor``-th pixel kept); the cloud is cast again along the new camera's rays at the
    same depths, so neighbouring pixels lie 1 / focal length apart as on a real camera."""
    if frame.points is None:
        raise ValueError(f"{frame.source} has no organized cloud to resample")
    k = frame.intrinsics
    if finer:

        def pick(a: np.ndarray) -> np.ndarray:
            return np.repeat(np.repeat(a, factor, axis=0), factor, axis=1)

        shift, scale = (factor - 1) / 2, float(factor)
    else:

        def pick(a: np.ndarray) -> np.ndarray:
            return np.ascontiguousarray(a[::factor, ::factor])

        shift, scale = 0.0, 1.0 / factor
    depth = pick(frame.points[..., 2])
    rows, cols = depth.shape
    camera = CameraIntrinsics(k.fx * scale, k.fy * scale, k.cx * scale + shift, k.cy * scale + shift, cols, rows)
    v, u = np.mgrid[0:rows, 0:cols].astype(np.float32)
    points = np.stack(
        [(u - camera.cx) / camera.fx * depth, (v - camera.cy) / camera.fy * depth, depth], axis=-1
    ).astype(np.float32)
    return Frame(
        color=pick(frame.color),
        depth=pick(frame.depth),
        intrinsics=camera,
        source=frame.source,
        points=points,
        labels=None if frame.labels is None else pick(frame.labels),
    )


def rolled(frame: Frame, quarter_turns: int) -> Frame:
    """``frame`` (with its organized cloud) seen by the camera rolled about its optical axis so that the image turns
    by ``quarter_turns`` x 90 degrees counter-clockwise (``np.rot90``); the cloud turns with the camera."""
    if frame.points is None:
        raise ValueError(f"{frame.source} has no organized cloud to roll")
    turns = quarter_turns % 4
    points, k = frame.points, frame.intrinsics
    for _ in range(turns):  # a pixel's image column becomes its row: (x, y) -> (y, -x) in the camera frame
        points = np.stack([points[..., 1], -points[..., 0], points[..., 2]], axis=-1)
        k = CameraIntrinsics(k.fy, k.fx, k.cy, k.width - 1 - k.cx, k.height, k.width)

    def turned(a: np.ndarray) -> np.ndarray:
        return np.ascontiguousarray(np.rot90(a, turns))

    return Frame(
        color=turned(frame.color),
        depth=turned(frame.depth),
        intrinsics=k,
        source=frame.source,
        points=turned(points).astype(np.float32),
        labels=None if frame.labels is None else turned(frame.labels),
    )


def noisier(frame: Frame, millimetres_at_1m: float, seed: int = 0) -> Frame:
    """``frame`` (with its organized cloud) from a noisier sensor: each point moved along its ray by Gaussian noise
    of ``millimetres_at_1m * z^2`` (the depth noise of a structured-light or stereo camera grows with the square
    of the depth), drawn with ``seed``."""
    if frame.points is None:
        raise ValueError(f"{frame.source} has no organized cloud to add noise to")
    depth = frame.points[..., 2]
    noise = np.random.default_rng(seed).normal(0.0, 1.0, depth.shape).astype(np.float32)
    scale = 1.0 + noise * np.float32(millimetres_at_1m / 1000.0) * depth  # z (1 + n s z): sigma s z^2 along the ray
    points = (frame.points * scale[..., None]).astype(np.float32)
    return Frame(
        color=frame.color,
        depth=frame.depth,
        intrinsics=frame.intrinsics,
        source=frame.source,
        points=points,
        labels=frame.labels,
    )
