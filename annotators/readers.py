"""Reader annotators: they put a colour image, a depth image and the camera info into the CAS.

* :class:`KitchenSceneReader` renders the project's built-in kitchen scene.
* :class:`ColorDepthPairReader` reads a recorded colour/depth PNG pair (see :mod:`annotators.frame_io`).

Both decode once and keep the frame on the instance, so repeated ticks of the same frame cost nothing but
the CAS writes; the arrays are shared with the CAS, never copied, and must not be modified downstream.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from pathlib import Path
from typing import ClassVar

import numpy as np

from annotators import kitchen_scene
from annotators.frame_io import Frame, FrameError, read_color_depth_pair
from robokudo.annotator import Annotator
from robokudo.types import CameraInfo, CameraIntrinsics, CasType, ColorImage, DepthImage, QueryView

DEFAULT_KITCHEN_VIEW = "table"


def _to_intrinsics(scene_intrinsics: kitchen_scene.CameraIntrinsics) -> CameraIntrinsics:
    """The runtime's intrinsics type from the scene renderer's."""
    k = scene_intrinsics
    return CameraIntrinsics(fx=k.fx, fy=k.fy, cx=k.cx, cy=k.cy, width=k.width, height=k.height)


class KitchenSceneReader(Annotator):
    """Renders the built-in kitchen from a named camera view (``"table"`` when ``view`` is None).

    ``seed`` seeds the sensor noise; ``moved`` moves objects (see ``kitchen_scene.kitchen_objects``). The
    optional QueryView input is declared for choosing the view from the query's region (not used yet).
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = ()
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (QueryView,)
    outputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage, DepthImage, CameraInfo)

    def __init__(
        self,
        view: str | None = None,
        seed: int = 0,
        moved: Mapping[str, np.ndarray] | None = None,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        self.scene_view = view
        self.seed = seed
        self.moved = dict(moved) if moved else None
        self._rendered: dict[str, kitchen_scene.RenderedScene] = {}
        self._last: kitchen_scene.RenderedScene | None = None

    @property
    def last_scene(self) -> kitchen_scene.RenderedScene | None:
        """The scene (with its ground truth) written by the last successful run, or None before it."""
        return self._last

    def choose_view(self) -> str:
        """The camera view to render (the configured one, else the default)."""
        return self.scene_view or DEFAULT_KITCHEN_VIEW

    def analyse(self) -> None:
        """Render (once per view) and write the three views."""
        view = self.choose_view()
        scene = self._rendered.get(view)
        if scene is None:
            try:
                scene = kitchen_scene.render_kitchen(view, seed=self.seed, moved=self.moved)
            except ValueError as error:
                self.fail(f"cannot render the kitchen: {error}")
            self._rendered[view] = scene
        self._last = scene
        self.write(ColorImage(scene.color))
        self.write(DepthImage(scene.depth))
        self.write(
            CameraInfo(
                intrinsics=_to_intrinsics(scene.intrinsics),
                cam_to_world=scene.cam_to_world,
                frame_id=f"kitchen/{view}",
                timestamp=time.time(),
            )
        )


class ColorDepthPairReader(Annotator):
    """Reads frame ``frame`` of a folder in the uoc layout (NNNNNN-color.png, NNNNNN-depth.png, camera_params.json).

    ``depth_scale`` is in sensor units per metre; None takes it from camera_params.json, else 1000 (mm).
    The camera pose is unknown, so CameraInfo carries no ``cam_to_world``.
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = ()
    outputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage, DepthImage, CameraInfo)

    def __init__(
        self, folder: str | Path, frame: int = 0, depth_scale: float | None = None, name: str | None = None
    ) -> None:
        super().__init__(name=name)
        self.folder = Path(folder)
        self.frame = frame
        self.depth_scale = depth_scale
        self._decoded: Frame | None = None

    def load(self) -> Frame:
        """The decoded frame (read from disk on first use); raises FrameError."""
        if self._decoded is None:
            self._decoded = read_color_depth_pair(self.folder, self.frame, self.depth_scale)
        return self._decoded

    def analyse(self) -> None:
        """Write the frame's colour, depth and camera info."""
        try:
            frame = self.load()
        except FrameError as error:
            self.fail(str(error))
        self.write(ColorImage(frame.color))
        self.write(DepthImage(frame.depth))
        self.write(CameraInfo(intrinsics=frame.intrinsics, frame_id="camera", timestamp=time.time()))
