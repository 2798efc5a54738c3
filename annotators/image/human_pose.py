"""Human pose: people with 2-D and 3-D body keypoints, from mediapipe's pose landmark model.

The model is mediapipe 0.10.21's legacy pose solution (complexity 1; the model files ship in its wheel, nothing
is fetched). It finds one person per image, so with a point cloud it runs on a crop around every person that
the depth people detector (:func:`annotators.cloud.people.find_people`) finds, and reads each keypoint's 3-D
point from the organized cloud (the median of the person's points in a small window around the pixel); without
a cloud it runs once on the whole image and reports 2-D keypoints only; when the cloud shows no ground to stand
on (a close view of a person's upper body) it runs on the whole image. A person's points are those connected in
depth to its shoulders and head (:mod:`annotators.people.body_points`) that lie within ``body_reach`` of its
skeleton's bones (what touches the person in depth, e.g. a door at the pointing hand, is cut off), and its Pose
is their centroid, the person's 3-D position as robokudo defines it. With a cloud, a skeleton counts only when
at least ``min_on_person`` of its keypoints fall on the candidate's points (the model, given a crop without a
person, may still draw one on whatever is there).

mediapipe's option setter reads ``FieldDescriptor.label``, which protobuf 6 removed, so the detector passes no
score thresholds (the graph's are cleared) and keeps a person only when its torso landmarks are visible.
"""

from __future__ import annotations

import contextlib
import io
import sys
import weakref
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from annotators.cloud.people import IMAGE_UP, PeopleParameters, PersonSegment, find_people, ground_plane
from annotators.cloud.plane import plane_distances, up_in_camera
from annotators.people.body_points import body_mask, centroid, support_surfaces
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.resources import Guarded
from robokudo.core.types import (
    PERSON_CLASS,
    BodyKeypoints,
    CameraInfo,
    CasType,
    Classification,
    ColorImage,
    PersonHypothesis,
    PointCloud,
    Pose,
)

LANDMARKS: tuple[str, ...] = (
    "nose", "left_eye_inner", "left_eye", "left_eye_outer", "right_eye_inner", "right_eye", "right_eye_outer",
    "left_ear", "right_ear", "mouth_left", "mouth_right", "left_shoulder", "right_shoulder", "left_elbow",
    "right_elbow", "left_wrist", "right_wrist", "left_pinky", "right_pinky", "left_index", "right_index",
    "left_thumb", "right_thumb", "left_hip", "right_hip", "left_knee", "right_knee", "left_ankle", "right_ankle",
    "left_heel", "right_heel", "left_foot_index", "right_foot_index",
)  # fmt: skip
"""mediapipe's 33 pose landmarks, in its order."""

TORSO: tuple[int, ...] = tuple(LANDMARKS.index(n) for n in ("left_shoulder", "right_shoulder", "left_hip", "right_hip"))
"""The landmarks that must be visible for a crop to count as a person."""


class PoseModelError(RuntimeError):
    """The pose model cannot be loaded (mediapipe missing or broken)."""


def load_pose_model(video: bool = False) -> Any:
    """mediapipe's legacy pose solution (complexity 1); raises PoseModelError. For single images by default; with
    ``video`` for consecutive images of one person: it finds the person once and then runs only the landmark
    model on the region its previous landmarks give (a third of the time)."""
    try:
        with contextlib.redirect_stderr(io.StringIO()) as said:  # its protobuf bindings' harmless complaint
            import mediapipe as mp
        _pass_on(said.getvalue())
        return mp.solutions.pose.Pose(
            static_image_mode=not video,
            model_complexity=1,
            smooth_landmarks=False,  # smoothing lags behind a walking person; the trackers filter over time
            min_detection_confidence=None,
            min_tracking_confidence=None,
        )
    except Exception as error:  # ImportError, or mediapipe's own errors when its graph cannot start
        raise PoseModelError(f"the mediapipe pose model cannot be loaded: {error}") from None


BINDINGS_NOISE = "'MessageFactory' object has no attribute 'GetPrototype'"
"""What mediapipe's protobuf bindings print on import with protobuf >= 5 (harmless: the pose solution runs)."""


