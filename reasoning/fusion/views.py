"""Repeated views: when a sighting shows an object as the belief's last sighting did (one piece of evidence, not two).

A sighting *repeats* the belief's last view when it comes from the same recording, its position is in the same frame
(the same camera, or the world when the camera pose is known) and the object covers the same place in the image up
to segmentation jitter: the intersection over union of the two image boxes is at least :data:`SAME_BOX_IOU`. A
camera that moved, or an object that moved, moves the box in the image; another recording is another occasion.
Experts that look at the same pixels again say what they said before, so their statements are dependent evidence
(:meth:`reasoning.fusion.rule.ValueSupport.repeat`) and do not accumulate like independent views.

The belief's recording is the one it was first seen in: a sighting in another recording never repeats (its
statements count as new views, as every statement did before repeats were told apart).
"""

from __future__ import annotations

SAME_BOX_IOU: float = 0.8
"""Least intersection over union of two image boxes of one view. A box shifted by a tenth of its width (or by 5 % of
its size along both axes) keeps IoU 0.82: the segmentation jitter of an object seen again from (nearly) the same
place. Measured on the three real PCL grabber frames (a hand-held Kinect drifting under a degree between frames,
0.25 s apart): the three whole objects keep IoU 0.84-0.94 from frame to frame (one view); objects cut by the image
border, whose boxes the border and the segmentation change, fall to 0.55-0.69 and count as new views (as every view
did before). A camera turned or moved to look elsewhere, or an object moved by more than a tenth of its size across
the line of sight, falls below it."""


def box_iou(a: tuple[int, int, int, int], b: tuple[int, int, int, int]) -> float:
    """Intersection over union of two image boxes ``(x0, y0, x1, y1)`` (0 when either is empty)."""
    ax0, ay0, ax1, ay1 = a
    bx0, by0, bx1, by1 = b
    w = min(ax1, bx1) - max(ax0, bx0)
    h = min(ay1, by1) - max(ay0, by0)
    if w <= 0 or h <= 0:
        return 0.0
    inter = w * h
    union = (ax1 - ax0) * (ay1 - ay0) + (bx1 - bx0) * (by1 - by0) - inter
    return inter / union if union > 0 else 0.0


def repeats_view(
    last_roi: tuple[int, int, int, int] | None,
    last_frame: str,
    last_recording: str,
    roi: tuple[int, int, int, int] | None,
    frame: str,
    recording: str,
) -> bool:
    """True when a sighting (``roi`` in ``frame`` of ``recording``) repeats the belief's last view (see the module
    docstring); never when either image box is unknown."""
    if roi is None or last_roi is None or frame != last_frame or recording != last_recording:
        return False
    return roi == last_roi or box_iou(last_roi, roi) >= SAME_BOX_IOU
