"""Draw an answer on its frame: the picture ``robokudo run|query --annotated-image`` writes, for every query kind.

:func:`draw_answer` takes the CAS a tree analysed and draws, on a copy of its colour image, what that frame's
experts found and what the answer says about it:

- objects: every hypothesis outlined; the answer's objects boxed with ``#id class`` (every hypothesis numbered with
  its colour and size when the CAS holds no answer, as after ``robokudo run``);
- people: each person's 2-D body keypoints as dots joined by the skeleton's bones;
- pointing: the arm's 3-D ray projected from the shoulder to the aimed point, and the target highlighted (the
  pointed object's box, or the region's box outline when the region boxes are given) with the angle between the ray
  and the target;
- free space: every free placement's rectangle on its surface, projected and filled, numbered largest first;
- track: the tracked target's box, its estimate with the spread as a circle, and the ``trail`` of earlier estimates.

3-D geometry is projected with the frame's camera (:meth:`~robokudo.core.types.CameraIntrinsics.project`; world
points through the inverse of the camera pose). Colours are RGB; the marks tests look for are drawn without
anti-aliasing in the colours below.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from annotators.image.human_pose import BONES
from reasoning.beliefs.answer import Answer
from robokudo.application.report import summarize
from robokudo.core.cas import CAS
from robokudo.core.geometry import pose_matrix
from robokudo.core.regions import RegionBox
from robokudo.core.types import (
    BodyKeypoints,
    CameraInfo,
    ColorImage,
    FreePlacement,
    ObjectHypothesis,
    PersonHypothesis,
    PointingTarget,
    QueryAnswer,
    TargetTrack,
)

ANSWER_COLOR = (0, 229, 255)
"""Boxes of the answer's objects (or of every hypothesis without an answer)."""
OUTLINE_COLOR = (160, 160, 160)
"""The outline of every hypothesis' segment."""
BONE_COLOR = (255, 200, 0)
KEYPOINT_COLOR = (255, 40, 40)
RAY_COLOR = (255, 0, 255)
"""The pointing ray."""
TARGET_COLOR = (255, 255, 0)
"""The pointed object or region."""
PLACEMENT_COLOR = (0, 255, 96)
"""The outline of a free placement (its fill is blended into the image)."""
TRACK_COLOR = (255, 128, 0)
"""The tracked target's box, estimate and trail."""

KEYPOINT_VISIBILITY = 0.5
"""Keypoints less visible than this are not drawn."""
NEAREST = 0.05
"""Points nearer to the camera plane than this (metres) are not projected."""
FILL_ALPHA = 0.35


@dataclass(frozen=True)
class Box:
    """A hypothesis' image box and its label."""

    roi: tuple[int, int, int, int]
    label: str


def answer_boxes(cas: CAS) -> tuple[Box, ...]:
    """The answer's objects seen in this frame (``#id label``), or else every hypothesis, with their boxes."""
    answer = _answer(cas)
    if answer is not None:
        labelled = tuple(
            Box(tuple(int(v) for v in o.roi), f"#{o.id} {o.shown_label()}")  # type: ignore[arg-type]
            for o in answer.objects
            if o.roi is not None
        )
        if labelled:
            return labelled
    hypotheses = cas.annotations(ObjectHypothesis)
    return tuple(Box(tuple(int(v) for v in h.roi), f"hypothesis {i}") for i, h in enumerate(hypotheses, 1))  # type: ignore[arg-type]


def draw_answer(
    cas: CAS, *, regions: Iterable[RegionBox] = (), trail: Sequence[tuple[float, float]] = ()
) -> np.ndarray:
    """The colour image of ``cas`` (a new RGB array) with what its experts found and its answer drawn (see the
    module); ``regions`` are the semantic map's boxes (to outline a pointed region), ``trail`` earlier image positions
    of a tracked target, oldest first. ValueError when the CAS has no colour image."""
    color_view = cas.view(ColorImage)
    if color_view is None:
        raise ValueError("the CAS has no ColorImage to draw on")
    canvas = np.ascontiguousarray(color_view.image).copy()
    camera = _Camera.of(cas)
    _draw_placements(canvas, cas, camera)
    _draw_outlines(canvas, cas)
    for box in _boxes(cas):
        _draw_box(canvas, box.roi, box.label, ANSWER_COLOR)
    _draw_people(canvas, cas)
    _draw_pointing(canvas, cas, camera, tuple(regions))
    _draw_tracks(canvas, cas, camera, trail)
    return canvas


