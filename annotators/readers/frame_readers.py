"""Reader annotators: they put a colour image, a depth image and the camera info into the CAS.

* :class:`KitchenSceneReader` renders the project's built-in kitchen scene (with the camera pose).
* :class:`ColorDepthPairReader` reads a frame of a uoc-layout folder (see :mod:`annotators.readers.frame_io`).
* :class:`TumSequenceReader` and :class:`TumPairReader` read the TUM RGB-D layouts (:mod:`annotators.readers.tum_io`).
* :class:`PcdReader` reads an organized PCD file and also writes its point cloud (:mod:`annotators.readers.pcd_io`).
* :class:`TiffSequenceReader` reads the PCL ImageGrabber TIFF layout (:mod:`annotators.readers.tiff_io`).
* :class:`BagReader` reads a frame of a ROS 1 or ROS 2 bag (:mod:`annotators.readers.bag_io`).
* :class:`Open3dFolderReader` reads a frame of an Open3D RGB-D folder (:mod:`annotators.readers.open3d_io`).

:func:`annotators.readers.choice.reader_for` picks the reader from a path. Every reader decodes once and keeps the frame
on the instance, so repeated ticks of the same frame cost nothing but the CAS writes; the arrays are shared with
the CAS, never copied, and must not be modified downstream. Recorded frames have no camera pose (``cam_to_world`` is
None) unless the recording gives one (an Open3D folder's ``trajectory.log``, a TUM sequence's ``groundtruth.txt``).
Every reader names the recording its frame belongs to (``CameraInfo.recording``): a sequence folder (TUM, TIFF,
Open3D) is one continuous recording, while each file of a uoc folder, a TUM pair or a PCD file is a snapshot of its
own; all views of the built-in kitchen show one world (``KITCHEN_RECORDING``).
"""

from __future__ import annotations

import time
from abc import abstractmethod
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import ClassVar, Generic, TypeVar

import numpy as np

from annotators.readers.bag_io import MILLIMETRES, BagTopics, read_bag_frame
from annotators.readers.frame_io import Frame, FrameError, frame_camera, read_color_depth_pair, require_frame_folder
from annotators.readers.open3d_io import OPEN3D_DEPTH_SCALE, Open3dRecording
from annotators.readers.pcd_io import read_pcd
from annotators.readers.tiff_io import read_tiff_frame
from annotators.readers.tum_io import TUM_DEPTH_SCALE, TumSequence, read_tum_pair
from annotators.simulation import kitchen_person, kitchen_scene
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CameraInfo, CameraIntrinsics, CasType, ColorImage, DepthImage, PointCloud, QueryView

DEFAULT_KITCHEN_VIEW = "table"
PERSON_VIEW = "person"
"""The kitchen view of the table with a person behind it (``kitchen_person.person_view``)."""
KITCHEN_RECORDING = "kitchen"
"""The recording of every view of the built-in kitchen: one simulated world."""


