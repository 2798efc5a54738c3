"""Frame streams: live sources that give the next frame each time they are asked, paced at a sensor rate.

* :class:`KitchenCameraStream` is the built-in kitchen as a simulated camera: a frame every ``1 / rate_hz`` s from
  the current view, which can be changed while it runs (:meth:`~KitchenCameraStream.look_at` a region, as
  ``robokudo query`` points the camera). A consumer slower than the camera gets the newest frame; frames it missed
  are skipped, as with a real sensor.
* :class:`PlaybackStream` plays a recorded source (:func:`recorded_stream`: anything ``--input`` reads, or a ROS
  bag) frame after frame, never skipping one: at the recorded rate (from the frames' time stamps where the layout
  has them: TUM sequences, TIFF grabber folders, bags) or at ``rate_hz``; ``loop`` starts over at the end, else
  the stream ends and every later request raises :class:`SourceEndedError`.

:meth:`FrameStream.next_frame` blocks until the next frame is due (or returns None at once with ``block=False``);
:meth:`FrameStream.close` wakes a blocked caller, which then gets SourceEndedError. :class:`StreamReader` is the reader
annotator over a stream: each run writes the stream's next frame into the CAS, and fails with the reason when the
source ended (``StreamReader.ended``) or a frame cannot be read. A server builds its perceive node from
:func:`stream_for` (``--input``, ``--rate``, loop or once) and turns SourceEndedError into "source ended" aborts.
Streams are thread-safe: a view change or close may come from another thread than the reading one.
"""

from __future__ import annotations

import math
import threading
import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import ClassVar, Self

from py_trees.common import Status

from annotators.readers.bag_io import ANY_TOPICS, BagTopics, bag_frames, is_bag
from annotators.readers.choice import recorded_frames
from annotators.readers.frame_io import Frame, FrameError, frame_camera
from annotators.readers.frame_readers import DEFAULT_KITCHEN_VIEW, KITCHEN_RECORDING, FileFrameReader
from annotators.simulation import kitchen_scene
from annotators.simulation.kitchen_person import PERSON_VIEWS, PersonPose, PersonScript, person_view
from annotators.simulation.kitchen_scene import SceneObject
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.pipeline import StructureError
from robokudo.core.types import CameraInfo, CasType, ColorImage, DepthImage

PERCEPTION_PIPELINE = "perception"
"""The name of a served root's perceive pipeline (the paper's Fig. 4): its CAS holds the frame read this run, which
:class:`PerceivedFrameReader` hands to the task's pipeline."""

DEFAULT_RATE_HZ = 30.0
"""The kitchen camera's rate, and the playback rate of recordings without time stamps unless one is given."""
MAX_RECORDED_GAP_S = 5.0
"""A time-stamp gap above this (or not positive) is not a sensor period: such a step is played at the default rate."""
MAX_LAG_S = 1.0
"""A playback consumer more than this behind the schedule gets frames at once and the schedule restarts from now."""


class SourceEndedError(Exception):
    """The stream has no more frames: a recording played once reached its end, or the stream was closed."""


@dataclass(frozen=True, eq=False)
class StreamFrame:
    """A frame delivered by a stream: the frame, its camera info, its position in the source and in the stream."""

    frame: Frame
    camera: CameraInfo
    index: int
    """The frame's position in its source (the sensor's frame count for a live camera)."""
    sequence: int
    """How many frames the stream delivered before this one."""


class FrameStream(ABC):
    """Frames one after another at the source's pace (see the module docstring)."""

    def __init__(self, name: str) -> None:
        self.name = name
        self._lock = threading.Lock()
        self._reading = threading.Lock()
        self._closed = threading.Event()
        self._delivered = 0

    def next_frame(self, block: bool = True) -> StreamFrame | None:
        """The next frame, waiting until it is due; None when ``block`` is False and none is due yet.

        Raises SourceEndedError when the source has no more frames (or the stream was closed), FrameError when the frame
        cannot be read. Callers on several threads take turns.
        """
        with self._reading:
            self._check_open()
            return self._next(block)

    @abstractmethod
    def _next(self, block: bool) -> StreamFrame | None:
        """:meth:`next_frame` for one caller at a time."""

    @property
    def delivered(self) -> int:
        """How many frames the stream has delivered."""
        return self._delivered

    def close(self) -> None:
        """Stop the stream; a caller waiting in :meth:`next_frame` wakes up with SourceEndedError."""
        self._closed.set()

    @property
    def closed(self) -> bool:
        """True once :meth:`close` was called."""
        return self._closed.is_set()

    def _wait_until(self, due: float) -> None:
        """Sleep until monotonic time ``due``; SourceEndedError when the stream is closed meanwhile."""
        while not self._closed.is_set():
            delay = due - time.monotonic()
            if delay <= 0:
                return
            self._closed.wait(delay)
        raise SourceEndedError(f"{self.name}: the stream was closed")

    def _check_open(self) -> None:
        if self._closed.is_set():
            raise SourceEndedError(f"{self.name}: the stream was closed")

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None
    ) -> None:
        self.close()


