"""This checkout's PoseAnnotator against another checkout's (e.g. a worktree of the branch before a change): the
poses of every hypothesis on real frames, compared for equality.

``python bench/compare_pose.py --reference /path/to/other/checkout`` runs the tabletop tree of each checkout in its
own worker process on frames 0-4 of ../shared/data/uoc_tabletop_realsense and on every third of the 45 mOSD learn
scenes (../shared/data/pcl_mosd_tabletop/learn), twice per scene: as recorded (no camera pose: principal boxes in
the camera frame) and with a fixed camera pose (upright boxes in the world frame). It prints, per scene, whether
both trees found the same hypotheses (point indices) and the largest difference of their pose positions (m) and
orientations (quaternion components), and the verdict "equal" / "NOT equal" over all scenes.
"""

from __future__ import annotations

import argparse
import dataclasses
import pickle
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DATA = (ROOT.parent / "shared" / "data").resolve()
UOC = DATA / "uoc_tabletop_realsense"
UOC_FRAMES = range(5)
MOSD = DATA / "pcl_mosd_tabletop" / "learn"
MOSD_SCENES = [f"learn{number}" for number in range(0, 45, 3)]
CAMERA_POSE = np.array(
    [[1.0, 0.0, 0.0, 0.1], [0.0, -0.5, 0.8660254037844386, -0.6], [0.0, -0.8660254037844386, -0.5, 1.2], [0, 0, 0, 1]]
)
"""A camera 1.2 m above the floor looking down at 60 degrees from the vertical (rows: world axes)."""

Result = dict[tuple[str, str], list[tuple[bytes, np.ndarray, np.ndarray, str]]]


def poses_of(checkout: str) -> Result:
    """Per (scene, variant): every hypothesis' point indices (bytes) and pose (position, orientation, frame)."""
    sys.path.insert(0, checkout)
    from annotators.cloud.pose import PoseAnnotator
    from annotators.readers.frame_readers import PcdReader
    from robokudo.core.annotator import Annotator
    from robokudo.core.engine import Engine
    from robokudo.core.types import CameraInfo, ObjectHypothesis, Pose
    from trees.tabletop import create_pipeline, create_tree

    scenes = [(f"uoc {frame}", lambda frame=frame: create_tree(str(UOC), frame)) for frame in UOC_FRAMES]
    scenes += [(scene, lambda scene=scene: create_pipeline(PcdReader(MOSD / f"{scene}.pcd"))) for scene in MOSD_SCENES]
    result: Result = {}
    for name, build in scenes:
        for variant in ("camera", "world"):
            root = build()
            if variant == "world":
                node = next(node for node in root.iterate() if isinstance(node, PoseAnnotator))

                def posed_camera(view_type: type, node: PoseAnnotator = node) -> object:
                    view = Annotator.optional_view(node, view_type)
                    if view_type is CameraInfo and view is not None:
                        return dataclasses.replace(view, cam_to_world=CAMERA_POSE)
                    return view

                node.optional_view = posed_camera  # type: ignore[method-assign]
            Engine(root, hz=1000.0).tick()
            poses = []
            for hypothesis in root.cas.annotations(ObjectHypothesis):
                pose = hypothesis.first(Pose)
                indices = np.asarray(hypothesis.point_indices).tobytes()
                if pose is None:
                    poses.append((indices, np.full(3, np.nan), np.full(4, np.nan), ""))
                else:
                    poses.append((indices, np.asarray(pose.position), np.asarray(pose.orientation), pose.frame))
            result[name, variant] = poses
    return result


def compare(ours: Result, theirs: Result) -> bool:
    """Print the per-scene differences; True when every pose is exactly equal."""
    equal = True
    worst = 0.0
    for key in ours:
        mine, other = ours[key], theirs[key]
        same_hypotheses = [m[0] for m in mine] == [o[0] for o in other]
        frames = [m[3] for m in mine] == [o[3] for o in other]
        positions = max((float(np.max(np.abs(m[1] - o[1]))) for m, o in zip(mine, other, strict=True)), default=0.0)
        orientations = max((float(np.max(np.abs(m[2] - o[2]))) for m, o in zip(mine, other, strict=True)), default=0.0)
        exact = same_hypotheses and frames and positions == 0.0 and orientations == 0.0
        equal &= exact
        worst = max(worst, positions, orientations) if same_hypotheses else float("inf")
        print(
            f"  {key[0]:9s} {key[1]:6s} {len(mine):3d} hypotheses  same hypotheses: {same_hypotheses}  frames: {frames}"
            f"  max |d position| {positions:.3g} m  max |d quaternion| {orientations:.3g}"
            f"  {'equal' if exact else 'differ'}"
        )
    print(f"poses exactly equal: {'equal' if equal else 'NOT equal'}; largest difference {worst:.3g}")
    return equal


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--reference", help="path of the other checkout")
    parser.add_argument("--worker", help=argparse.SUPPRESS)
    parser.add_argument("--out", help=argparse.SUPPRESS)
    arguments = parser.parse_args()
    if arguments.worker:
        with open(arguments.out, "wb") as file:
            pickle.dump(poses_of(arguments.worker), file)
        return
    results = []
    with tempfile.TemporaryDirectory() as folder:
        for index, checkout in enumerate((str(ROOT), arguments.reference)):
            out = str(Path(folder) / f"{index}.pkl")
            command = [sys.executable, __file__, "--worker", checkout, "--out", out]
            subprocess.run(command, check=True, env={"PYTHONPATH": checkout, "PATH": ""})
            with open(out, "rb") as file:
                results.append(pickle.load(file))
    print(f"poses of this checkout vs {arguments.reference}:")
    compare(results[0], results[1])


if __name__ == "__main__":
    main()