class KitchenSceneReader(Annotator):
    """Renders the built-in kitchen from a named camera view (``"table"`` when ``view`` is None).

    ``seed`` seeds the sensor noise; ``moved`` moves objects (see ``kitchen_scene.kitchen_objects``); ``person``
    puts a person into the kitchen (a spec of ``kitchen_person.person_spec_pose``: ``stand``, ``wave``,
    ``point:<target>``, optionally ``@x,y``), seen by default from the ``"person"`` view (table and person); ``extra``
    adds objects with their albedo (``render_kitchen(extra=...)``, e.g. a storage layout's ``extra()``). The
    optional QueryView input is declared for choosing the view from the query's region (not used yet).
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = ()
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (QueryView,)
    outputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage, DepthImage, CameraInfo)
    capability: ClassVar[Capability] = Capability(
        label="kitchen scene reader",
        description="Renders the built-in synthetic kitchen (colour, depth, camera info).",
        cost_ms=60.0,
        reliability=1.0,
    )

    def __init__(
        self,
        view: str | None = None,
        seed: int = 0,
        moved: Mapping[str, np.ndarray] | None = None,
        person: str | None = None,
        extra: Sequence[tuple[kitchen_scene.SceneObject, tuple[int, int, int]]] = (),
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        self.extra = tuple(extra)
        self.scene_view = view
        self.seed = seed
        self.moved = dict(moved) if moved else None
        self.person = person
        self._rendered: dict[str, kitchen_scene.RenderedScene] = {}
        self._last: kitchen_scene.RenderedScene | None = None

    @property
    def last_scene(self) -> kitchen_scene.RenderedScene | None:
        """The scene (with its ground truth) written by the last successful run, or None before it."""
        return self._last

    def choose_view(self) -> str:
        """The camera view to render (the configured one, else the person view with a person, else the default)."""
        return self.scene_view or (PERSON_VIEW if self.person else DEFAULT_KITCHEN_VIEW)

    def analyse(self) -> None:
        """Render (once per view) and write the three views."""
        view = self.choose_view()
        scene = self._rendered.get(view)
        if scene is None:
            try:
                person = kitchen_person.person_spec_pose(self.person) if self.person else None
                camera = kitchen_person.person_view() if view == PERSON_VIEW else view
                scene = kitchen_scene.render_kitchen(
                    camera, seed=self.seed, moved=self.moved, person=person, extra=self.extra
                )
            except ValueError as error:
                self.fail(f"cannot render the kitchen: {error}")
            self._rendered[view] = scene
        self._last = scene
        self.write(ColorImage(scene.color))
        self.write(DepthImage(scene.depth))
        self.write(
            CameraInfo(
                intrinsics=scene.intrinsics,
                cam_to_world=scene.cam_to_world,
                frame_id=f"kitchen/{view}",
                timestamp=time.time(),
                recording=KITCHEN_RECORDING,
            )
        )


class FileFrameReader(Annotator):
    """Base of the readers of recorded frames: decode once (:meth:`decode`), then write the views on every run.

    ``intrinsics`` given explicitly replace those of the files; readers whose frames hold a point cloud declare
    PointCloud among their outputs and write it too.
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = ()
    outputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage, DepthImage, CameraInfo)

    def __init__(self, name: str | None = None) -> None:
        super().__init__(name=name)
        self._decoded: Frame | None = None
        self._cloud: PointCloud | None = None

    @abstractmethod
    def decode(self) -> Frame:
        """Read the frame from disk; raises FrameError with the reason."""

    @abstractmethod
    def recording(self) -> str:
        """The recording this frame belongs to: the sequence for a continuous recording, else the snapshot."""

    @property
    def last_frame(self) -> Frame | None:
        """The decoded frame (with ground-truth labels when the file has them), None before the first read."""
        return self._decoded

    def load(self) -> Frame:
        """The decoded frame (read from disk on first use); raises FrameError."""
        if self._decoded is None:
            self._decoded = self.decode()
        return self._decoded

    def analyse(self) -> None:
        """Write the frame's colour, depth and camera info (and its cloud when the reader provides one)."""
        try:
            frame = self.load()
        except FrameError as error:
            self.fail(str(error))
        except (OSError, ValueError) as error:
            self.fail(f"cannot read the frame: {type(error).__name__}: {error}")
        self.write(ColorImage(frame.color))
        self.write(DepthImage(frame.depth))
        self.write(frame_camera(frame, self.recording()))
        if PointCloud in self.outputs:
            if frame.points is None:
                self.fail(f"{frame.source} holds no point cloud")
            if self._cloud is None:
                mask = np.isfinite(frame.points[..., 2])
                self._cloud = PointCloud(points=frame.points, mask=mask, colors=frame.color)
            self.write(self._cloud)


class ColorDepthPairReader(FileFrameReader):
    """Reads frame ``frame`` of a folder in the uoc layout (NNNNNN-color.png, NNNNNN-depth.png, camera_params.json).

    ``depth_scale`` is in sensor units per metre; None takes it from camera_params.json, else 1000 (mm).
    """

    capability: ClassVar[Capability] = Capability(
        label="colour/depth pair reader",
        description="Reads a frame of a uoc-layout folder (NNNNNN-color.png, NNNNNN-depth.png, camera_params.json).",
        cost_ms=15.0,
        reliability=1.0,
    )

    def __init__(
        self, folder: str | Path, frame: int = 0, depth_scale: float | None = None, name: str | None = None
    ) -> None:
        super().__init__(name=name)
        self.folder = Path(folder)
        self.frame = frame
        self.depth_scale = depth_scale

    def decode(self) -> Frame:
        """Decode the pair of PNGs with the folder's camera parameters."""
        return read_color_depth_pair(self.folder, self.frame, self.depth_scale)

    def recording(self) -> str:
        """The frame itself: the frames of a uoc folder are separate scenes, not one recording."""
        return f"{self.folder.resolve()}#{self.frame:06d}"


