"""Colour names of this checkout vs another revision on the same objects: how many names a change moves.

The objects: the hand-labelled colour test set (tests/data/colors/real_colors.json) named from 300, 1000 and 3000
pixels each, and the hypotheses the tabletop tree finds on uoc frames 0-4 and on every fifth mOSD learn scene,
named as SemanticColorAnnotator names them (all of a frame at once). The hypotheses are found once, by this
checkout's tree, and both revisions name the same pixels; each revision runs in its own worker process with its
own checkout first on the path.

    python bench/color_agreement.py --reference main
"""

from __future__ import annotations

import argparse
import io
import json
import pickle
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"
UOC_FRAMES = range(5)
MOSD_STEP = 5
PIXEL_COUNTS = (300, 1000, 3000)


def find_hypotheses(path: Path) -> None:
    """Ticks this checkout's tabletop tree on the frames and pickles (tag, image, [(mask, roi)]) to ``path``."""
    sys.path.insert(0, str(ROOT))
    from annotators.readers.frame_readers import PcdReader
    from robokudo.core.engine import Engine
    from robokudo.core.types import ColorImage, ObjectHypothesis
    from trees.tabletop import create_pipeline, create_tree

    found = []
    roots = [(f"uoc{f}", create_tree(str(DATA / "uoc_tabletop_realsense"), f)) for f in UOC_FRAMES]
    scenes = sorted((DATA / "pcl_mosd_tabletop" / "learn").glob("*.pcd"))[::MOSD_STEP]
    roots += [(scene.stem, create_pipeline(PcdReader(scene))) for scene in scenes]
    for tag, root in roots:
        Engine(root, hz=1000.0).tick()
        hypotheses = [(h.mask.copy(), tuple(int(v) for v in h.roi)) for h in root.cas.annotations(ObjectHypothesis)]
        found.append((tag, root.cas.view(ColorImage).image.copy(), hypotheses))
    path.write_bytes(pickle.dumps(found))


def name_all(checkout: str, hypotheses_path: str) -> None:
    """Worker: the names (and shares, confidences) ``checkout`` gives every object, as one JSON object."""
    sys.path.insert(0, checkout)
    import numpy as np

    from annotators.image.color import SemanticColorAnnotator, name_objects_colors
    from annotators.image.color_surfaces import objects_pixels
    from annotators.image.white_balance import estimate_frame_light
    from robokudo.core.types import ObjectHypothesis
    from tests.annotators.color_set import load_frame, load_samples, sample_mask

    def described(colors: tuple) -> list:
        return [[c.name, round(c.share, 3), round(c.confidence, 3)] for c in colors]

    names: dict[str, list] = {}
    for sample in load_samples():
        frame = load_frame(sample.input, sample.frame)
        mask = sample_mask(sample, frame)
        ys, xs = np.nonzero(mask)
        roi = (int(xs.min()), int(ys.min()), int(xs.max()) + 1, int(ys.max()) + 1)
        hypothesis = ObjectHypothesis(point_indices=np.flatnonzero(mask), mask=mask, roi=roi)
        light = estimate_frame_light(frame.color)
        for count in PIXEL_COUNTS:
            picked = objects_pixels(frame.color, [hypothesis], count)
            names[f"labelled, {count} pixels: {sample.key}"] = described(name_objects_colors(picked, light)[0])
    max_pixels = SemanticColorAnnotator().max_pixels
    for tag, image, found in pickle.loads(Path(hypotheses_path).read_bytes()):
        hypotheses = [ObjectHypothesis(point_indices=np.empty(0, int), mask=m, roi=r) for m, r in found]
        picked = [p for p in objects_pixels(image, hypotheses, max_pixels) if p[0].shape[0]]
        for index, colors in enumerate(name_objects_colors(picked, estimate_frame_light(image))):
            names[f"tree hypotheses: {tag}#{index}"] = described(colors)
    print(json.dumps(names))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", required=True, help="git revision to compare this checkout's names with")
    arguments = parser.parse_args()
    with tempfile.TemporaryDirectory() as folder:
        archive = subprocess.run(
            ["git", "-C", str(ROOT), "archive", arguments.reference], check=True, capture_output=True
        )
        reference = Path(folder) / "reference"
        reference.mkdir()
        with tarfile.open(fileobj=io.BytesIO(archive.stdout)) as tar:
            tar.extractall(reference, filter="data")
        (Path(folder) / "shared").symlink_to(DATA.parent)  # tests find ../shared/data beside the checkout
        hypotheses = Path(folder) / "hypotheses.pickle"
        find_hypotheses(hypotheses)
        results = {}
        for label, checkout in (("ours", str(ROOT)), ("reference", str(reference))):
            run = [sys.executable, __file__, "--worker", checkout, str(hypotheses)]
            results[label] = json.loads(subprocess.run(run, check=True, capture_output=True, text=True).stdout)
    ours, theirs = results["ours"], results["reference"]
    groups: dict[str, list[int]] = {}
    largest = 0.0
    for key, colors in theirs.items():
        group = key.split(":")[0]
        total_changed = groups.setdefault(group, [0, 0])
        total_changed[0] += 1
        mine = ours[key]
        if [c[0] for c in mine] != [c[0] for c in colors]:
            total_changed[1] += 1
            print(f"  changed {key}: {colors} -> {mine}")
            continue
        for a, b in zip(mine, colors, strict=True):
            largest = max(largest, abs(a[1] - b[1]), abs(a[2] - b[2]))
    print(f"colour names of this checkout vs {arguments.reference}:")
    for group, (total, changed) in groups.items():
        print(f"  {group:32s} {changed}/{total} objects named differently")
    print(f"  largest share or confidence difference where the names agree: {largest:.3f}")


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--worker":
        name_all(sys.argv[2], sys.argv[3])
    else:
        main()
