"""A person's own points in an organized cloud, and the person's 3-D position.

**What a person's 3-D position is.** robokudo places a person at the centroid of the person's own visible points:
the surface of the body the sensor sees in this frame, without what stands in front of it (a table's objects,
the table edge) or behind it. Every people detector reports this point, every people test scores against it (the
real-data test computes it from the cloud; the kitchen tests from the renderer's person pixels), and the trackers
filter it. Why this and not a body-model point such as the pelvis:

* it is measured, not inferred: no assumed body depth or build, no guess where hidden legs are; the same point on
  real clouds (clothes, partial views, people cut by the image border) as in the kitchen;
* it is what a robot acts on: the body surface it sees is what it approaches, keeps its distance to, hands
  things to and points its camera at, and the floor point below it lies within half a body depth (10-17 cm,
  towards the robot) of where the person stands;
* it is stable where a robot looks: a person the robot follows or watches is in view, and the point moves with
  the visible part only when the view of the body changes (a table hiding the legs lifts it), which a tracker
  absorbs as it would any measured motion.

**Which points are the person's.** A depth candidate (a column standing on the ground) or the box around the
skeleton holds the person and whatever is in the same image region. The person's points are those connected in
depth to the person's shoulders and head: neighbouring pixels are joined when their depths differ by less than
``step`` (metres, growing with distance); a depth step (the edge of an object in front, the table's far edge
below the body) cuts the region there. The pose detector keeps of them those near the skeleton's bones
(:func:`annotators.image.human_pose.near_skeleton`): a surface the person touches (a door at her pointing hand)
is connected in depth but is not the person.
"""

from __future__ import annotations

import cv2
import numpy as np

SEED_JOINTS: tuple[int, ...] = (0, 11, 12)
"""The mediapipe landmarks the body region grows from: nose, left and right shoulder (rarely hidden by what
stands in front of a person, unlike the hips and hands)."""


def depth_step(depth: float) -> float:
    """The largest depth difference (metres) between neighbouring pixels of one surface at ``depth`` metres:
    a Kinect-class sensor's noise and quantisation grow with distance."""
    return max(0.04, 0.025 * depth)


def body_mask(
    points: np.ndarray, allowed: np.ndarray, pixels: np.ndarray, keypoints: np.ndarray, window: int = 4
) -> np.ndarray | None:
    """The pixels (HxW bool) of the person: within ``allowed``, connected in depth to the seed joints.

    ``points`` is the organized camera-frame cloud (HxWx3, NaN where no depth), ``pixels`` (33x2) and
    ``keypoints`` (33x3) the person's landmarks. A seed is the region holding most pixels within ``window`` of
    a seed landmark whose depth is within one depth step of the landmark's 3-D point. None when no seed lands.
    """
    if points.shape[:2] != allowed.shape or pixels.shape[0] <= max(SEED_JOINTS):
        raise ValueError("the cloud, the allowed mask and the keypoints do not describe one image")
    window_box = _bounding_box(allowed)
    if window_box is None:
        return None
    # regions never join across pixels outside ``allowed``: the work is done in its bounding box only
    top, left, bottom, right_edge = window_box
    inside = _region_mask(
        points[top:bottom, left:right_edge],
        allowed[top:bottom, left:right_edge],
        pixels - (left, top),
        keypoints,
        window,
    )
    if inside is None:
        return None
    mask = np.zeros(allowed.shape, dtype=bool)
    mask[top:bottom, left:right_edge] = inside
    return mask


def _bounding_box(mask: np.ndarray) -> tuple[int, int, int, int] | None:
    """The rows and columns (top, left, bottom, right; exclusive ends) that hold the mask's pixels, or None."""
    rows = np.flatnonzero(mask.any(axis=1))
    if rows.size == 0:
        return None
    cols = np.flatnonzero(mask[rows[0] : rows[-1] + 1].any(axis=0))
    return int(rows[0]), int(cols[0]), int(rows[-1]) + 1, int(cols[-1]) + 1