OpenedRecording = TypeVar("OpenedRecording", TumSequence, Open3dRecording)


class _RecordingFolderReader(FileFrameReader, Generic[OpenedRecording]):
    """Base of the readers of frame ``frame`` of a folder holding one continuous recording. ``depth_scale`` is in
    units per metre (None: the layout's ``default_depth_scale``); ``intrinsics`` given replace the folder's;
    ``opened`` is the folder's lists read once, shared by the readers of all its frames (a playback stream), else
    each decode reads them."""

    default_depth_scale: ClassVar[float]
    layout: ClassVar[type[TumSequence] | type[Open3dRecording]]
    """The folder's lists, read by its ``open``."""

    def __init__(
        self,
        folder: str | Path,
        frame: int = 0,
        depth_scale: float | None = None,
        intrinsics: CameraIntrinsics | None = None,
        name: str | None = None,
        opened: OpenedRecording | None = None,
    ) -> None:
        super().__init__(name=name)
        self.folder = Path(folder)
        self.frame = frame
        self.depth_scale = self.default_depth_scale if depth_scale is None else depth_scale
        self.intrinsics = intrinsics
        self.opened = opened

    def recording(self) -> str:
        """The folder: one continuous recording."""
        return str(self.folder.resolve())

    def decode(self) -> Frame:
        """Decode the frame from the folder's lists, read now unless opened already."""
        opened = self.opened or self.open(require_frame_folder(self.folder, self.frame))
        return opened.read(self.frame, self.depth_scale, self.intrinsics)

    @classmethod
    def open(cls, folder: Path) -> OpenedRecording:
        """Read the folder's lists, for the readers of all its frames to share."""
        return cls.layout.open(folder)


class TumSequenceReader(_RecordingFolderReader[TumSequence]):
    """Reads frame ``frame`` (time order) of a TUM RGB-D sequence folder (rgb.txt, depth.txt).

    ``depth_scale`` is in units per metre (TUM: 5000); ``intrinsics`` default to the folder's camera_params.json,
    else the PrimeSense default TUM documents (fx = fy = 525, cx = 319.5, cy = 239.5).
    """

    capability: ClassVar[Capability] = Capability(
        label="TUM sequence reader",
        description="Reads a frame of a TUM RGB-D sequence folder (rgb.txt, depth.txt; depth scale 5000).",
        cost_ms=15.0,
        reliability=1.0,
    )

    default_depth_scale: ClassVar[float] = TUM_DEPTH_SCALE
    layout: ClassVar[type[TumSequence]] = TumSequence


class TumPairReader(FileFrameReader):
    """Reads one TUM-style colour/depth pair given by either file (``TUM_color.png`` beside ``TUM_depth.png``).

    ``depth_scale`` is in units per metre (TUM: 5000); ``intrinsics`` default to the PrimeSense default.
    """

    capability: ClassVar[Capability] = Capability(
        label="TUM pair reader",
        description="Reads one TUM-style colour/depth pair (TUM_color.png beside TUM_depth.png; depth scale 5000).",
        cost_ms=15.0,
        reliability=1.0,
    )

    def __init__(
        self,
        path: str | Path,
        depth_scale: float = TUM_DEPTH_SCALE,
        intrinsics: CameraIntrinsics | None = None,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        self.path = Path(path)
        self.depth_scale = depth_scale
        self.intrinsics = intrinsics

    def decode(self) -> Frame:
        """Find the other file of the pair and decode both."""
        return read_tum_pair(self.path, self.depth_scale, self.intrinsics)

    def recording(self) -> str:
        """The pair's file: a snapshot of its own."""
        return str(self.path.resolve())


class Open3dFolderReader(_RecordingFolderReader[Open3dRecording]):
    """Reads frame ``frame`` of an Open3D RGB-D folder (``color/`` or ``image/``, ``depth/``, camera JSON), with its
    camera pose when the folder has a ``trajectory.log``.

    ``depth_scale`` is in units per metre (Open3D: 1000); ``intrinsics`` default to the folder's Open3D camera JSON,
    else the PrimeSense default.
    """

    capability: ClassVar[Capability] = Capability(
        label="Open3D folder reader",
        description="Reads a frame of an Open3D RGB-D folder (color/ and depth/ images, camera JSON, poses).",
        cost_ms=15.0,
        reliability=1.0,
    )

    default_depth_scale: ClassVar[float] = OPEN3D_DEPTH_SCALE
    layout: ClassVar[type[Open3dRecording]] = Open3dRecording


class PcdReader(FileFrameReader):
    """Reads an organized PCD file (x y z rgb/rgba, optional ``label``): colour, depth (z), camera info and the
    cloud itself, so no PointCloudGenerator is needed. Intrinsics are fitted to the grid unless given; the
    ``label`` field is kept as ground truth in ``last_frame.labels``."""

    outputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage, DepthImage, CameraInfo, PointCloud)
    capability: ClassVar[Capability] = Capability(
        label="PCD reader",
        cost_ms=60.0,
        reliability=1.0,
    )

    def __init__(self, path: str | Path, intrinsics: CameraIntrinsics | None = None, name: str | None = None) -> None:
        super().__init__(name=name)
        self.path = Path(path)
        self.intrinsics = intrinsics

    def decode(self) -> Frame:
        """Decode the PCD file."""
        return read_pcd(self.path, self.intrinsics)

    def recording(self) -> str:
        """The PCD file: a snapshot of its own."""
        return str(self.path.resolve())