def _check_rate(rate_hz: float) -> float:
    if not math.isfinite(rate_hz) or rate_hz <= 0:
        raise ValueError(f"the stream rate must be a positive number of frames per second, got {rate_hz}")
    return float(rate_hz)


CLOCKS: tuple[str, ...] = ("wall", "frames")
"""How a simulated camera's scene advances: with the wall clock (a slow consumer misses frames and sees the scene
jump), or one camera period per delivered frame (the world waits for a slow consumer; frame time stamps are
world time)."""

KEPT_RECORDING_BYTES = 256 * 2**20
"""A looping recording whose decoded frames take at most this many bytes is decoded once and replayed from
memory (a single frame played as a sequence is not decoded again every run)."""

MAX_REMEMBERED_POSES = 1000
"""How many delivered frames' person poses a scripted kitchen stream keeps for :meth:`pose_at_stamp`."""


class KitchenCameraStream(FrameStream):
    """The built-in kitchen as a simulated camera producing a frame every ``1 / rate_hz`` seconds.

    Each view is rendered once (``seed`` seeds its sensor noise) and delivered with a fresh time stamp; the view
    can be changed while the stream runs (:meth:`set_view`, :meth:`look_at`).

    With a ``person`` script (:class:`~annotators.simulation.kitchen_person.PersonScript`) the kitchen holds the
    scripted figure: every frame is rendered anew with the figure posed at the script's time (seconds since the
    stream was made or :meth:`restart_script`), the views of ``PERSON_VIEWS`` (``person``, ``room``) can be chosen
    too, and :meth:`pose_at_stamp` gives the ground-truth pose of a delivered frame (for scoring only). ``extra``
    adds objects to the scene (a storage layout's ``extra()``). Without either, nothing changes. The script's time
    is the wall clock, or with ``clock="frames"`` one camera period per delivered frame (:data:`CLOCKS`).

    The scene can change while the stream runs: :meth:`stage` sets up a new scene (script, added objects),
    :meth:`play` starts another script, and the events :meth:`grasp` (an object is taken away) and :meth:`place`
    (an object is put down) change what the next frames show. :meth:`ground_truth` is the scene as it is now.
    """

    def __init__(
        self,
        rate_hz: float = DEFAULT_RATE_HZ,
        view: str = DEFAULT_KITCHEN_VIEW,
        seed: int = 0,
        person: PersonScript | None = None,
        extra: tuple[tuple[SceneObject, tuple[int, int, int]], ...] = (),
        clock: str = "wall",
    ) -> None:
        super().__init__(name="kitchen camera")
        self.rate_hz = _check_rate(rate_hz)
        if clock not in CLOCKS:
            raise ValueError(f"unknown clock {clock!r}; known: {', '.join(CLOCKS)}")
        self.clock = clock
        """``wall``: the scene's time is the wall clock; ``frames``: it advances one camera period per frame."""
        self._world = 0.0
        self._epoch = time.time()
        self.seed = seed
        self.person = person
        self.extra = tuple(extra)
        self.hidden: frozenset[str] = frozenset()
        """Kitchen objects taken out of the scene (grasped)."""
        self._view = self._checked_view(view)
        self._rendered: dict[str, kitchen_scene.RenderedScene] = {}
        self._start = time.monotonic()
        self._script_start = self._start
        self._poses: dict[float, PersonPose] = {}
        self._last_slot = -1
        self._last_view: str | None = None
        self._delivered_pose: PersonPose | None = None

    def _now(self) -> float:
        """The scene's time now (monotonic seconds; with the frames clock, the next frame's world time)."""
        return time.monotonic() if self.clock == "wall" else self._start + self._world

    @property
    def live(self) -> bool:
        """True when frames are rendered anew (a scripted person, added or taken objects)."""
        return self.person is not None or bool(self.extra) or bool(self.hidden)

    def stage(
        self,
        person: PersonScript | None = None,
        extra: tuple[tuple[SceneObject, tuple[int, int, int]], ...] = (),
    ) -> None:
        """Set the scene up anew from the next frame on: the kitchen's own objects all back in place, ``extra``
        added, and ``person``'s script played from its start (None: nobody)."""
        extra = tuple(extra)
        taken = [o.name for o in kitchen_scene.kitchen_objects()] + [o.name for o, _ in extra]
        if len(set(taken)) < len(taken):
            clashing = sorted({n for n in taken if taken.count(n) > 1})
            raise ValueError(f"added objects need names of their own, not {clashing}")
        with self._lock:
            self.person, self.extra, self.hidden = person, extra, frozenset()
            self._script_start = self._now()
            self._poses.clear()

    def play(self, person: PersonScript) -> None:
        """Play ``person``'s script from its start with the next frame (the person's next motions)."""
        with self._lock:
            self.person = person
            self._script_start = self._now()

    def grasp(self, name: str) -> SceneObject:
        """A grasp event: the object called ``name`` (a kitchen object or an added one) is gone from the next frame
        on; the object as it stood. ValueError when no such object is in the scene."""
        with self._lock:
            for index, (obj, _) in enumerate(self.extra):
                if obj.name == name:
                    self.extra = self.extra[:index] + self.extra[index + 1 :]
                    return obj
            present = {o.name: o for o in kitchen_scene.kitchen_objects() if o.name not in self.hidden}
            if name not in present:
                names = sorted(present) + [o.name for o, _ in self.extra]
                raise ValueError(f"no object {name!r} in the scene to grasp; there are: {', '.join(names)}")
            self.hidden = self.hidden | {name}
            return present[name]

    def place(self, obj: SceneObject, albedo: tuple[int, int, int]) -> None:
        """A place event: ``obj`` (rendered with ``albedo``) stands in the scene from the next frame on. A grasped
        kitchen object may be put down under its own name; ValueError when an object of that name or id is there."""
        with self._lock:
            present = [o for o in kitchen_scene.kitchen_objects() if o.name not in self.hidden]
            present += [o for o, _ in self.extra]
            if any(o.name == obj.name or o.object_id == obj.object_id for o in present):
                raise ValueError(f"an object called {obj.name!r} or with id {obj.object_id} is in the scene already")
            self.extra = (*self.extra, (obj, albedo))

    def ground_truth(self) -> tuple[SceneObject, ...]:
        """The objects in the scene now (kitchen objects not taken, then the added ones); for scoring only."""
        with self._lock:
            kept = tuple(o for o in kitchen_scene.kitchen_objects() if o.name not in self.hidden)
            return kept + tuple(o for o, _ in self.extra)

    def _checked_view(self, view: str) -> str:
        views = list(kitchen_scene.camera_views())
        if self.person is not None:
            views += list(PERSON_VIEWS)
        if view not in views:
            raise ValueError(f"unknown kitchen camera view {view!r}; known: {', '.join(views)}")
        return view

    def restart_script(self) -> None:
        """Play the person's script from its start with the next frame."""
        with self._lock:
            self._script_start = self._now()
            self._poses.clear()

    def script_time(self) -> float:
        """Seconds since the person's script started."""
        with self._lock:
            return self._now() - self._script_start

    def pose_at_stamp(self, timestamp: float) -> PersonPose | None:
        """The person's pose in the frame stamped ``timestamp`` (None when no such frame was delivered)."""
        with self._lock:
            return self._poses.get(timestamp)

    @property
    def view(self) -> str:
        """The camera view frames are rendered from."""
        with self._lock:
            return self._view

    def set_view(self, view: str) -> None:
        """Render the next frames from the named view (ValueError for an unknown one)."""
        checked = self._checked_view(view)
        with self._lock:
            self._view = checked

    def look_at(self, region: str) -> str:
        """Point the camera at ``region`` (as ``robokudo query`` does); the chosen view. ValueError when no view
        looks at it."""
        view = kitchen_scene.camera_looking_at(region)
        self.set_view(view)
        return view

    def prepare(self) -> None:
        """Render every view now, so that pointing the camera later costs no rendering on the reading thread."""
        for view in kitchen_scene.camera_views():
            self._scene(view)

    def _scene(self, view: str) -> kitchen_scene.RenderedScene:
        if self.live:
            return self._live_scene(view)
        with self._lock:
            scene = self._rendered.get(view)
        if scene is None:
            scene = kitchen_scene.render_kitchen(view, seed=self.seed)
            with self._lock:
                scene = self._rendered.setdefault(view, scene)
        return scene

    def _live_scene(self, view: str) -> kitchen_scene.RenderedScene:
        with self._lock:
            person, extra, hidden = self.person, self.extra, self.hidden
            elapsed = self._now() - self._script_start
        pose = None if person is None else person.pose_at(elapsed)
        where = person_view(view) if view in PERSON_VIEWS else view
        self._delivered_pose = pose
        scene = kitchen_scene.render_kitchen(where, seed=self.seed, person=pose, extra=extra, hidden=hidden)
        with self._lock:
            self._rendered[view] = scene
        return scene

    @property
    def last_scene(self) -> kitchen_scene.RenderedScene | None:
        """The scene (with its ground truth) of the current view, None before it was first rendered."""
        with self._lock:
            return self._rendered.get(self._view)

    def _next(self, block: bool) -> StreamFrame | None:
        """The camera's newest frame after the last one delivered (frames a slow caller missed are skipped); after
        the view changed, a frame from the new view at once."""
        period = 1.0 / self.rate_hz
        slot = math.floor((time.monotonic() - self._start) / period)
        view = self.view
        if slot <= self._last_slot and view == self._last_view:
            if not block:
                return None
            slot = self._last_slot + 1
            self._wait_until(self._start + slot * period)
        slot = max(slot, self._last_slot + 1)
        scene = self._scene(view)
        camera = CameraInfo(
            intrinsics=scene.intrinsics,
            cam_to_world=scene.cam_to_world,
            frame_id=f"kitchen/{view}",
            timestamp=time.time() if self.clock == "wall" else self._epoch + self._world,
            recording=KITCHEN_RECORDING,
        )
        frame = Frame(scene.color, scene.depth, scene.intrinsics, source=f"kitchen/{view}", timestamp=camera.timestamp)
        if self.person is not None and self._delivered_pose is not None:
            with self._lock:
                self._poses[camera.timestamp] = self._delivered_pose
                while len(self._poses) > MAX_REMEMBERED_POSES:
                    del self._poses[next(iter(self._poses))]
        self._last_slot = slot
        self._last_view = view
        if self.clock == "frames":
            with self._lock:
                self._world += period
        delivered = StreamFrame(frame, camera, index=slot, sequence=self._delivered)
        self._delivered += 1
        return delivered