def _region_mask(
    points: np.ndarray, allowed: np.ndarray, pixels: np.ndarray, keypoints: np.ndarray, window: int
) -> np.ndarray | None:
    """:func:`body_mask` within one window of the image (``pixels`` in the window's coordinates)."""
    rows, cols = allowed.shape
    z = points[..., 2]
    valid = allowed & np.isfinite(z)
    if not valid.any():
        return None
    depth = np.where(valid, z, 0.0).astype(np.float32)
    reference = float(np.median(z[valid]))
    step = np.float32(depth_step(reference))
    joined = valid.copy()
    # cut between neighbours whose depths differ by more than one step (either side of the edge)
    down = np.abs(np.diff(depth, axis=0)) > step
    right = np.abs(np.diff(depth, axis=1)) > step
    joined[:-1] &= ~down
    joined[1:] &= ~down
    joined[:, :-1] &= ~right
    joined[:, 1:] &= ~right
    count, labels = cv2.connectedComponents(joined.astype(np.uint8), connectivity=4)
    if count <= 1:
        return None
    seeds: set[int] = set()
    for joint in SEED_JOINTS:
        u, v = pixels[joint]
        target = keypoints[joint, 2]
        if not (np.isfinite(u) and np.isfinite(v) and np.isfinite(target)):
            continue
        c, r = round(float(u)), round(float(v))
        r0, r1, c0, c1 = max(0, r - window), min(rows, r + window + 1), max(0, c - window), min(cols, c + window + 1)
        if r0 >= r1 or c0 >= c1:
            continue
        patch = labels[r0:r1, c0:c1]
        near = (patch > 0) & (np.abs(z[r0:r1, c0:c1] - target) < depth_step(float(target)))
        if near.any():
            seeds.add(int(np.bincount(patch[near]).argmax()))
    if not seeds:
        return None
    return np.isin(labels, sorted(seeds))


def support_surfaces(
    points: np.ndarray,
    allowed: np.ndarray,
    up: np.ndarray,
    below: float,
    max_tilt_degrees: float = 25.0,
    step: int = 2,
) -> np.ndarray:
    """The pixels (HxW bool) within ``allowed`` that lie on a surface facing up (its normal within
    ``max_tilt_degrees`` of ``up``) lower than ``below`` (a height along ``up``, in the cloud's frame): the top of
    a table or the floor beside a person, which depth connects to the person where the body meets its far edge.
    Normals come from the neighbours ``step`` pixels away on either side (NaN where one is missing: not cut)."""
    cut = np.zeros(allowed.shape, dtype=bool)
    box = _bounding_box(allowed)
    if box is None:
        return cut
    top, left, bottom, right = box
    top, left = max(0, top - step), max(0, left - step)
    bottom, right = min(allowed.shape[0], bottom + step), min(allowed.shape[1], right + step)
    window = points[top:bottom, left:right].astype(np.float32)
    if window.shape[0] <= 2 * step or window.shape[1] <= 2 * step:
        return cut
    across = window[step:-step, 2 * step :] - window[step:-step, : -2 * step]  # along the rows (u)
    down = window[2 * step :, step:-step] - window[: -2 * step, step:-step]  # along the columns (v)
    normal = np.cross(across, down)
    direction = (up / np.linalg.norm(up)).astype(np.float32)
    centre = window[step:-step, step:-step]
    with np.errstate(invalid="ignore"):
        length = np.linalg.norm(normal, axis=-1)
        facing = np.abs(normal @ direction) > np.cos(np.radians(max_tilt_degrees)) * length
        low = centre @ direction < below
    inner = facing & low & (length > 0)
    cut[top + step : bottom - step, left + step : right - step] = inner
    return cut & allowed


def centroid(points: np.ndarray, mask: np.ndarray) -> np.ndarray | None:
    """The mean of the valid points under ``mask`` (the person's position, see the module), or None."""
    box = _bounding_box(mask)
    if box is None:
        return None
    top, left, bottom, right = box
    chosen = points[top:bottom, left:right][mask[top:bottom, left:right]]
    chosen = chosen[np.isfinite(chosen[:, 2])]
    return chosen.mean(axis=0, dtype=np.float64) if chosen.shape[0] else None