class TiffSequenceReader(FileFrameReader):
    """Reads frame ``frame`` of a PCL ImageGrabber TIFF folder (tiff/ with pclzf/*.xml, or the tiff folder).

    ``depth_scale`` (units per metre) and ``intrinsics`` default to the frame's XML file.
    """

    capability: ClassVar[Capability] = Capability(
        label="TIFF sequence reader",
        description="Reads a frame of a PCL ImageGrabber folder (16-bit TIFF pairs with XML intrinsics).",
        cost_ms=20.0,
        reliability=1.0,
    )

    def __init__(
        self,
        folder: str | Path,
        frame: int = 0,
        depth_scale: float | None = None,
        intrinsics: CameraIntrinsics | None = None,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        self.folder = Path(folder)
        self.frame = frame
        self.depth_scale = depth_scale
        self.intrinsics = intrinsics

    def decode(self) -> Frame:
        """Decode the frame's TIFFs with the XML intrinsics."""
        return read_tiff_frame(self.folder, self.frame, self.depth_scale, self.intrinsics)

    def recording(self) -> str:
        """The grabber folder: one continuous recording."""
        return str(self.folder.resolve())


class BagReader(FileFrameReader):
    """Reads frame ``frame`` (recording order) of a ROS 1 ``.bag`` or a ROS 2 bag (folder, ``.mcap``, ``.db3``).

    Colour + depth ``sensor_msgs/Image`` paired by stamp with the ``CameraInfo`` intrinsics; topics are picked by
    type unless named. ``depth_scale`` is in units per metre of 16-bit depth (ROS: millimetres).
    :class:`BagCloudReader` reads bags of organized ``PointCloud2`` messages.
    """

    capability: ClassVar[Capability] = Capability(
        label="bag reader",
        description="Reads a frame of a ROS 1 or ROS 2 bag (sensor_msgs/Image colour + depth with CameraInfo).",
        cost_ms=40.0,
        reliability=1.0,
    )

    def __init__(
        self,
        path: str | Path,
        frame: int = 0,
        color_topic: str | None = None,
        depth_topic: str | None = None,
        info_topic: str | None = None,
        cloud_topic: str | None = None,
        depth_scale: float = MILLIMETRES,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        self.path = Path(path)
        self.frame = frame
        self.topics = BagTopics(color=color_topic, depth=depth_topic, info=info_topic, cloud=cloud_topic)
        self.depth_scale = depth_scale

    def decode(self) -> Frame:
        """Read the bag up to the frame and decode it."""
        return read_bag_frame(self.path, self.frame, self.topics, self.depth_scale)

    def recording(self) -> str:
        """The bag: one continuous recording."""
        return str(self.path.resolve())


class BagCloudReader(BagReader):
    """Reads frame ``frame`` of a bag of organized ``sensor_msgs/PointCloud2`` messages: colour, depth (z), camera
    info (fitted to the grid) and the cloud itself. A colour + depth image bag gives no cloud (use BagReader)."""

    outputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage, DepthImage, CameraInfo, PointCloud)
    capability: ClassVar[Capability] = Capability(
        label="bag cloud reader",
        description="Reads a frame of a ROS 1 or ROS 2 bag of organized sensor_msgs/PointCloud2 messages.",
        cost_ms=60.0,
        reliability=1.0,
    )