def write_image(picture: np.ndarray, path: str | Path) -> Path:
    """Write an RGB picture to ``path`` (format from the suffix); returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if not cv2.imwrite(str(path), cv2.cvtColor(picture, cv2.COLOR_RGB2BGR)):
        raise OSError(f"could not write an image to {path}")
    return path


def write_annotated_image(
    cas: CAS, path: str | Path, *, regions: Iterable[RegionBox] = (), trail: Sequence[tuple[float, float]] = ()
) -> Path:
    """Draw the answer on its frame (:func:`draw_answer`) and write the picture to ``path``; returns the path."""
    return write_image(draw_answer(cas, regions=regions, trail=trail), path)


# ----------------------------------------------------------------------------------------------- projection


@dataclass(frozen=True)
class _Camera:
    """The frame's camera: intrinsics and the transform from the world into the camera (None without a pose)."""

    info: CameraInfo | None
    world_to_camera: np.ndarray | None

    @classmethod
    def of(cls, cas: CAS) -> _Camera:
        info = cas.view(CameraInfo)
        pose = None if info is None or info.cam_to_world is None else np.asarray(info.cam_to_world, dtype=np.float64)
        return cls(info, None if pose is None else np.linalg.inv(pose))

    def to_camera(self, points: np.ndarray, frame: str) -> np.ndarray | None:
        """Nx3 points of ``frame`` in the camera frame (None when that frame cannot be reached)."""
        p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if self.info is None:
            return None
        if frame in ("camera", self.info.frame_id):
            return p
        if self.world_to_camera is None:
            return None
        return p @ self.world_to_camera[:3, :3].T + self.world_to_camera[:3, 3]

    def pixels(self, points: np.ndarray, frame: str = "camera") -> np.ndarray | None:
        """Nx2 pixel positions of Nx3 points, None when any is behind the camera or the frame is unknown."""
        camera = self.to_camera(points, frame)
        if camera is None or self.info is None or not np.all(camera[:, 2] > NEAREST):
            return None
        return self.info.intrinsics.project(camera)

    def segment(self, start: np.ndarray, end: np.ndarray) -> np.ndarray | None:
        """The two pixel ends of a camera-frame segment, clipped to the part in front of the camera."""
        a, b = np.asarray(start, dtype=np.float64), np.asarray(end, dtype=np.float64)
        if a[2] <= NEAREST and b[2] <= NEAREST:
            return None
        if a[2] <= NEAREST or b[2] <= NEAREST:
            t = (NEAREST * 1.01 - a[2]) / (b[2] - a[2])
            cut = a + t * (b - a)
            a, b = (cut, b) if a[2] <= NEAREST else (a, cut)
        return self.pixels(np.stack((a, b)))


def _answer(cas: CAS) -> Answer | None:
    found = cas.view(QueryAnswer)
    return found.answer if found is not None and isinstance(found.answer, Answer) else None


def _point(pixel: np.ndarray) -> tuple[int, int]:
    return round(float(pixel[0])), round(float(pixel[1]))


# ----------------------------------------------------------------------------------------------- drawing


def _boxes(cas: CAS) -> tuple[Box, ...]:
    """The answer's boxes; without an answer every hypothesis numbered with its colour and size (as in the
    hypothesis table of ``robokudo run``)."""
    if _answer(cas) is not None:
        return answer_boxes(cas)
    boxes = []
    for s in summarize(cas):
        label = f"{s.number} {s.color}" + (f" {100 * s.size[0]:.0f}cm" if s.size is not None else "")
        boxes.append(Box(tuple(int(v) for v in s.roi), label))  # type: ignore[arg-type]
    return tuple(boxes)


def _draw_outlines(canvas: np.ndarray, cas: CAS) -> None:
    for hypothesis in cas.annotations(ObjectHypothesis):
        x0, y0, x1, y1 = hypothesis.roi
        local = np.ascontiguousarray(hypothesis.mask[y0:y1, x0:x1]).view(np.uint8)
        contours, _ = cv2.findContours(local, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_SIMPLE, offset=(x0, y0))
        cv2.drawContours(canvas, contours, -1, OUTLINE_COLOR, 1, cv2.LINE_AA)