def _pass_on(printed: str) -> None:
    """Write what importing mediapipe printed to stderr, but for the bindings' harmless line, which users read as
    a crash."""
    kept = [line for line in printed.splitlines(keepends=True) if BINDINGS_NOISE not in line]
    sys.stderr.write("".join(kept))


def detect_landmarks(model: Any, image: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The one person's landmarks in an RGB uint8 image: pixels (33x2) and visibility (33), or None."""
    result = model.process(np.ascontiguousarray(image))
    if result.pose_landmarks is None:
        return None
    marks = result.pose_landmarks.landmark
    height, width = image.shape[:2]
    pixels = np.array([(m.x * width, m.y * height) for m in marks], dtype=np.float64)
    visibility = np.array([m.visibility for m in marks], dtype=np.float64)
    return pixels, visibility


def crop_box(roi: tuple[int, int, int, int], shape: tuple[int, int], margin: float) -> tuple[int, int, int, int]:
    """The ROI grown by ``margin`` of its height on every side and clipped to the image (x1/y1 exclusive)."""
    x0, y0, x1, y1 = roi
    pad = round(margin * (y1 - y0))
    return max(0, x0 - pad), max(0, y0 - pad), min(shape[1], x1 + pad), min(shape[0], y1 + pad)


def keypoint_points(pixels: np.ndarray, points: np.ndarray, member: np.ndarray | None, window: int = 4) -> np.ndarray:
    """The 3-D point of each keypoint: the median of the valid cloud points (of ``member`` pixels when given)
    within ``window`` pixels of it; NaN where there are none."""
    rows, cols = points.shape[:2]
    count = pixels.shape[0]
    usable = np.isfinite(pixels).all(axis=1)
    centres = np.zeros((count, 2), dtype=np.int64)
    centres[usable] = np.round(pixels[usable]).astype(np.int64)  # (column, row) of each keypoint
    offsets = np.arange(-window, window + 1)
    r = centres[:, 1, None, None] + offsets[None, :, None]  # keypoint x row offset x 1
    c = centres[:, 0, None, None] + offsets[None, None, :]  # keypoint x 1 x column offset
    inside = usable[:, None, None] & (r >= 0) & (r < rows) & (c >= 0) & (c < cols)
    r, c = np.clip(r, 0, rows - 1), np.clip(c, 0, cols - 1)
    patches = points[r, c].astype(np.float64)  # keypoint x window x window x 3
    keep = inside & np.isfinite(patches[..., 2])
    if member is not None:
        keep &= member[r, c]
    patches[~keep] = np.nan
    return _median_of_valid(patches.reshape(count, -1, 3), keep.reshape(count, -1).sum(axis=1))


def _median_of_valid(values: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """Per row of ``values`` (rows x samples x 3, NaN where not valid), the median of its ``valid`` (per row)
    samples per coordinate; NaN for a row without any."""
    ordered = np.sort(values, axis=1)  # NaN sorts last
    low = np.clip((valid - 1) // 2, 0, None)[:, None, None]
    high = np.clip(valid // 2, 0, None)[:, None, None]
    low_values = np.take_along_axis(ordered, np.broadcast_to(low, (values.shape[0], 1, 3)), axis=1)[:, 0]
    high_values = np.take_along_axis(ordered, np.broadcast_to(high, (values.shape[0], 1, 3)), axis=1)[:, 0]
    median = (low_values + high_values) / 2.0
    median[valid == 0] = np.nan
    return median


BONES: tuple[tuple[str, str], ...] = (
    ("left_shoulder", "right_shoulder"), ("left_hip", "right_hip"), ("left_shoulder", "left_hip"),
    ("right_shoulder", "right_hip"), ("left_shoulder", "left_elbow"), ("left_elbow", "left_wrist"),
    ("right_shoulder", "right_elbow"), ("right_elbow", "right_wrist"), ("left_hip", "left_knee"),
    ("left_knee", "left_ankle"), ("right_hip", "right_knee"), ("right_knee", "right_ankle"), ("nose", "nose"),
)  # fmt: skip
"""The skeleton's bones (pairs of landmarks); the nose stands for the head."""


ARM_JOINTS: frozenset[str] = frozenset(
    f"{side}_{joint}" for side in ("left", "right") for joint in ("elbow", "wrist", "pinky", "index", "thumb")
)


def _unoccluded(keypoints: np.ndarray, body_depth: float = 0.3, arm_reach: float = 0.8) -> np.ndarray:
    """The keypoints without those whose depth says they lie on something in front of the body (an object that
    hides the hips): farther than ``body_depth`` in depth from the shoulders (``arm_reach`` for arm joints)."""
    shoulders = keypoints[[LANDMARKS.index("left_shoulder"), LANDMARKS.index("right_shoulder")], 2]
    if not np.isfinite(shoulders).any():
        return keypoints
    reference = float(np.nanmedian(shoulders))
    limits = np.array([arm_reach if name in ARM_JOINTS else body_depth for name in LANDMARKS])
    kept = keypoints.copy()
    with np.errstate(invalid="ignore"):
        kept[np.abs(keypoints[:, 2] - reference) > limits] = np.nan
    return kept


def near_skeleton(points: np.ndarray, keypoints: np.ndarray, reach: float) -> np.ndarray | None:
    """Which of the Nx3 ``points`` lie within ``reach`` of a bone between keypoints with depth (33x3); the torso
    (between the shoulders and the hips) counts too. None when no bone has depth at both ends."""
    keypoints = _unoccluded(keypoints).astype(np.float32)  # centimetres matter, not more: single precision
    cloud = np.asarray(points, dtype=np.float32)
    near = np.zeros(cloud.shape[0], dtype=bool)
    open_ = np.flatnonzero(np.isfinite(cloud[:, 2]))  # the valid points not found near yet (each bone tests only these)
    corners = keypoints[list(TORSO)]
    if np.all(np.isfinite(corners)):  # the torso first: it holds most of a person's points
        centre = corners.mean(axis=0)
        radius = float(np.max(np.linalg.norm(corners - centre, axis=1)))
        offset = cloud[open_] - centre
        inside = np.einsum("ij,ij->i", offset, offset) < radius * radius
        near[open_[inside]] = True
        open_ = open_[~inside]
    used = 0
    for first, second in BONES:
        a, b = keypoints[LANDMARKS.index(first)], keypoints[LANDMARKS.index(second)]
        if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
            continue
        used += 1
        if open_.size == 0:
            continue
        ab = b - a
        length = float(ab @ ab)
        offset = cloud[open_] - a
        t = np.zeros(open_.size, np.float32) if length < 1e-12 else np.clip(offset @ ab / np.float32(length), 0, 1)
        offset -= t[:, None] * ab
        limit = reach + (first == "nose") * 0.05
        inside = np.einsum("ij,ij->i", offset, offset) < limit * limit
        near[open_[inside]] = True
        open_ = open_[~inside]
    return near if used else None


@dataclass
class _Followed:
    """A person seen in the previous frame of a sequence: its image box and where it is (its video-mode model is
    the detector's model of the same number)."""

    roi: tuple[int, int, int, int]
    mask: np.ndarray
    """Its pixels in the previous frame (HxW): blanked out of the crops the other followed people are looked for
    in, so that the model, which sees one person per crop, does not draw this one there."""
    position: np.ndarray | None = None
    """Where the person was (camera frame), the centre of the column its points are looked for in."""
    standing: bool = False
    """Whether the search found the person standing on the ground (a depth candidate), not in the whole image."""
    velocity: np.ndarray | None = None
    """How fast (m/s, camera frame) the person moved between the last two frames it was followed in."""
    box_velocity: np.ndarray | None = None
    """How fast (pixels/s) its box's centre moved then."""

    def predicted(self, gap: float, shape: tuple[int, int]) -> tuple[tuple[int, int, int, int], np.ndarray | None]:
        """Where the person is expected ``gap`` seconds later: its box shifted as it moved, and its position."""
        if self.box_velocity is None or gap <= 0:
            return self.roi, self.position
        du, dv = np.round(self.box_velocity * gap).astype(int)
        x0, y0, x1, y1 = self.roi
        du = int(np.clip(du, -x0, shape[1] - x1))  # the box stays in the image
        dv = int(np.clip(dv, -y0, shape[0] - y1))
        position = self.position
        if position is not None and self.velocity is not None:
            position = position + self.velocity * gap
        return (x0 + du, y0 + dv, x1 + du, y1 + dv), position

    def moved(self, person: PersonHypothesis, gap: float, top_speed: float) -> None:
        """Remember where it was found now (``gap`` seconds after the previous frame); the velocities are the mean
        of the last two steps' (one step's noise does not carry a standing person off), a 3-D speed over
        ``top_speed`` (a jump of the detection, not a walk) stopping the prediction."""
        roi, position = person.roi, _position(person)
        velocity = box_velocity = None
        if gap > 0:
            known = position is not None and self.position is not None
            velocity = (position - self.position) / gap if known else None  # type: ignore[operator]
            box_velocity = (_box_centre(roi) - _box_centre(self.roi)) / gap
            if velocity is not None and float(np.linalg.norm(velocity)) > top_speed:
                velocity = box_velocity = None
        if velocity is not None and self.velocity is not None:
            velocity = (velocity + self.velocity) / 2.0
        if box_velocity is not None and self.box_velocity is not None:
            box_velocity = (box_velocity + self.box_velocity) / 2.0
        self.velocity, self.box_velocity = velocity, box_velocity
        self.roi, self.position, self.mask = roi, position, person.mask


def _box_centre(roi: tuple[int, int, int, int]) -> np.ndarray:
    return np.array([(roi[0] + roi[2]) / 2.0, (roi[1] + roi[3]) / 2.0])


def _close_models(models: list[Guarded[Any]]) -> None:
    """Close mediapipe models (each under its lock) and forget them."""
    for model in models:
        with model.lock:
            model.value.close()
    models.clear()


def _position(person: PersonHypothesis) -> np.ndarray | None:
    pose = person.first(Pose)
    return None if pose is None else np.asarray(pose.position, dtype=np.float64)


class HumanPoseDetector(Annotator):
    """Finds people with 2-D and 3-D body keypoints (mediapipe pose on crops around depth person candidates).

    Run on consecutive frames of one recording (a continuous task's loop), it follows the people it saw: each is
    looked for only in a crop around where it is expected (its previous box moved on as it moved between the
    last two frames, grown by ``follow_margin`` of its height), by a video-mode model of its own that runs just
    the landmark model there; a person the search found standing on the ground has its points looked for as the
    search did, among those above the ground within a column around its expected position (``column_radius``
    plus ``follow_reach`` metres, a step off the prediction; a step faster than ``top_speed`` is not used to
    predict). The full search (the depth candidates, each through the single-image model) runs on the first
    frame, when a followed person is not found again, when the sequence breaks (another recording, time going
    back or a gap over ``max_gap`` seconds) and every ``search_every`` frames, so people who walk in are found.

    With ``follow_target`` (a continuous track of a person: its tracker follows one person) only the target is
    followed between searches (which then run every ``target_search_every`` frames), so a frame costs one model run
    however many people are in view: the target is the most confident person of the first search (the one a
    tracker locks onto) and, after a later search, the person nearest to where the target was expected (the one a
    tracker associates). A search still reports everyone.
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage,)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud, CameraInfo)
    outputs: ClassVar[tuple[type[CasType], ...]] = (PersonHypothesis, BodyKeypoints)
    capability: ClassVar[Capability] = Capability(
        label="human pose detector",
        synonyms=("pose estimator", "body keypoint detector", "skeleton tracker"),
        classes=(PERSON_CLASS,),
        cost_ms=1000.0,
        reliability=0.85,
    )

    def __init__(
        self,
        min_torso_visibility: float = 0.5,
        crop_margin: float = 0.12,
        min_on_person: float = 0.5,
        parameters: PeopleParameters | None = None,
        body_reach: float = 0.15,
        follow_margin: float = 0.2,
        follow_reach: float = 0.2,
        search_every: int = 30,
        max_gap: float = 5.0,
        top_speed: float = 2.5,
        follow_target: bool = False,
        target_search_every: int = 90,
        support_clearance: float = 0.15,
        name: str | None = None,
    ) -> None:
        super().__init__(name=name)
        for label, count in (("search_every", search_every), ("target_search_every", target_search_every)):
            if isinstance(count, bool) or not isinstance(count, int) or count < 1:
                raise ValueError(f"{label} must be a whole number >= 1, not {count!r}")
        numbers = (
            ("follow_margin", follow_margin), ("follow_reach", follow_reach), ("max_gap", max_gap),
            ("top_speed", top_speed), ("support_clearance", support_clearance),
        )  # fmt: skip
        for label, value in numbers:
            if not np.isfinite(value) or value < 0:
                raise ValueError(f"{label} must be a number >= 0, not {value!r}")
        self.body_reach = body_reach
        """How far (m) from its skeleton's bones (or torso) a point counts as the person's."""
        self.min_torso_visibility = min_torso_visibility
        self.crop_margin = crop_margin
        self.min_on_person = min_on_person
        self.parameters = parameters or PeopleParameters()
        self.follow_margin = follow_margin
        self.follow_reach = follow_reach
        self.search_every = search_every
        self.max_gap = max_gap
        """The longest time (s) between two frames of one sequence: more than a search takes on a busy machine (a
        shorter one made every frame after a search a break, so a slow search never led to following); a person
        who moved farther than a step meanwhile is searched for anyway."""
        self.top_speed = top_speed
        """The fastest a person moves (m/s): a faster step between two frames is a jump of the detection, and the
        prediction of where the person is next does not use it."""
        self.support_clearance = support_clearance
        """How far (m) below the shoulders a surface facing up must lie to be a support (a table, the floor) and
        not the person (the top of the shoulders and head face up too)."""
        self.follow_target = bool(follow_target)
        """Whether only the target (see the class) is followed between searches, not everyone seen."""
        self.target_search_every = target_search_every
        """Every how many frames the full search runs while only the target is followed (``search_every`` when
        everyone is): rarer, as people walking in do not matter to a track of one person and a follow that loses
        the target or finds it more than a step away searches at once."""
        self.searches = 0
        """How many frames had the full search (the others followed the people of the previous frame)."""
        self._followed: list[_Followed] = []
        self._video_models: list[Guarded[Any]] = []
        """The video-mode models following people (loaded on the first frame that follows anyone, so a one-shot
        run loads none), closed when the node is shut down or dropped: an unclosed mediapipe graph keeps its
        memory (~100 MB)."""
        self._close_models = weakref.finalize(self, _close_models, self._video_models)
        self._sequence: tuple[str, str, float] | None = None
        self._gap = 0.0
        """Seconds between the previous frame and this one (0 when unknown)."""
        self._since_search = 0
        self._unbroken = False
        """Whether this frame continues the previous one's sequence (the same recording, a gap up to ``max_gap``)."""

    def model(self) -> Guarded[Any]:
        """The pose model, loaded on first use and shared through this annotator's resources."""
        return self.resources.get(("mediapipe-pose", 1), lambda: Guarded(load_pose_model()))

    def analyse(self) -> None:
        """Write a PersonHypothesis with BodyKeypoints per person whose torso the model sees."""
        image = self.view(ColorImage).image
        if image.ndim != 3 or image.shape[2] != 3 or image.dtype != np.uint8 or min(image.shape[:2]) < 16:
            self.fail(f"the colour image is not an RGB uint8 image of at least 16x16 pixels (got {image.shape})")
        try:
            model = self.model()
        except PoseModelError as error:
            self.fail(str(error))
        cloud = self.optional_view(PointCloud)
        points = cloud.points if cloud is not None and cloud.points.shape[:2] == image.shape[:2] else None
        if self._continues(self.optional_view(CameraInfo)) and self._followed:
            people = self._follow(image, points)
            if people is not None:
                self._since_search += 1
                for person in people:
                    self.write(person)
                return
        self._since_search = 0
        self.searches += 1
        people, standing = self._search(model, image, points, cloud)
        self._remember(self._target(people, image.shape[:2]) if self.follow_target else people, standing)
        for person in people:
            self.write(person)

    def _search(
        self, model: Guarded[Any], image: np.ndarray, points: np.ndarray | None, cloud: PointCloud | None
    ) -> tuple[list[PersonHypothesis], bool]:
        """The full search: the pose model on a crop around every depth candidate, else on the whole image; the
        people, and whether they were found standing on the ground (as depth candidates)."""
        whole_image = [((0, 0, image.shape[1], image.shape[0]), None)]
        crops: list[tuple[tuple[int, int, int, int], PersonSegment | None]] = []
        if cloud is not None and points is not None and cloud.mask.any():
            up = up_in_camera(self.optional_view(CameraInfo))
            candidates = find_people(points, cloud.mask, IMAGE_UP if up is None else up, self.parameters)
            crops = [(crop_box(c.roi, image.shape[:2], self.crop_margin), c) for c in candidates]
        people = self._look(model, image, points, crops)
        if people:
            return people, True
        # no cloud, no ground in view (a close view of the upper body) or no candidate was a person
        people = self._look(model, image, points, whole_image)
        if not people:
            self._followed = []
            self.fail(f"the pose model saw no person's torso in {len(crops)} candidate region(s) nor the whole image")
        return people, False

    def _continues(self, info: CameraInfo | None) -> bool:
        """True when this frame follows the previous one of the same sequence and no periodic search is due."""
        key = ("", "", 0.0) if info is None else (info.recording, info.frame_id, float(info.timestamp))
        previous, self._sequence = self._sequence, key
        self._gap = key[2] - previous[2] if previous is not None and key[2] > 0 and previous[2] > 0 else 0.0
        self._unbroken = (
            previous is not None and info is not None and previous[:2] == key[:2] and 0 < self._gap <= self.max_gap
        )
        every = self.target_search_every if self.follow_target else self.search_every
        return self._unbroken and self._since_search + 1 < every

    def _follow(self, image: np.ndarray, points: np.ndarray | None) -> list[PersonHypothesis] | None:
        """Each followed person in a crop around its predicted box (its previous box moved on as it moved between
        the last two frames); None when one of them is not found there. A person's points are looked for above the
        ground (when the cloud shows it), as the search does, around its predicted position."""
        ground = None
        if points is not None and any(f.standing for f in self._followed):
            up = up_in_camera(self.optional_view(CameraInfo))
            ground = ground_plane(points, np.isfinite(points[..., 2]), IMAGE_UP if up is None else up, self.parameters)
        while len(self._video_models) < len(self._followed):
            try:
                self._video_models.append(Guarded(load_pose_model(video=True)))
            except PoseModelError:
                return None  # the search runs with the single-image model instead
        people = []
        for followed, model in zip(self._followed, self._video_models, strict=False):
            roi, expected = followed.predicted(self._gap, image.shape[:2])
            crop = crop_box(roi, image.shape[:2], self.follow_margin)
            allowed = np.zeros(image.shape[:2], dtype=bool)
            x0, y0, x1, y1 = crop
            allowed[y0:y1, x0:x1] = True
            if points is not None and ground is not None and followed.standing:
                allowed[y0:y1, x0:x1] = self._column(points[y0:y1, x0:x1], ground, expected)
            shown = self._without_others(image, crop, followed)
            found = self._look(model, shown, points, [(crop, None)], allowed)
            if len(found) != 1 or not self._near(followed, expected, _position(found[0])):
                return None  # lost, or the model drew a person elsewhere: the search decides
            people.append(found[0])
        for followed, person in zip(self._followed, people, strict=True):
            followed.moved(person, self._gap, self.top_speed)
        return people

    def _without_others(self, image: np.ndarray, crop: tuple[int, int, int, int], followed: _Followed) -> np.ndarray:
        """The image with the other followed people's pixels (of the previous frame, not this one's) painted over
        in ``crop`` with the crop's median colour; the image itself when none of them reaches into the crop."""
        x0, y0, x1, y1 = crop
        others = np.zeros((y1 - y0, x1 - x0), dtype=bool)
        for other in self._followed:
            if other is not followed:
                others |= other.mask[y0:y1, x0:x1]
        others &= ~followed.mask[y0:y1, x0:x1]
        if not others.any():
            return image
        shown = image.copy()
        window = shown[y0:y1, x0:x1]
        window[others] = np.median(window.reshape(-1, 3), axis=0).astype(np.uint8)
        return shown

    def _near(self, followed: _Followed, expected: np.ndarray | None, now: np.ndarray | None) -> bool:
        """Whether a followed person's position lies at most a step (``follow_reach``) from where it was expected
        or where it was (True when a position is unknown); a farther one is left to the search, so following never
        drifts."""
        if expected is None or now is None or followed.position is None:
            return True
        return bool(min(np.linalg.norm(now - expected), np.linalg.norm(now - followed.position)) <= self.follow_reach)

    def _column(self, points: np.ndarray, ground: np.ndarray, centre: np.ndarray | None) -> np.ndarray:
        """Which points stand above the ground (``min_height``) within the column (``column_radius`` plus a
        step's reach, ``follow_reach``) around where the person is expected, as the search's depth candidates do."""
        normal = ground[:3].astype(np.float32)
        with np.errstate(invalid="ignore"):
            keep = np.isfinite(points[..., 2]) & (plane_distances(points, ground) > self.parameters.min_height)
            if centre is not None:
                offset = points - centre.astype(np.float32)
                across = offset - (offset @ normal)[..., None] * normal
                reach = self.parameters.column_radius + self.follow_reach
                keep &= np.einsum("...i,...i->...", across, across) < reach * reach
        return keep

    def _target(self, people: list[PersonHypothesis], shape: tuple[int, int]) -> list[PersonHypothesis]:
        """The one person of a search to follow: the one nearest to where the followed target was expected (by
        its 3-D position) when there was a target, else the most confident one (the first of equals)."""
        if len(people) <= 1:
            return people
        expected = self._followed[0].predicted(self._gap, shape)[1] if self._followed and self._unbroken else None
        if expected is not None:
            positions = [_position(p) for p in people]
            placed = [(float(np.linalg.norm(p - expected)), i) for i, p in enumerate(positions) if p is not None]
            if placed:
                return [people[min(placed)[1]]]
        return [max(people, key=lambda p: (_position(p) is not None, p.confidence))]

    def _remember(self, people: list[PersonHypothesis], standing: bool) -> None:
        """Follow these people from the next frame on, each with a video-mode model of this node (``standing``:
        they were found as depth candidates standing on the ground, and are looked for there)."""
        self._followed = [_Followed(p.roi, p.mask, _position(p), standing) for p in people]

    def shutdown(self) -> None:
        """Close the video-mode models (py_trees calls this when the tree shuts down; dropping the node does too)."""
        self._followed = []
        self._close_models()

    def _look(
        self,
        model: Guarded[Any],
        image: np.ndarray,
        points: np.ndarray | None,
        crops: list[tuple[tuple[int, int, int, int], PersonSegment | None]],
        allowed: np.ndarray | None = None,
    ) -> list[PersonHypothesis]:
        """Run the model on each crop; the people it sees there."""
        found: list[PersonHypothesis] = []
        for (x0, y0, x1, y1), candidate in crops:
            with model.lock:
                landmarks = detect_landmarks(model.value, image[y0:y1, x0:x1])
            if landmarks is None:
                continue
            pixels, visibility = landmarks
            if float(np.mean(visibility[list(TORSO)])) < self.min_torso_visibility:
                continue
            pixels = pixels + np.array([x0, y0])
            xyz = None
            if points is not None:
                xyz = keypoint_points(pixels, points, None if candidate is None else candidate.mask)
                if np.count_nonzero(np.isfinite(xyz[:, 2])) < self.min_on_person * len(LANDMARKS):
                    continue  # the skeleton does not lie on the candidate's points: something else was seen
            found.append(self._person(pixels, visibility, xyz, candidate, points, allowed))
        return found

    def _support_below_shoulders(self, points: np.ndarray, region: np.ndarray, xyz: np.ndarray) -> np.ndarray:
        """The pixels of ``region`` on surfaces facing up lower than ``support_clearance`` below the person's
        shoulders (a table she stands at, the floor): not the person, and cut so that depth does not join what
        stands on them (nothing when the shoulders have no depth)."""
        shoulders = xyz[[LANDMARKS.index("left_shoulder"), LANDMARKS.index("right_shoulder")]]
        shoulders = shoulders[np.isfinite(shoulders).all(axis=1)]
        if shoulders.shape[0] == 0:
            return np.zeros(region.shape, dtype=bool)
        up = up_in_camera(self.optional_view(CameraInfo))
        up = IMAGE_UP if up is None else up
        below = float(np.min(shoulders @ up)) - self.support_clearance
        return support_surfaces(points, region, up, below)

    def _near_bones(self, points: np.ndarray, body: np.ndarray, xyz: np.ndarray) -> np.ndarray:
        """The body pixels within ``body_reach`` of the skeleton's bones (or the torso): what touches the person
        in depth (a fridge door at her pointing hand, a wall she leans on) is not the person; all of them when no
        bone has depth."""
        flat = np.flatnonzero(body)
        near = near_skeleton(points.reshape(-1, 3)[flat], xyz, self.body_reach)
        if near is None:
            return body
        kept = np.zeros(body.shape, dtype=bool)
        kept.reshape(-1)[flat[near]] = True
        return kept

    def _person(
        self,
        pixels: np.ndarray,
        visibility: np.ndarray,
        xyz: np.ndarray | None,
        candidate: PersonSegment | None,
        points: np.ndarray | None = None,
        allowed: np.ndarray | None = None,
    ) -> PersonHypothesis:
        """The hypothesis of one seen person: its own points (see :mod:`annotators.people.body_points`), the Pose
        at their centroid, the class Human and the keypoints."""
        confidence = float(np.mean(visibility[list(TORSO)]))
        height, width = self.view(ColorImage).image.shape[:2]
        if candidate is not None:
            region, roi = candidate.mask, candidate.roi
        else:
            x0, y0 = np.clip(np.floor(pixels.min(axis=0)).astype(int), 0, (width - 1, height - 1))
            x1, y1 = np.clip(np.ceil(pixels.max(axis=0)).astype(int) + 1, 1, (width, height))
            region = np.zeros((height, width), dtype=bool)
            region[y0:y1, x0:x1] = True
            if allowed is not None:  # the region the person was looked for in (the skeleton may not span it)
                region = allowed
            roi = (int(x0), int(y0), int(x1), int(y1))
        mask = region
        position = None
        if points is not None and xyz is not None:
            region = region & ~self._support_below_shoulders(points, region, xyz)
            body = body_mask(points, region, pixels, _unoccluded(xyz))
            if body is not None and body.any():
                body = self._near_bones(points, body, xyz)
            if body is None or not body.any():
                # no seed joint lands on the body: the points near the skeleton's bones (not a table and the
                # objects in front)
                body = np.zeros((height, width), dtype=bool)
                flat = np.flatnonzero(region)
                near = near_skeleton(points.reshape(-1, 3)[flat], xyz, self.body_reach)
                if near is not None:
                    body.reshape(-1)[flat[near]] = True
            if body.any():
                mask = body
                if allowed is not None:  # a followed person's box is where its points are
                    rows, cols = np.nonzero(mask)
                    roi = (int(cols.min()), int(rows.min()), int(cols.max()) + 1, int(rows.max()) + 1)
            position = centroid(points, mask)
        hypothesis = PersonHypothesis(
            point_indices=np.flatnonzero(mask), mask=mask, roi=roi, source=self.name, confidence=confidence
        )
        if position is None and candidate is not None:
            position = candidate.centroid
        if position is not None:
            hypothesis.annotations.append(
                Pose(position=position, orientation=np.array([0.0, 0.0, 0.0, 1.0]), source=self.name)
            )
        hypothesis.annotations.append(Classification(class_name=PERSON_CLASS, source=self.name, confidence=confidence))
        if xyz is None:
            xyz = np.full((pixels.shape[0], 3), np.nan)
        hypothesis.annotations.append(
            BodyKeypoints(
                names=LANDMARKS, pixels=pixels, points=xyz, visibility=visibility, source=self.name,
                confidence=confidence,
            )
        )  # fmt: skip
        return hypothesis