RecordedFrames = Callable[[], Iterator[tuple[Frame, str]]]
"""Opens a recording from its start: an iterator of its frames in order, each with the recording it belongs to."""


class PlaybackStream(FrameStream):
    """Plays a recording frame after frame (see the module docstring); ``rate_hz`` None plays at the recorded rate.
    When looping, a recording whose decoded frames fit in ``keep_bytes`` is replayed from memory after its first
    play (the frames are read-only for the consumers)."""

    def __init__(
        self,
        frames: RecordedFrames,
        name: str,
        rate_hz: float | None = None,
        loop: bool = True,
        keep_bytes: int = KEPT_RECORDING_BYTES,
    ) -> None:
        super().__init__(name=name)
        self.keep_bytes = keep_bytes
        self._kept: list[tuple[Frame, str]] | None = [] if loop and keep_bytes > 0 else None
        self._kept_bytes = 0
        self._replay: tuple[tuple[Frame, str], ...] | None = None
        self.rate_hz = None if rate_hz is None else _check_rate(rate_hz)
        self.loop = loop
        self._open = frames
        self._frames: Iterator[tuple[Frame, str]] | None = None
        self._pending: tuple[Frame, str, int] | None = None
        self._previous_stamp: float | None = None
        self._due: float | None = None
        self._index = 0
        self._error: Exception | None = None
        self._ended: str | None = None
        self.loops = 0
        """How many times the recording started over."""

    @property
    def ended(self) -> bool:
        """True once a recording played once delivered its last frame."""
        return self._ended is not None

    def _gap(self, stamp: float | None) -> float:
        if self.rate_hz is not None:
            return 1.0 / self.rate_hz
        previous = self._previous_stamp
        if stamp is not None and previous is not None and 0 < stamp - previous <= MAX_RECORDED_GAP_S:
            return stamp - previous
        return 1.0 / DEFAULT_RATE_HZ

    def _advance(self) -> tuple[Frame, str, int]:
        """The next frame of the recording (starting over when looping); SourceEndedError after a single play."""
        for attempt in range(2):
            if self._frames is None:
                self._frames = iter(self._replay) if self._replay is not None else self._open()
            try:
                frame, recording = next(self._frames)
            except StopIteration:
                self._frames = None
                if self._kept is not None and self._index > 0:  # the whole first play fitted: replay it from now on
                    self._replay, self._kept = tuple(self._kept), None
                if self._index == 0:
                    raise SourceEndedError(f"{self.name}: the recording holds no frame") from None
                if not self.loop or attempt == 1:
                    self._ended = f"{self.name}: all {self._index} frames played"
                    raise SourceEndedError(self._ended) from None
                self.loops += 1
                self._index = 0
                self._previous_stamp = None
                continue
            self._index += 1
            self._keep(frame, recording)
            return frame, recording, self._index - 1
        raise SourceEndedError(f"{self.name}: the recording holds no frame")

    def _keep(self, frame: Frame, recording: str) -> None:
        """Keep a frame of the first play while the recording fits in ``keep_bytes``."""
        if self._kept is None:
            return
        arrays = (frame.color, frame.depth, frame.points, frame.labels)
        self._kept_bytes += sum(a.nbytes for a in arrays if a is not None)
        if self._kept_bytes > self.keep_bytes:
            self._kept = None  # too long: decoded again on every play
        else:
            self._kept.append((frame, recording))

    def _next(self, block: bool) -> StreamFrame | None:
        """The recording's next frame once it is due (frames are never skipped)."""
        if self._ended is not None:
            raise SourceEndedError(self._ended)
        if self._error is not None:
            raise self._error
        if self._pending is None:
            try:
                self._pending = self._advance()
            except FrameError as error:
                self._error = error
                raise
            stamp = self._pending[0].timestamp
            now = time.monotonic()
            self._due = now if self._due is None else max(self._due + self._gap(stamp), now - MAX_LAG_S)
            self._previous_stamp = stamp
        assert self._due is not None
        if not block and time.monotonic() < self._due:
            return None
        self._wait_until(self._due)
        frame, recording, index = self._pending
        self._pending = None
        delivered = StreamFrame(frame, frame_camera(frame, recording), index=index, sequence=self._delivered)
        self._delivered += 1
        return delivered