def _draw_box(canvas: np.ndarray, roi: tuple[int, int, int, int], label: str, rgb: tuple[int, int, int]) -> None:
    x0, y0, x1, y1 = roi
    cv2.rectangle(canvas, (x0, y0), (x1 - 1, y1 - 1), rgb, 2)
    _draw_label(canvas, (x0, y0), label, rgb)


def _draw_label(canvas: np.ndarray, corner: tuple[int, int], label: str, rgb: tuple[int, int, int]) -> None:
    """A label on a black background just above ``corner`` (below the image's top)."""
    x0, y0 = corner
    (width, height), _ = cv2.getTextSize(label, cv2.FONT_HERSHEY_SIMPLEX, 0.45, 1)
    top = max(y0 - height - 6, 0)
    cv2.rectangle(canvas, (x0, top), (x0 + width + 6, top + height + 6), (0, 0, 0), -1)
    cv2.putText(canvas, label, (x0 + 3, top + height + 2), cv2.FONT_HERSHEY_SIMPLEX, 0.45, rgb, 1, cv2.LINE_AA)


def _draw_people(canvas: np.ndarray, cas: CAS) -> None:
    """Each person's skeleton: bones between visible keypoints, a dot on every visible keypoint."""
    for person in cas.annotations(PersonHypothesis):
        for keypoints in person.find(BodyKeypoints):
            pixels = np.asarray(keypoints.pixels, dtype=np.float64)
            shown = (np.asarray(keypoints.visibility) >= KEYPOINT_VISIBILITY) & np.all(np.isfinite(pixels), axis=1)
            index = {name: i for i, name in enumerate(keypoints.names) if shown[i]}
            for first, second in BONES:
                if first != second and first in index and second in index:
                    a, b = pixels[index[first]], pixels[index[second]]
                    cv2.line(canvas, _point(a), _point(b), BONE_COLOR, 2, cv2.LINE_8)
            for i in index.values():
                cv2.circle(canvas, _point(pixels[i]), 3, KEYPOINT_COLOR, -1, cv2.LINE_8)


def _draw_pointing(canvas: np.ndarray, cas: CAS, camera: _Camera, regions: tuple[RegionBox, ...]) -> None:
    """Each pointing ray from the shoulder to the aimed point, and its target with the angle between them."""
    answer = _answer(cas)
    for pointing in cas.annotations(PointingTarget):
        origin = np.asarray(pointing.origin, dtype=np.float64)
        direction = np.asarray(pointing.direction, dtype=np.float64)
        along = float(np.dot(np.asarray(pointing.point, dtype=np.float64) - origin, direction))
        ends = camera.segment(origin, origin + (along if along > 0 else 1.0) * direction)
        if ends is not None:
            cv2.line(canvas, _point(ends[0]), _point(ends[1]), RAY_COLOR, 2, cv2.LINE_8)
            cv2.circle(canvas, _point(ends[0]), 4, RAY_COLOR, -1, cv2.LINE_8)
        degrees = np.degrees(pointing.angular_error)
        if pointing.kind == "object" and pointing.roi is not None:
            x0, y0, x1, y1 = (int(v) for v in pointing.roi)
            cv2.rectangle(canvas, (x0 - 4, y0 - 4), (x1 + 3, y1 + 3), TARGET_COLOR, 2, cv2.LINE_8)
            named = answer.pointing.target if answer is not None and answer.pointing is not None else "pointed at"
            _draw_label(canvas, (x0 - 3, y1 + 24), f"{named}, {degrees:.1f} deg", TARGET_COLOR)
            continue
        region = next((r for r in regions if r.name == pointing.name), None)
        outline = None if region is None else _region_outline(region, camera)
        if outline is not None:
            cv2.polylines(canvas, [outline], True, TARGET_COLOR, 2, cv2.LINE_8)
            corner = (int(outline[:, 0].min()), int(outline[:, 1].min()))
        else:
            aimed = camera.pixels(np.asarray(pointing.point))
            if aimed is None:
                continue
            corner = _point(aimed[0])
            cv2.circle(canvas, corner, 8, TARGET_COLOR, 2, cv2.LINE_8)
        _draw_label(canvas, corner, f"region {pointing.name}, {degrees:.1f} deg", TARGET_COLOR)


