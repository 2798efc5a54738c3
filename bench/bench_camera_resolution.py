"""The clutter segmenter on cameras of other image sizes: the 45 labelled mOSD learn scenes (Kinect, 640x480) seen
through finer pixels (1280x960: each pixel repeated 2x2, focal length doubled) and coarser ones (320x240: every other
pixel, focal length halved), through the camera rolled about its axis by 90, 180 and 270 degrees and through a
noisier sensor (Gaussian noise along each ray of 2 or 4 mm x z^2 on top of the Kinect's own, about 1.6), scored as
``robokudo eval segmentation`` scores them, per category.

    python bench/bench_camera_resolution.py

Two segmenters side by side in one run, on the same resampled frames: the ClutterSegmenter as it is (its grid stride
follows the camera's pixel angle, ``ClutterParameters.for_camera``) and with the stride fixed at 2 whatever the camera
(``reference_focal=0``). Both are identical at 640x480. Also the median time of the tree's front and segmenter per
scene (reading excluded). The pixels' repetition adds no detail a real finer camera would see: this measures that
the thresholds scale with the camera, not how a real 1280x960 sensor's noise behaves. A roll changes no stride: both
segmenters answer alike there, and what moves is where the grid's cells fall on the objects and which way ties in
the growth from seeds break.
"""

from __future__ import annotations

import statistics
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from annotators.cloud.clutter import ClutterSegmenter  # noqa: E402
from annotators.readers.frame_io import Frame  # noqa: E402
from annotators.readers.frame_readers import PcdReader  # noqa: E402
from reasoning.evaluation.mosd import object_labels, scene_category  # noqa: E402
from reasoning.evaluation.segmentation import SegmentationScore, score_segmentation, summarize  # noqa: E402
from tests.annotators.camera_resampling import GivenFrame, noisier, resampled, rolled  # noqa: E402
from trees.segmenters import with_front  # noqa: E402

MOSD = (ROOT.parent / "shared" / "data" / "pcl_mosd_tabletop" / "learn").resolve()
CAMERAS = (
    {"640x480": (1, True, 0, 0.0), "1280x960": (2, True, 0, 0.0), "320x240": (2, False, 0, 0.0)}
    | {f"roll {90 * turns}": (1, True, turns, 0.0) for turns in (1, 2, 3)}
    | {f"noise {mm:g} mm": (1, True, 0, mm) for mm in (2.0, 4.0)}
)
"""Each camera: (resampling factor, finer, quarter turns of roll, added noise in mm at 1 m)."""
SEGMENTERS = {
    "follows the camera": with_front(ClutterSegmenter),
    "stride fixed at 2": with_front(lambda: ClutterSegmenter(reference_focal=0.0)),
}
CATEGORIES = ("boxes", "stacked", "occluded", "cylindric")


def camera_view(frame: Frame, camera: str) -> Frame:
    factor, finer, turns, noise = CAMERAS[camera]
    seen = frame if factor == 1 else resampled(frame, factor, finer)
    seen = rolled(seen, turns) if turns else seen
    return noisier(seen, noise) if noise else seen


def main() -> None:
    files = sorted(MOSD.glob("learn*.pcd"), key=lambda p: int(p.stem[5:]))
    scores: dict[tuple[str, str], dict[str, list[SegmentationScore]]] = defaultdict(lambda: defaultdict(list))
    seconds: dict[tuple[str, str], list[float]] = defaultdict(list)
    for path in files:
        recorded = PcdReader(path).load()
        for camera in CAMERAS:
            frame = camera_view(recorded, camera)
            truth = object_labels(frame.labels)
            valid = np.isfinite(frame.points[..., 2])
            for name, segment in SEGMENTERS.items():
                segmented = segment(GivenFrame(frame))
                score = score_segmentation(truth, segmented.labels, valid)
                scores[camera, name][scene_category(path)].append(score)
                seconds[camera, name].append(segmented.seconds)
    print(
        f"mOSD learn ({len(files)} scenes) through other cameras: object recall / precision at box IoU >= 0.5 / "
        "overlap F; front + segmenter median ms per scene"
    )
    header = " | ".join(f"{c:>17}" for c in (*CATEGORIES, "all"))
    print(f"{'camera':10} {'segmenter':19} | {header} | ms")
    for camera in CAMERAS:
        for name in SEGMENTERS:
            per = scores[camera, name]
            cells = [summarize(per[c]) for c in CATEGORIES] + [summarize([s for c in CATEGORIES for s in per[c]])]
            row = " | ".join(f"{s.recall:.2f} / {s.precision:.2f} / {s.overlap_f:.3f}" for s in cells)
            print(f"{camera:10} {name:19} | {row} | {statistics.median(seconds[camera, name]) * 1000:.0f}")


if __name__ == "__main__":
    main()
