"""Form features of each object hypothesis for classification: height/width ratio, a handle, an open top, a waist.

Measured on the hypothesis' points in the upright support frame (:mod:`annotators.geometry.support_frame`, z up):

* **height over width**: the height (top at the 98 % height quantile; bottom at the support, or the 2 % quantile
  without one) over the footprint's longer extent (2 % to 98 % along its principal axes);
* **handle**: looked for on the points that are not grazing (:mod:`annotators.geometry.grazing`: the streaks of
  stray points along an object's outline, where lines of sight cross a depth jump, stick out of it like a handle).
  The body is modelled twice, and a handle sticking out of either is one:

  - as a surface of revolution (:mod:`annotators.cloud.body_profile`: one axis, a radius per height band, which
    follows a tapered mug or a wider base). A handle is a clump of points of the middle part sticking out of it by
    more than ``HANDLE_GAP`` of the radius at their height (and at least 1 cm), in a narrow direction (circular
    spread under ``HANDLE_SPREAD``), that makes up at least ``HANDLE_SECTOR_SHARE`` of the middle part seen within
    ``HANDLE_SECTOR`` of that direction (a handle stands out of what is seen there; the corner of a box or the
    flat side of an oblong bottle is a small fringe of a broad face);
  - as the circle fitted to the footprint of the lowest part (up to ``BODY_SLICE`` of the height), where a handle
    never is (seen as a half arc, this circle often comes out too wide, but it still finds a small handle seen
    end-on, which the profile absorbs). A handle is a clump of points of the middle part sticking out of that circle
  by more than ``HANDLE_GAP`` of its radius, in a narrow direction (circular spread under ``HANDLE_SPREAD``),
  while the lowest part does not stick out there (a wider base is no handle). Its confidence grows with its
  points up to ``HANDLE_POINTS``; the confidence that there is none grows with how much of the middle part was
  seen but falls with the share of it that sticks out without forming a handle, to 0 at ``HANDLE_SHARE`` (about
  what a handle seen from the side holds: a handle seen end-on or cut apart by the segmenter looks like that, a
  plain cup's or can's side does not). When most of the middle part (``FLARE_SHARE``) sticks out of that circle,
  the body is wider above its foot (a bowl's flaring wall): that is no handle, and the confidence that there is
  none is taken from the body profile instead, which follows the flare.
  "None" means none in view: a handle straight behind the body shows at most as a sliver over the far rim, a few
  pixels high from a tabletop view (the blue mug of the first RealSense frame), which the depth image does not
  resolve. From the elevations of a tabletop view a handle hides behind a round body in about a quarter of the
  directions around it, whatever the object; that it may be there is the classifier's to weigh, not this cue's;
* **waist**: the object is narrower across the middle of its height than across its top and its bottom (a drill
  standing on its battery, its pistol grip between the battery and the body; a wine glass's stem): the footprint
  extent of the middle band (``WAIST_BANDS``) is less than ``WAIST_RATIO`` of the smaller of the bottom and top
  bands' extents, measured along the footprint's principal axes (points missing in a band's middle, hidden behind
  something in front, do not narrow it). The confidence grows with how far the ratio lies from ``WAIST_RATIO`` (full
  at ``WAIST_CLEAR`` times beyond it either way) and with the points in the sparsest band (full at
  ``FULL_EVIDENCE``). Over the labelled objects of the shared frames (``bench/measure_waists.py``,
  bench/profiles/waist-analysis.txt) the two upright drills measure 0.33 and 0.45, every other uoc object 0.75 or
  more and every mOSD object 0.76 or more;
* **open top**: by visibility. Every seen point of a closed (convex) object is seen from outside: the line of
  sight from it to the camera leaves the object's convex hull at once. The inside of an open object (a cup's
  far inner wall, a bowl's bottom) is seen through the opening: its line of sight crosses the hull for a good part
  of the object's width and leaves it over the rim, near the top. (Two objects cut as one are not convex either:
  a line of sight from the one behind runs through their hull too, but leaves it lower, between them.) What is
  seen through an opening is the far part of the inside: seen from above, it lies within the footprint of the
  object's top (its points above ``RIM_EXIT`` of the height: the rim), widened by ``THROUGH_MIN``, and beyond
  the middle of that top as seen from the camera (the near rim hides the near inside). The middle is halfway
  between the top's near and far edge, not the middle of its points: an open top seen obliquely shows many points
  on its far rim and the upper far inside and few on its thin near rim, so the points' median lies near the far
  rim. A taller object's face
  seen over a shorter one cut together with it in front, or a bottle's shoulder below its cap, is seen over the
  top of the hull too, but in front of the top's middle or beside the top. The share of points seen through the
  hull for more than ``THROUGH`` of the footprint's extent (and at least ``THROUGH_MIN`` metres), leaving it
  above ``RIM_EXIT`` of the height, in the far part of the top, says open (more than ``OPEN_SHARE``) or closed;
  the confidence grows with the distance of that share from ``OPEN_SHARE`` (a share near it says little either
  way).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from types import ModuleType
from typing import ClassVar

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from annotators.cloud.base_layer import BaseLayer, find_base
from annotators.cloud.body_profile import body_profile
from annotators.cloud.cloud_expert import CloudExpert
from annotators.cloud.shape import circle_fit
from annotators.geometry.grazing import grazing_pixels
from annotators.geometry.support_frame import SupportFrame, sampled_indices, support_frame, usable_plane
from robokudo.core.capability import Capability
from robokudo.core.types import CameraInfo, CasType, FormFeatures, ObjectHypothesis, Plane, PointCloud

BODY_SLICE = 0.2
"""The lowest part of the object (share of its height) whose footprint is taken as the body."""
HANDLE_BAND = (0.25, 0.9)
"""The part of the height (shares) where a handle is looked for."""
HANDLE_GAP = 0.25
"""A handle point lies farther than (1 + this) body radii (and at least 1 cm more) from the body's axis."""
HANDLE_SPREAD = np.radians(40.0)
"""A handle's points point in one direction: their circular standard deviation around the axis is below this."""
HANDLE_SECTOR = np.radians(30.0)
"""The directions within this angle of a handle's are where it is seen (for ``HANDLE_SECTOR_SHARE``)."""
HANDLE_SECTOR_SHARE = 0.25
"""A handle sticking out of the body profile makes up at least this share of the middle part seen in its sector."""
HANDLE_MIN_SHARE = 0.02
"""A handle holds at least this share of the middle part's points (and 8 points)."""
HANDLE_POINTS = 20
"""Points of a handle at which it is taken as certain."""
HANDLE_SHARE = 0.1
"""Share of the middle part a handle seen from the side holds: sticking out that much, the points leave it open
whether there is a handle (no confidence that there is none)."""
FLARE_SHARE = 0.5
"""Share of the middle part sticking out of the foot circle beyond which that is the body, wider above its foot (a
bowl's flaring wall), not a handle: a handle holds about ``HANDLE_SHARE`` of it, never most of it."""
THROUGH = 0.15
"""A point is seen through the object when its line of sight crosses the hull for this share of the extent."""
THROUGH_MIN = 0.01
"""... and for at least this many metres (depth noise puts surface points a few millimetres inside the hull)."""
RIM_EXIT = 0.85
"""... leaving the hull over the rim: at least this share of the height up (not between two objects cut as one)."""
TOP_SPAN = (0.1, 0.9)
"""The quantiles of the top's points (along the direction away from the camera) taken as its near and far edge:
its middle lies halfway between them (stray points, or a second object cut together with it, move it little)."""
THROUGH_TESTED = 400
"""At most about this many points (evenly taken) are tested for being seen through the object."""
OPEN_SHARE = 0.1
"""Share of points seen through the object from which it is open at the top."""
FULL_EVIDENCE = 40
"""Points (object, or handle) at which the evidence is taken as complete (confidence 1)."""
WAIST_BANDS = ((0.0, 0.25), (0.375, 0.625), (0.75, 1.0))
"""The bottom, middle and top bands of the height (shares) whose footprint extents the waist compares."""
WAIST_RATIO = 0.6
"""A middle band narrower than this share of the narrower of the bottom and top bands is a waist."""
WAIST_CLEAR = 1.5
"""A ratio this many times beyond ``WAIST_RATIO`` (either way) says waist or none with full confidence."""