def _region_outline(region: RegionBox, camera: _Camera) -> np.ndarray | None:
    """The convex outline (int32 Kx2) of a region box's projected corners, None when a corner is behind the camera."""
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=np.float64)
    local = signs * np.asarray(region.size, dtype=np.float64) / 2
    corners = local @ region.pose[:3, :3].T + region.pose[:3, 3]
    pixels = camera.pixels(corners, region.frame)
    if pixels is None:
        return None
    return cv2.convexHull(np.round(pixels).astype(np.int32)).reshape(-1, 2)


def _draw_placements(canvas: np.ndarray, cas: CAS, camera: _Camera) -> None:
    """Every free placement's rectangle on its surface, filled and outlined, numbered largest first."""
    placements = sorted(cas.annotations(FreePlacement), key=lambda p: -p.size[0] * p.size[1])
    outlines = []
    for placement in placements:
        half = np.asarray(placement.size, dtype=np.float64) / 2
        local = np.array([[-half[0], -half[1], 0.0], [half[0], -half[1], 0.0], [half[0], half[1], 0.0],
                          [-half[0], half[1], 0.0]])  # fmt: skip
        pose = pose_matrix(placement.position, placement.orientation)
        pixels = camera.pixels(local @ pose[:3, :3].T + pose[:3, 3], placement.frame)
        outlines.append(None if pixels is None else np.round(pixels).astype(np.int32))
    if not any(o is not None for o in outlines):
        return
    fill = canvas.copy()
    for outline in outlines:
        if outline is not None:
            cv2.fillPoly(fill, [outline], PLACEMENT_COLOR, cv2.LINE_8)
    cv2.addWeighted(fill, FILL_ALPHA, canvas, 1 - FILL_ALPHA, 0, dst=canvas)
    for number, (placement, outline) in enumerate(zip(placements, outlines, strict=True), start=1):
        if outline is None:
            continue
        cv2.polylines(canvas, [outline], True, PLACEMENT_COLOR, 1, cv2.LINE_8)
        label = f"{number}: {100 * placement.size[0]:.0f}x{100 * placement.size[1]:.0f}cm fits {placement.fits}"
        centre = outline.mean(axis=0)
        (width, height), _ = cv2.getTextSize(label, cv2.FONT_HERSHEY_SIMPLEX, 0.45, 1)
        _draw_label(canvas, (int(centre[0] - width / 2), int(centre[1] + height / 2)), label, (255, 255, 255))


def _draw_tracks(canvas: np.ndarray, cas: CAS, camera: _Camera, trail: Sequence[tuple[float, float]]) -> None:
    """The trail of earlier estimates, then each track's box (when seen), estimate cross and spread circle."""
    points = np.array([p for p in trail if p is not None and np.all(np.isfinite(p))], dtype=np.float64).reshape(-1, 2)
    if points.shape[0] >= 2:
        cv2.polylines(canvas, [np.round(points).astype(np.int32)], False, TRACK_COLOR, 2, cv2.LINE_8)
    for point in points:
        cv2.circle(canvas, _point(point), 2, TRACK_COLOR, -1, cv2.LINE_8)
    for track in cas.annotations(TargetTrack):
        label = f"tracked {track.target or 'object'}" + ("" if track.seen else f", unseen {track.unseen_for:.1f}s")
        if track.hypothesis is not None:
            _draw_box(canvas, tuple(int(v) for v in track.hypothesis.roi), label, TRACK_COLOR)  # type: ignore[arg-type]
        if track.pixel is None:
            continue
        centre = _point(np.asarray(track.pixel))
        cv2.drawMarker(canvas, centre, TRACK_COLOR, cv2.MARKER_CROSS, 14, 2, cv2.LINE_8)
        position = camera.to_camera(np.asarray(track.position), track.frame)
        depth = float(position[0, 2]) if position is not None else 0.0
        if camera.info is not None and depth > NEAREST and track.spread > 0:
            radius = max(int(camera.info.intrinsics.fx * track.spread / depth), 3)
            cv2.circle(canvas, centre, radius, TRACK_COLOR, 1, cv2.LINE_8)
        if track.hypothesis is None:
            _draw_label(canvas, (centre[0] + 8, centre[1] - 8), label, TRACK_COLOR)
