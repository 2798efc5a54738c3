"""Issue 15, item 6: the TUM teacup on its saucer measured against the sensor's resolution (form9-analysis.txt).

    PYTHONPATH=. python bench/experiments/form9_teacup.py

Runs "find all objects" on the shared TUM frame, takes the hypothesis at the teacup and prints: the camera's height
and the cup's range in the support frame, the Kinect's depth step (``2.85e-3 * z^2``) and lateral pixel size there,
the hypothesis' points row by row (depth, heights), the body's extents across and along the line of sight, with and
without the handle's image columns, the form expert's handle evidence on the body, and what-if scores: the
teacup's cues against every class profile, with a hypothetical teacup kind and with the handle taken as seen.
"""

from __future__ import annotations

import dataclasses
import os
import tempfile
from pathlib import Path

import numpy as np

from annotators.classification import knowledge_classifier as kc
from annotators.cloud.base_layer import find_base
from annotators.cloud.form import foot_circle_handle, profile_handle
from annotators.geometry.support_frame import support_frame, usable_plane
from reasoning.planning.query_planner import class_profiles
from robokudo.application.service import AnsweringService
from robokudo.core.types import CameraInfo, ObjectHypothesis, Plane, PointCloud

TUM = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "tum_rgbd_sample_open3d"
CUP_PIXEL = (485, 215)
"""A pixel on the teacup's wall (x, y)."""
BODY_COLUMNS = 495
"""The last image column of the cup's body: columns 496-502 show the handle (looked at in the colour image)."""
FX = 525.0
QUANTISATION = 2.85e-3
"""Kinect v1 depth step = this * z^2 (metres)."""


def probe() -> None:
    """Print the measurements and the what-if scores (see the module docstring)."""
    tmp = Path(tempfile.mkdtemp())
    os.environ["ROBOKUDO_USER_ONTOLOGY"] = str(tmp / "user.ttl")
    with AnsweringService.open(tmp / "beliefs.sqlite", input_path=str(TUM)) as service:
        cas = service.answer("find all objects").tree.cas
        profiles = [dict(p) for p in class_profiles(service.kb)]
    x, y = CUP_PIXEL
    cup = max(cas.annotations(ObjectHypothesis), key=lambda h: int(h.mask[y - 2 : y + 3, x - 2 : x + 3].sum()))
    cloud = cas.view(PointCloud)
    camera = cas.view(CameraInfo)
    frame = support_frame(usable_plane(cas.annotations(Plane)), camera)
    rows, cols = np.nonzero(cup.mask)
    depth = cloud.points[rows, cols, 2].astype(np.float64)
    valid = np.isfinite(depth) & (depth > 0)
    rows, cols, depth = rows[valid], cols[valid], depth[valid]
    points = frame.points(cloud.points[rows, cols].astype(np.float64))
    eye = frame.camera_to_frame[:3, 3]
    centre = np.median(points[:, :2], axis=0)
    horizontal = float(np.linalg.norm(centre - eye[:2]))
    z = float(np.median(depth))
    print(f"camera {eye[2]:.3f} m above the support; cup {horizontal:.3f} m away horizontally, depth {z:.3f} m")
    print(f"  elevation of the lines of sight {np.degrees(np.arctan2(eye[2], horizontal)):.1f} deg")
    print(f"  depth step {100 * QUANTISATION * z * z:.2f} cm; lateral {1000 * z / FX:.2f} mm per pixel")
    print("row  n  columns  depth(m)  height(cm)")
    for row in range(rows.min(), rows.max() + 1):
        on = rows == row
        if on.any():
            h = 100 * points[on, 2]
            print(
                f"{row} {on.sum():3d} {cols[on].min()}-{cols[on].max()} {np.median(depth[on]):.3f}"
                f" {h.min():.1f}..{h.max():.1f}"
            )
    bottom = 0.0
    height = float(np.quantile(points[:, 2], 0.98))
    base = find_base(points, bottom, height)
    step = base.step if base is not None else 0.0
    body = points[:, 2] >= step
    print(f"base step {100 * step:.1f} cm; body points {body.sum()}, top (98 %) {100 * height:.2f} cm")
    away = (centre - eye[:2]) / horizontal
    across = np.array([-away[1], away[0]])

    def extent(values: np.ndarray) -> float:
        low, high = np.quantile(values, (0.02, 0.98))
        return float(high - low)

    no_handle = body & (cols <= BODY_COLUMNS)
    print(
        f"extent across the line of sight {100 * extent(points[body, :2] @ across):.1f} cm"
        f" (without the handle's columns {100 * extent(points[no_handle, :2] @ across):.1f} cm);"
        f" along it {100 * extent(points[body, :2] @ away):.1f} cm"
    )
    print(
        "handle evidence on the body: foot circle",
        foot_circle_handle(points[body], step, height - step),
        "profile",
        profile_handle(points[body], step, height - step),
    )
    cues = kc.KnowledgeClassifier().cues(cup)
    print(cues)
    cup_profile = next(p for p in profiles if p["class"] == "Cup")

    def what_if(extra: list[dict[str, object]], seen: kc.Cues, label: str) -> None:
        matches = sorted((kc.score(kc.Profile.from_mapping(p), seen) for p in profiles + extra), key=lambda m: -m.score)
        decision = kc.decide(matches, expected="Cup", cues=seen)
        top = ", ".join(f"{m.profile.class_name} {m.score:.3f}" for m in matches[:5])
        print(f"{label}: {decision.class_name} {decision.confidence:.2f} | {top}")

    with_handle = dataclasses.replace(cues, handle=(True, 1.0))
    what_if([], cues, "as measured")
    what_if([], with_handle, "handle seen")
    for low, high in ((0.4, 0.65), (0.5, 0.85)):
        teacup = dict(cup_profile)
        teacup.update(
            {
                "class": "Teacup",
                "handle": True,
                "height_to_width": (low, high),
                "ancestors": ("Teacup", *cup_profile["ancestors"]),  # type: ignore[misc]
            }
        )
        what_if([teacup], cues, f"teacup kind {low}-{high}")
        what_if([teacup], with_handle, f"teacup kind {low}-{high}, handle seen")


if __name__ == "__main__":
    probe()