@dataclass(frozen=True)
class Form:
    """The measured form features (see the module docstring)."""

    height_to_width: float
    has_handle: bool
    handle_confidence: float
    open_top: bool
    open_confidence: float
    base: BaseLayer | None = None
    waisted: bool = False
    waist_confidence: float = 0.0


def _extent(xy: np.ndarray) -> float:
    centred = xy - xy.mean(axis=0)
    _, _, axes = np.linalg.svd(centred, full_matrices=False)
    along = centred @ axes.T
    low, high = np.quantile(along, (0.02, 0.98), axis=0)
    return float((high - low).max())


def _circular_spread(angles: np.ndarray) -> float:
    length = float(np.hypot(np.cos(angles).mean(), np.sin(angles).mean()))
    return float(np.sqrt(-2.0 * np.log(max(length, 1e-12))))


def _angle_to(angles: np.ndarray, direction: float) -> np.ndarray:
    return np.abs(np.angle(np.exp(1j * (angles - direction))))


def profile_handle(points: np.ndarray, bottom: float, height: float) -> tuple[bool, float]:
    """Whether a handle sticks out of the body profile (see the module docstring), and the confidence that it does
    (0 without)."""
    profile = body_profile(points, bottom, height)
    z = points[:, 2] - bottom
    middle = (z >= HANDLE_BAND[0] * height) & (z <= HANDLE_BAND[1] * height)
    if profile is None or np.count_nonzero(middle) < 20:
        return False, 0.0
    offsets = points[middle, :2] - profile.centre
    radius = profile.radius_at(z[middle])
    excess = np.linalg.norm(offsets, axis=1) - radius
    out = excess > np.maximum(0.01, HANDLE_GAP * radius)
    if np.count_nonzero(out) < max(8, HANDLE_MIN_SHARE * out.size):
        return False, 0.0
    angles = np.arctan2(offsets[:, 1], offsets[:, 0])
    if _circular_spread(angles[out]) > HANDLE_SPREAD:
        return False, 0.0
    direction = float(np.arctan2(np.sin(angles[out]).mean(), np.cos(angles[out]).mean()))
    sector = _angle_to(angles, direction) < HANDLE_SECTOR
    if np.count_nonzero(out & sector) < HANDLE_SECTOR_SHARE * np.count_nonzero(sector):
        return False, 0.0
    return True, min(1.0, np.count_nonzero(out) / HANDLE_POINTS)


