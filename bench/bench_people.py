"""Benchmark of the people detectors on the real five_people.pcd frame (../shared/data/pcl_people).

Side by side in one run: the depth-only people detector and the human pose detector (mediapipe pose on a crop
around every depth candidate), ms per frame (median of the runs after a warm-up), people found, and each
person's distance between the reported position and the centroid of the cloud points its keypoints span
(the reference of tests/annotators/test_people_real.py).

Run: ``.venv/bin/python bench/bench_people.py [--runs N]``
"""

from __future__ import annotations

import argparse
import statistics
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from annotators.cloud.people import DepthPeopleDetector  # noqa: E402
from annotators.image.human_pose import HumanPoseDetector  # noqa: E402
from annotators.readers.frame_readers import PcdReader  # noqa: E402
from robokudo.core.annotator import Annotator  # noqa: E402
from robokudo.core.engine import Engine  # noqa: E402
from robokudo.core.pipeline import Pipeline  # noqa: E402
from robokudo.core.types import BodyKeypoints, PersonHypothesis, Pose  # noqa: E402
from tests.annotators.test_people_real import reference_centroid  # noqa: E402

FRAME = ROOT.parent / "shared" / "data" / "pcl_people" / "five_people.pcd"


def measure(detector: Annotator, runs: int) -> tuple[float, list[PersonHypothesis], np.ndarray]:
    """Median ms of the detector alone per frame (the reader's time excluded), its people and the cloud."""
    reader = PcdReader(FRAME)
    root = Pipeline("people", [reader, detector])
    engine = Engine(root)
    engine.tick()  # warm-up: loads the model
    times = []
    for _ in range(runs):
        engine.tick()
        times.append(detector.stats.last_seconds * 1000)
    return statistics.median(times), root.cas.annotations(PersonHypothesis), reader.last_frame.points


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=5)
    runs = parser.parse_args().runs
    print(f"{'detector':<22} {'ms/frame':>9} {'people':>7}  position error vs keypoint-column centroid (cm)")
    for detector in (DepthPeopleDetector(), HumanPoseDetector()):
        ms, people, points = measure(detector, runs)
        errors = []
        for person in people:
            keypoints = person.first(BodyKeypoints)
            if keypoints is not None:
                errors.append(np.linalg.norm(person.first(Pose).position - reference_centroid(points, keypoints)))
        shown = ", ".join(f"{e * 100:.1f}" for e in errors) if errors else "(no keypoints)"
        print(f"{detector.name:<22} {ms:>9.1f} {len(people):>7}  {shown}")


if __name__ == "__main__":
    main()