def _folder_frames(path: str) -> RecordedFrames:
    choices = recorded_frames(path)

    def frames() -> Iterator[tuple[Frame, str]]:
        for choice in choices:
            reader = choice.create()
            assert isinstance(reader, FileFrameReader)
            yield reader.load(), reader.recording()

    return frames


def _bag_frames(path: Path, topics: BagTopics) -> RecordedFrames:
    recording = str(path.resolve())

    def frames() -> Iterator[tuple[Frame, str]]:
        for frame in bag_frames(path, topics):
            yield frame, recording

    return frames


def recorded_stream(
    path: str, rate_hz: float | None = None, loop: bool = True, topics: BagTopics = ANY_TOPICS
) -> PlaybackStream:
    """A playback stream of the recording at ``path``: any layout ``--input`` reads, or a ROS 1 / ROS 2 bag
    (``topics`` names the bag's topics; unnamed ones are picked by type). ValueError for a path of no known
    layout."""
    if rate_hz is not None:
        _check_rate(rate_hz)
    resolved = Path(path).expanduser()
    if is_bag(resolved):
        return PlaybackStream(_bag_frames(resolved, topics), name=str(resolved), rate_hz=rate_hz, loop=loop)
    return PlaybackStream(_folder_frames(path), name=str(resolved), rate_hz=rate_hz, loop=loop)