def handle_evidence(points: np.ndarray, bottom: float, height: float) -> tuple[bool, float]:
    """Whether a handle sticks out of the body's side, and the confidence of that (see the module docstring); the
    points should hold no grazing ones. When most of the middle part sticks out of the foot circle
    (:data:`FLARE_SHARE`) the body itself is wider above its foot (a bowl): the circle then says nothing about a
    handle either way, and the confidence that there is none is the body profile's, which follows the flare."""
    circle = foot_circle_handle(points, bottom, height)
    if circle[0]:  # the circle's handle (and confidence) stands whatever the profile finds
        return circle
    found, confidence = profile_handle(points, bottom, height)
    if found:
        return True, confidence
    if foot_flare_share(points, bottom, height) > FLARE_SHARE:
        return False, profile_none_confidence(points, bottom, height)
    return circle


def _foot_and_middle(points: np.ndarray, bottom: float, height: float) -> tuple[np.ndarray, np.ndarray]:
    """The x, y of the lowest part (the foot, up to ``BODY_SLICE`` of the height) and of the middle part
    (``HANDLE_BAND``)."""
    z = points[:, 2] - bottom
    body = points[z <= BODY_SLICE * height, :2]
    middle = points[(z >= HANDLE_BAND[0] * height) & (z <= HANDLE_BAND[1] * height), :2]
    return body, middle


