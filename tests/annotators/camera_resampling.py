"""One recorded view as other cameras would see it, shared by the tests and bench/bench_camera_resolution.py: the same
scene through finer pixels (each pixel repeated, focal length multiplied) or coarser ones (every few pixels kept,
focal length divided), and a reader that hands such a frame to a tree."""

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
