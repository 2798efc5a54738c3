"""The form expert of this tree against another tree's (e.g. a detached worktree of main): cues and time per frame.

Three steps, each a subcommand:

    python bench/compare_form.py dump INPUTS.pkl        # the experts' inputs: uoc frames 0-4, every 3rd mOSD learn
    python bench/compare_form.py measure INPUTS.pkl OUT.pkl   # run with PYTHONPATH at the tree to measure
    python bench/compare_form.py compare INPUTS.pkl /other/tree [rounds]   # both trees, alternating, side by side

``dump`` runs "find all objects" on each frame and keeps what the FormAnnotator reads: the organised cloud, each
hypothesis' sampled indices and the support frame. ``measure`` runs the per-frame work of the FormAnnotator on them
(``measure_forms`` where the tree has it, else the annotator's loop body; the first frame once untimed
before) and stores every Form and the seconds per
frame. ``compare`` prints, per tree, the median ms per frame, their ratio (goal: >= 2x), and whether every
hypothesis' cues (handle and open top, with their confidences) are bit-identical.
"""

from __future__ import annotations

import os
import pickle
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, os.environ.get("PYTHONPATH", "").split(os.pathsep)[0] or str(ROOT))

import numpy as np  # noqa: E402

DATA = (ROOT.parent / "shared" / "data").resolve()
MAX_POINTS = 3000
"""The FormAnnotator's default ``max_points``."""


def frames() -> list[tuple[str, int]]:
    """(input path, frame) of the compared frames."""
    uoc = [(str(DATA / "uoc_tabletop_realsense"), n) for n in range(5)]
    learn = sorted((DATA / "pcl_mosd_tabletop" / "learn").glob("learn*.pcd"), key=lambda p: int(p.stem[5:]))
    return uoc + [(str(p), 0) for p in learn[::3]]


def dump(target: Path) -> None:
    """Store the FormAnnotator's inputs of every compared frame."""
    from annotators.geometry.support_frame import sampled_indices, support_frame, usable_plane
    from robokudo.application.service import AnsweringService
    from robokudo.core.types import CameraInfo, ObjectHypothesis, Plane, PointCloud

    inputs = []
    with tempfile.TemporaryDirectory() as tmp:
        os.environ.setdefault("ROBOKUDO_USER_ONTOLOGY", str(Path(tmp) / "user.ttl"))
        for number, (path, frame) in enumerate(frames()):
            with AnsweringService.open(Path(tmp) / f"{number}.sqlite", input_path=path, frame=frame) as service:
                cas = service.answer("find all objects").tree.cas
            cloud = cas.view(PointCloud)
            frame_ = support_frame(usable_plane(cas.annotations(Plane)), cas.view(CameraInfo))
            indices = [sampled_indices(cloud, h, MAX_POINTS) for h in cas.annotations(ObjectHypothesis)]
            inputs.append(
                {"name": f"{Path(path).name}#{frame}", "points": cloud.points, "indices": indices, "frame": frame_}
            )
            print(f"{Path(path).name}#{frame}: {len(indices)} hypotheses", file=sys.stderr)
    target.write_bytes(pickle.dumps(inputs))


def measure(source: Path, target: Path) -> None:
    """Run this tree's form expert on the stored inputs: its Forms and seconds per frame."""
    import annotators.cloud.form as form

    inputs = pickle.loads(source.read_bytes())
    results, seconds = [], []
    for entry in [inputs[0], *inputs]:  # the first round untimed: imports, compiled code loaded
        start = time.perf_counter()
        if hasattr(form, "measure_forms"):
            forms = form.measure_forms(entry["points"], entry["indices"], entry["frame"])
        else:
            flat = entry["points"].reshape(-1, 3)
            forms = []
            for indices in entry["indices"]:
                grazing = form.grazing_pixels(entry["points"], indices)
                forms.append(
                    form.measure_form(entry["frame"].points(flat[indices].astype(np.float64)), entry["frame"], grazing)
                )
        seconds.append(time.perf_counter() - start)
        results.append(
            [
                None
                if f is None
                else (f.height_to_width, f.has_handle, f.handle_confidence, f.open_top, f.open_confidence)
                for f in forms
            ]
        )
    target.write_bytes(pickle.dumps({"tree": form.__file__, "forms": results[1:], "seconds": seconds[1:]}))


def compare(source: Path, other: Path, rounds: int) -> None:
    """Both trees' experts, alternating rounds; prints ms per frame and whether the cues are identical."""
    runs: dict[str, list[dict]] = {"this": [], "other": []}
    with tempfile.TemporaryDirectory() as tmp:
        for number in range(rounds):
            for name, tree in (("this", ROOT), ("other", other)):
                out = Path(tmp) / f"{name}{number}.pkl"
                env = {**os.environ, "PYTHONPATH": str(tree)}
                subprocess.run(
                    [sys.executable, str(Path(__file__).resolve()), "measure", str(source), str(out)],
                    env=env,
                    check=True,
                )
                runs[name].append(pickle.loads(out.read_bytes()))
    per_frame = {
        name: [statistics.median(r["seconds"][i] for r in rs) * 1000 for i in range(len(rs[0]["seconds"]))]
        for name, rs in runs.items()
    }
    names = [entry["name"] for entry in pickle.loads(source.read_bytes())]
    print(f"{'frame':24} {'this ms':>8} {'other ms':>9}  hypotheses")
    ours, theirs = runs["this"][0]["forms"], runs["other"][0]["forms"]
    same = total = 0
    for i, name in enumerate(names):
        print(f"{name:24} {per_frame['this'][i]:8.1f} {per_frame['other'][i]:9.1f}  {len(ours[i])}")
        for a, b in zip(ours[i], theirs[i], strict=True):
            total += 1
            same += a == b
            if a != b:
                print(f"    differs: {a} vs {b}")
    mean_this, mean_other = statistics.mean(per_frame["this"]), statistics.mean(per_frame["other"])
    speedup = mean_other / mean_this
    print(f"trees: this {runs['this'][0]['tree']}, other {runs['other'][0]['tree']}; load {os.getloadavg()[0]:.2f}")
    print(
        f"mean ms per frame: this {mean_this:.1f}, other {mean_other:.1f}: {speedup:.2f}x "
        f"(goal >= 2x: {'met' if speedup >= 2.0 else 'NOT met'})"
    )
    uoc = [i for i, name in enumerate(names) if name.startswith("uoc")]
    print(
        f"uoc frames: this {statistics.mean(per_frame['this'][i] for i in uoc):.1f} ms, "
        f"other {statistics.mean(per_frame['other'][i] for i in uoc):.1f} ms per frame"
    )
    print(f"identical cues: {same}/{total} hypotheses ({'met' if same == total else 'NOT met'})")


def main() -> None:
    command, *arguments = sys.argv[1:]
    if command == "dump":
        dump(Path(arguments[0]))
    elif command == "measure":
        measure(Path(arguments[0]), Path(arguments[1]))
    elif command == "compare":
        compare(Path(arguments[0]), Path(arguments[1]), int(arguments[2]) if len(arguments) > 2 else 3)
    else:
        raise SystemExit(__doc__)


if __name__ == "__main__":
    main()