def foot_flare_share(points: np.ndarray, bottom: float, height: float) -> float:
    """The share of the middle part lying farther than the handle reach from the circle fitted to the foot (0 when
    there is no usable foot circle)."""
    body, middle = _foot_and_middle(points, bottom, height)
    if body.shape[0] < 10 or middle.shape[0] < 20:
        return 0.0
    fit = circle_fit(body)
    if fit is None or not np.isfinite(fit[1]) or fit[1] <= 0.005:
        return 0.0
    centre, radius = fit
    reach = radius + max(0.01, HANDLE_GAP * radius)
    return float(np.count_nonzero(np.linalg.norm(middle - centre, axis=1) > reach)) / middle.shape[0]


def profile_none_confidence(points: np.ndarray, bottom: float, height: float) -> float:
    """The confidence that no handle sticks out of the body profile (:mod:`annotators.cloud.body_profile`): growing
    with how much of the middle part was seen, falling to 0 when ``HANDLE_SHARE`` of it sticks out of the profile
    by more than the handle gap (as :func:`foot_circle_handle` weighs it against the foot circle); 0 without a
    profile."""
    profile = body_profile(points, bottom, height)
    z = points[:, 2] - bottom
    middle = (z >= HANDLE_BAND[0] * height) & (z <= HANDLE_BAND[1] * height)
    if profile is None or np.count_nonzero(middle) < 20:
        return 0.0
    radius = profile.radius_at(z[middle])
    excess = np.linalg.norm(points[middle, :2] - profile.centre, axis=1) - radius
    sticking_out = np.count_nonzero(excess > np.maximum(0.01, HANDLE_GAP * radius)) / excess.size
    return min(1.0, excess.size / FULL_EVIDENCE) * max(0.0, 1.0 - sticking_out / HANDLE_SHARE)


def foot_circle_handle(points: np.ndarray, bottom: float, height: float) -> tuple[bool, float]:
    """Whether a handle sticks out of the circle fitted to the foot, and the confidence of that (see the module
    docstring)."""
    body, middle = _foot_and_middle(points, bottom, height)
    if body.shape[0] < 10 or middle.shape[0] < 20:
        return False, 0.0
    fit = circle_fit(body)
    if fit is None:
        return False, 0.0
    centre, radius = fit
    if not np.isfinite(radius) or radius <= 0.005 or radius > 2.0 * _extent(body):
        return False, 0.0
    reach = radius + max(0.01, HANDLE_GAP * radius)
    offsets = middle - centre
    out = np.linalg.norm(offsets, axis=1) > reach
    sticking_out = np.count_nonzero(out) / middle.shape[0]
    confidence = min(1.0, middle.shape[0] / FULL_EVIDENCE) * max(0.0, 1.0 - sticking_out / HANDLE_SHARE)  # none
    if np.count_nonzero(out) < max(8, HANDLE_MIN_SHARE * middle.shape[0]):
        return False, confidence
    angles = np.arctan2(offsets[out, 1], offsets[out, 0])
    if _circular_spread(angles) > HANDLE_SPREAD:
        return False, confidence
    direction = np.array([np.cos(angles).mean(), np.sin(angles).mean()])
    below = body - centre
    base_out = (np.linalg.norm(below, axis=1) > reach) & (below @ direction > 0.7 * np.linalg.norm(below, axis=1))
    if np.count_nonzero(base_out) > 0.5 * np.count_nonzero(out) * body.shape[0] / middle.shape[0]:
        return False, confidence  # the base reaches out there too: a wider object, no handle
    return True, min(1.0, np.count_nonzero(out) / HANDLE_POINTS)


def waist_ratio(points: np.ndarray, bottom: float, height: float) -> tuple[float, int] | None:
    """The footprint extent of the middle band of the height over the smaller of the bottom and top bands'
    (:data:`WAIST_BANDS`, along the footprint's principal axes) and the points in the sparsest band; None when a
    band holds fewer than 10 points or the height is none."""
    if points.shape[0] < 20 or height <= 0.0:
        return None
    xy = points[:, :2] - points[:, :2].mean(axis=0)
    _, axes = np.linalg.eigh(xy.T @ xy)  # the footprint's principal axes (columns)
    along = xy @ axes
    z = (points[:, 2] - bottom) / height
    extents, counts = [], []
    for low, high in WAIST_BANDS:
        band = along[(z >= low) & (z <= high)]
        if band.shape[0] < 10:
            return None
        counts.append(band.shape[0])
        low_end, high_end = np.quantile(band, (0.02, 0.98), axis=0)
        extents.append(float((high_end - low_end).max()))
    narrower = min(extents[0], extents[2])
    if narrower <= 0.0:
        return None
    return max(extents[1] / narrower, 1e-6), min(counts)


