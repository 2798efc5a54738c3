"""The form expert's waist ratio (annotators.cloud.form.waist_ratio) of labelled real objects: how much narrower the
middle of an object's height is than its top and its bottom.

Two sets, read in place from ../shared/data:

* the hand-labelled objects of the uoc RealSense frames (tests/data/labels/guard_objects.json), each measured on
  the default clutter segmenter's segment at its label pixel (what the form expert gets in a query);
* every object of the 45 labelled mOSD learn scenes, measured on its ground-truth points (no segmenter involved).

Printed per object, lowest ratio first, with the verdict at ``WAIST_RATIO``; run from the repository root:
``python bench/measure_waists.py``. The figures of the session that added the cue are in
bench/profiles/waist-analysis.txt.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from annotators.cloud.clutter import ClutterParameters  # noqa: E402
from annotators.cloud.form import WAIST_RATIO, waist_ratio  # noqa: E402
from annotators.geometry.support_frame import SupportFrame, plane_frame  # noqa: E402
from annotators.readers.pcd_io import read_pcd  # noqa: E402
from reasoning.evaluation.mosd import object_labels, scene_category  # noqa: E402
from reasoning.evaluation.object_verdicts import load_labelled_objects  # noqa: E402
from tests.annotators.guard_frames import LABELS, frame_points, segment_points, support_plane  # noqa: E402

MOSD = ROOT.parent / "shared" / "data" / "pcl_mosd_tabletop" / "learn"


def upright_ratio(points: np.ndarray, model: np.ndarray) -> float | None:
    """The waist ratio of an object's Nx3 camera points standing on the plane ``model``, measured as the form
    expert does (in the plane's frame, bottom on the plane, top at the 98 % height)."""
    upright = SupportFrame(plane_frame(model), on_plane=True, guessed=False).points(points)
    measured = waist_ratio(upright, 0.0, float(np.quantile(upright[:, 2], 0.98)))
    return None if measured is None else measured[0]


def guard_objects() -> list[tuple[float, str]]:
    """(ratio, description) of every labelled uoc object, on the default segmenter's segment."""
    rows = []
    for (input_name, index), objects in load_labelled_objects(LABELS).items():
        points, colors = frame_points(input_name, index)
        labels = segment_points(points, colors, ClutterParameters())
        model = np.asarray(support_plane(points)[1].model, dtype=np.float64)
        for labelled in objects:
            x, y = labelled.pixel
            if not labels[y, x]:
                continue
            own = points[labels == labels[y, x]]
            ratio = upright_ratio(own[np.isfinite(own).all(axis=1)].astype(np.float64), model)
            if ratio is not None:
                rows.append((ratio, f"{Path(input_name).stem}#{index} {labelled.name}"))
    return rows


def mosd_objects() -> list[tuple[float, str]]:
    """(ratio, description) of every object of the mOSD learn scenes, on its ground-truth points."""
    rows = []
    for path in sorted(MOSD.glob("*.pcd"), key=lambda p: int(p.stem.removeprefix("learn"))):
        frame = read_pcd(path)
        points = np.ascontiguousarray(frame.points, dtype=np.float32)
        truth = object_labels(frame.labels)
        model = np.asarray(support_plane(points)[1].model, dtype=np.float64)
        for number in np.unique(truth[truth > 0]):
            own = points[truth == number]
            own = own[np.isfinite(own).all(axis=1)]
            if own.shape[0] < 200:
                continue
            ratio = upright_ratio(own.astype(np.float64), model)
            if ratio is not None:
                rows.append((ratio, f"{path.stem} ({scene_category(path.stem)}) object {number}"))
    return rows


def main() -> None:
    sets = (("uoc labelled objects (default segments)", guard_objects()), ("mOSD learn objects", mosd_objects()))
    for title, rows in sets:
        rows.sort()
        waisted = sum(ratio < WAIST_RATIO for ratio, _ in rows)
        print(f"{title}: {len(rows)} measured, {waisted} waisted (ratio < {WAIST_RATIO})")
        for ratio, name in rows:
            print(f"  {ratio:5.2f} {'waisted' if ratio < WAIST_RATIO else '       '} {name}")


if __name__ == "__main__":
    main()