def stream_for(
    path: str | None,
    rate_hz: float | None = None,
    loop: bool = True,
    view: str = DEFAULT_KITCHEN_VIEW,
    topics: BagTopics = ANY_TOPICS,
) -> FrameStream:
    """The stream of ``--input``: the kitchen camera (at ``rate_hz`` or the default, from ``view``) for None, else
    :func:`recorded_stream`."""
    if path is None:
        return KitchenCameraStream(rate_hz if rate_hz is not None else DEFAULT_RATE_HZ, view=view)
    return recorded_stream(path, rate_hz, loop, topics)


class StreamReader(Annotator):
    """Writes the stream's next frame (colour, depth, camera info) each time it runs; never the same frame twice.

    ``wait`` True blocks the tick until the next frame is due. ``wait`` False never blocks: while no new frame is
    due the reader stays RUNNING (feedback "waiting for the next frame"), so the engine keeps its tick rate and the
    rest of the tree runs once per new frame. Fails with the reason when the source ended (then :attr:`ended` is
    True) or a frame cannot be read.
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = ()
    outputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage, DepthImage, CameraInfo)
    capability: ClassVar[Capability] = Capability(
        label="stream reader",
        description="Reads the next frame of a live source (the kitchen camera, a recording or a bag played back).",
        cost_ms=5.0,
        reliability=1.0,
    )

    WAITING = "waiting for the next frame"

    def __init__(self, stream: FrameStream, wait: bool = True, name: str | None = None) -> None:
        super().__init__(name=name)
        self.stream = stream
        self.wait = wait
        self.ended = False
        self._last: StreamFrame | None = None
        self._due: StreamFrame | None = None
        self._problem: Exception | None = None

    @property
    def last_frame(self) -> StreamFrame | None:
        """The frame written by the last successful run, None before it."""
        return self._last

    def update(self) -> Status:
        """Without waiting: RUNNING until a new frame is due, then write it (see the class)."""
        if not self.wait:
            try:
                self._due = self.stream.next_frame(block=False)
            except (SourceEndedError, FrameError, OSError, ValueError) as error:
                self._problem = error  # analyse reports it as the run's failure
            if self._due is None and self._problem is None:
                self.feedback_message = self.WAITING
                return Status.RUNNING
        return super().update()

    def analyse(self) -> None:
        """Take the next frame and write it."""
        due, problem = self._due, self._problem
        self._due = self._problem = None
        try:
            if problem is not None:
                raise problem
            delivered = due if due is not None else self.stream.next_frame(block=True)
        except SourceEndedError as error:
            self.ended = True
            self.fail(f"source ended: {error}")
        except FrameError as error:
            self.fail(f"cannot read the next frame of {self.stream.name}: {error}")
        except (OSError, ValueError) as error:
            self.fail(f"cannot read the next frame of {self.stream.name}: {type(error).__name__}: {error}")
        assert delivered is not None
        self._last = delivered
        self.write(ColorImage(delivered.frame.color))
        self.write(DepthImage(delivered.frame.depth))
        self.write(delivered.camera)


class PerceivedFrameReader(Annotator):
    """The first step of a task in a served tree: takes the frame the root's perceive pipeline read this run.

    The views are shared by reference (no copy). Fails with the reason when the tree has no such pipeline or it
    holds no frame. Run again (a continuous task's loop), it stays RUNNING while the pipeline still holds the frame
    it took last, so no frame is analysed twice.
    """

    WAITING = "waiting for a newly perceived frame"

    inputs: ClassVar[tuple[type[CasType], ...]] = ()
    outputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage, DepthImage, CameraInfo)
    capability: ClassVar[Capability] = Capability(
        label="perceived frame",
        description="Takes the frame the running engine perceived this run (colour, depth, camera info).",
        cost_ms=0.1,
        reliability=1.0,
    )

    def __init__(self, pipeline: str = PERCEPTION_PIPELINE, name: str | None = None) -> None:
        super().__init__(name=name)
        self.pipeline = pipeline
        self._taken: CameraInfo | None = None

    def update(self) -> Status:
        """RUNNING while the perceive pipeline holds the frame taken last; else take it (see the class)."""
        if self._taken is not None:
            try:
                current = self.cas_of(self.pipeline).view(CameraInfo)
            except StructureError:
                current = None
            if current is self._taken:
                self.feedback_message = self.WAITING
                return Status.RUNNING
        return super().update()

    def analyse(self) -> None:
        """Write the perceived colour, depth and camera info into this task's CAS."""
        try:
            perceived = self.cas_of(self.pipeline)
        except StructureError as error:
            self.fail(str(error))
        views = (perceived.view(ColorImage), perceived.view(DepthImage), perceived.view(CameraInfo))
        if any(view is None for view in views):
            self.fail(f"no frame was perceived: the {self.pipeline!r} pipeline holds none")
        for view in views:
            assert view is not None
            self.write(view)
        self._taken = views[2]