def waist_evidence(points: np.ndarray, bottom: float, height: float) -> tuple[bool, float]:
    """Whether the object is narrower across the middle of its height than across its bottom and its top, and the
    confidence of that (see the module docstring); (False, 0) when it cannot be measured."""
    measured = waist_ratio(points, bottom, height)
    if measured is None:
        return False, 0.0
    ratio, fewest = measured
    clearness = min(1.0, abs(float(np.log(ratio / WAIST_RATIO))) / float(np.log(WAIST_CLEAR)))
    return ratio < WAIST_RATIO, clearness * min(1.0, fewest / FULL_EVIDENCE)


@functools.cache
def _loops() -> ModuleType:
    """:mod:`annotators.cloud.form_loops`, imported (and numba with it) on first use."""
    from annotators.cloud import form_loops

    return form_loops


def lines_of_sight(points: np.ndarray, tested: np.ndarray, camera: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each of the Mx3 ``tested`` points (some of the Nx3 ``points``): how far (metres) its line of sight towards
    ``camera`` runs inside the convex hull of ``points``, and the height (z) at which it leaves the hull. A flat hull
    (no volume) holds no line of sight: (0, the point's own z)."""
    try:
        hull = ConvexHull(points)
    except QhullError:
        return np.zeros(tested.shape[0]), tested[:, 2].copy()
    sight = camera - tested
    sight /= np.maximum(np.linalg.norm(sight, axis=1, keepdims=True), 1e-12)
    # -(tested . normal + offset): the distance to each face's plane, >= 0 inside; divided by sight . normal (> 0:
    # the line of sight runs towards that face) it is how far the line of sight runs to that face
    run = _loops().sight_runs(np.ascontiguousarray(tested), sight, hull.equations)
    return run, tested[:, 2] + run * sight[:, 2]


def far_inside_top(points: np.ndarray, tested: np.ndarray, rim_height: float, camera: np.ndarray) -> np.ndarray:
    """Which of the Mx3 ``tested`` points lie, seen from above, in the far part of the top of the Nx3 ``points``
    (those at least ``rim_height`` high): inside its footprint (convex hull in x, y, widened by ``THROUGH_MIN``)
    and beyond its middle as seen from ``camera`` (halfway between its near and far edge, at the ``TOP_SPAN``
    quantiles along the direction away from the camera); none without such a footprint."""
    top = points[points[:, 2] >= rim_height, :2]
    none = np.zeros(tested.shape[0], dtype=bool)
    if top.shape[0] < 3:
        return none
    try:
        hull = ConvexHull(top)
    except QhullError:  # the top is a line or a point: it encloses nothing
        return none
    inside = _loops().within_outline(np.ascontiguousarray(tested[:, :2]), hull.equations, THROUGH_MIN)
    centre = np.median(top, axis=0)
    away = centre - camera[:2]
    length = float(np.linalg.norm(away))
    if length < 1e-9:  # seen from straight above: no near and far side
        return inside
    away /= length
    near, far = np.quantile((top - centre) @ away, TOP_SPAN)
    middle = centre + away * (near + far) / 2.0
    return inside & ((tested[:, :2] - middle) @ away > 0.0)


def open_evidence(
    points: np.ndarray, bottom: float, height: float, camera: np.ndarray, extent: float | None = None
) -> tuple[bool, float]:
    """Whether the object is open at the top, and the confidence of that (see the module docstring); ``extent``:
    the footprint's longer extent when already measured (as :func:`measure_form` does)."""
    extent = _extent(points[:, :2]) if extent is None else extent
    if points.shape[0] < 20 or extent <= 0.0 or height <= 0.0:
        return False, 0.0
    tested = points[:: max(1, points.shape[0] // THROUGH_TESTED)]
    run, leaves_at = lines_of_sight(points, tested, camera)
    rim = bottom + RIM_EXIT * height
    through = (
        (run >= max(THROUGH * extent, THROUGH_MIN)) & (leaves_at >= rim) & far_inside_top(points, tested, rim, camera)
    )
    share = float(np.count_nonzero(through)) / tested.shape[0]
    clearness = min(1.0, abs(share - OPEN_SHARE) / OPEN_SHARE)
    return share > OPEN_SHARE, clearness * min(1.0, points.shape[0] / FULL_EVIDENCE)


def measure_form(points: np.ndarray, frame: SupportFrame, grazing: np.ndarray | None = None) -> Form | None:
    """The form features of an object's Nx3 points in ``frame`` (upright); None for fewer than 20 points or no
    height or width. ``grazing`` marks the points left out of the handle cue (:mod:`annotators.geometry.grazing`)."""
    if points.shape[0] < 20:
        return None
    z = points[:, 2]
    low, high = np.quantile(z, (0.02, 0.98))
    bottom = 0.0 if frame.on_plane else float(low)
    height = float(high) - bottom
    width = _extent(points[:, :2])
    if height <= 0.0 or width <= 0.0:
        return None
    base = find_base(points, bottom, height)
    if base is not None:  # the body above the step is measured; the base is noted in the Form
        body = points[:, 2] >= bottom + base.step
        points, bottom, height, width = points[body], bottom + base.step, height - base.step, base.body_width
        grazing = None if grazing is None else grazing[body]
    seen = points if grazing is None else points[~grazing]
    handle, handle_confidence = handle_evidence(seen, bottom, height)
    open_top, open_confidence = open_evidence(points, bottom, height, frame.camera_to_frame[:3, 3], width)
    waisted, waist_confidence = waist_evidence(points, bottom, height)
    return Form(height / width, handle, handle_confidence, open_top, open_confidence, base, waisted, waist_confidence)


class FormAnnotator(CloudExpert):
    """Attaches FormFeatures (height over width, a handle, an open top, a waist) to every object hypothesis.

    Measures in the supporting plane's frame when there is a Plane, else in the world frame when the camera pose
    is known, else assumes an upright camera (confidences halved).
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis, PointCloud)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (CameraInfo, Plane)
    outputs: ClassVar[tuple[type[CasType], ...]] = (FormFeatures,)
    purpose: ClassVar[str] = "measure the form of"
    capability: ClassVar[Capability] = Capability(
        label="form annotator",
        synonyms=("handle detector",),
        preconditions=("NeedsDepth",),
        cost_ms=35.0,  # per frame: ~20 hypotheses of a RealSense tabletop frame (bench/compare_form.py, loaded)
        reliability=0.7,
    )

    def __init__(self, max_points: int = 3000, name: str | None = None) -> None:
        super().__init__(name=name)
        self.max_points = max_points

    def analyse(self) -> None:
        """Measure each hypothesis; fail when none has enough valid points."""
        cloud = self.usable_cloud()
        hypotheses = self.hypotheses()
        frame = support_frame(usable_plane(self.annotations(Plane)), self.optional_view(CameraInfo))
        flat = cloud.points.reshape(-1, 3)
        scale = 0.5 if frame.guessed else 1.0
        measured = 0
        for hypothesis in hypotheses:
            indices = sampled_indices(cloud, hypothesis, self.max_points)
            grazing = grazing_pixels(cloud.points, indices)
            form = measure_form(frame.points(flat[indices].astype(np.float64)), frame, grazing)
            if form is None:
                continue
            self.attach(
                hypothesis,
                FormFeatures(
                    height_to_width=form.height_to_width,
                    has_handle=form.has_handle,
                    handle_confidence=form.handle_confidence * scale,
                    open_top=form.open_top,
                    open_confidence=form.open_confidence * scale,
                    base_width=None if form.base is None else form.base.base_width,
                    body_width=None if form.base is None else form.base.body_width,
                    waisted=form.waisted,
                    waist_confidence=form.waist_confidence * scale,
                    confidence=scale,
                ),
            )
            measured += 1
        if measured == 0:
            self.fail("no object hypothesis has enough valid points to measure its form")
