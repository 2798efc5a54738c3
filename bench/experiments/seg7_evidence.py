"""Evidence for seg7 (bench/profiles/seg7-analysis.txt): the tinted-transparent join and the neck rule held out.

1. ``shares``: every group of touching, like-tinted pieces the transparency step measures on the 57 guard inputs of
   bench/check_clutter_labels.py, with its share of holes of its tint (the step joins at 0.1 and above).
2. ``necks``: every pair the neck rule (annotators/geometry/necks.py) looks at on the shared scenes it was not
   chosen on (pcl_grabber_sequences frames 0-2, the two coloured pcl_tabletop_pcd clouds, the TUM desk), with
   the neck / width ratio and whether it joined. An overlay of each pair goes to ``--out`` for hand labelling:
   upper piece red, lower piece blue, the colour image beside it.

Run from the repository root: ``PYTHONPATH=$PWD python bench/experiments/seg7_evidence.py [shares|necks]``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import cv2
import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

import annotators.cloud.clutter as clutter  # noqa: E402
import annotators.geometry.necks as necks  # noqa: E402
import annotators.geometry.transparency as transparency  # noqa: E402

DATA = ROOT.parent / "shared" / "data"
HELD_OUT = [(DATA / "pcl_grabber_sequences", index, f"grabber{index}") for index in range(3)] + [
    (DATA / "pcl_tabletop_pcd" / "milk_cartoon_all_small_clorox.pcd", 0, "clorox"),
    (DATA / "pcl_tabletop_pcd" / "table_scene_mug_stereo_textured.pcd", 0, "mug stereo"),
    (DATA / "tum_rgbd_sample_open3d", 0, "tum"),
]


def shares() -> None:
    """Print the hole share of every like-tinted group on the guard inputs, largest first."""
    from bench.check_clutter_labels import prepare

    measured: list[tuple[str, int, int, float]] = []
    current = [""]
    original = transparency.hole_share

    def logged(labels, group, holes, chroma, rules, box=None):
        share = original(labels, group, holes, chroma, rules, box)
        measured.append((current[0], len(group), int(np.isin(labels, group).sum()), share))
        return share

    transparency.hole_share = logged
    # no pre-check: every group's share is measured (the joins then differ, the shares do not)
    clutter.TransparencyRules = lambda: transparency.TransparencyRules(hole_share=0.0)
    with tempfile.TemporaryDirectory() as folder:
        names = prepare(Path(folder))
        for name in names:
            current[0] = name
            data = np.load(Path(folder) / f"{name}.npz")
            clutter.segment_clutter(
                data["points"], data["mask"], data["model"], data["plane"], clutter.ClutterParameters(), data["colors"]
            )
    for name, pieces, pixels, share in sorted(measured, key=lambda entry: -entry[3]):
        print(f"{name:36s} {pieces} pieces {pixels:5d} grid px  hole share {share:.3f}")
    print(f"{len({entry[0] for entry in measured})} of {len(names)} inputs have a like-tinted group")


def neck_pairs(out: Path) -> None:
    """Print every pair the neck rule looks at on the held-out scenes; write an overlay of each to ``out``."""
    from py_trees.common import Status

    from annotators.readers.choice import reader_for
    from robokudo.core.engine import Engine
    from robokudo.core.types import ColorImage
    from trees.tabletop import create_pipeline

    out.mkdir(parents=True, exist_ok=True)
    seen: list[tuple] = []
    box: dict[str, tuple] = {}

    def partners(labels, plane_points, rules, pieces=None):
        pieces = pieces or necks.summarize_pieces(labels, plane_points, rules.sample_step)
        joins = []
        for upper, lower in necks.stacked_candidates(pieces, labels, rules).tolist():
            surface = necks.one_surface(labels, upper, pieces.boxes[upper], rules.one_surface)
            neck, body = necks.neck_and_body(labels, plane_points, upper, rules)
            joined = surface and neck < rules.neck_share * body
            seen.append((upper, lower, surface, neck, body, joined, labels == upper, labels == lower))
            if joined:
                joins.append((upper, lower))
        return joins

    segments = clutter.full_resolution_segments

    def kept_box(labels, depth, crop, step, *rest, **options):
        box["crop"], box["step"] = crop, step
        return segments(labels, depth, crop, step, *rest, **options)

    necks.neck_partners = partners
    clutter.full_resolution_segments = kept_box
    for path, frame, name in HELD_OUT:
        seen.clear()
        root = create_pipeline(reader_for(str(path), frame))
        if Engine(root).tick() is not Status.SUCCESS:
            print(f"{name}: the tabletop tree failed")
            continue
        image = root.cas.view(ColorImage).image
        x0, y0, _, _ = box["crop"]
        step = box["step"]
        print(f"{name}: {len(seen)} pairs looked at")
        for number, (upper, lower, surface, neck, body, joined, upper_mask, lower_mask) in enumerate(seen):
            overlay = image.copy()
            for mask, tint in ((upper_mask, (127, 0, 0)), (lower_mask, (0, 0, 127))):
                full = np.zeros(image.shape[:2], dtype=bool)
                grown = np.kron(mask, np.ones((step, step), dtype=bool))
                rows = min(grown.shape[0], full.shape[0] - y0 * step)
                cols = min(grown.shape[1], full.shape[1] - x0 * step)
                full[y0 * step : y0 * step + rows, x0 * step : x0 * step + cols] = grown[:rows, :cols]
                overlay[full] = (0.5 * overlay[full] + np.array(tint)).astype(np.uint8)
            ys, xs = np.nonzero(upper_mask)
            at = ((xs.mean() + x0) * step, (ys.mean() + y0) * step)
            ratio = neck / body if body else float("nan")
            print(
                f"  pair {number}: upper {upper} near ({at[0]:.0f}, {at[1]:.0f}) {upper_mask.sum()} grid px, lower "
                f"{lower} {lower_mask.sum()} grid px, one surface {surface}, neck {neck:.3f} m / width {body:.3f} m"
                f" = {ratio:.2f}, joined {joined}"
            )
            picture = cv2.cvtColor(np.hstack([overlay, image]), cv2.COLOR_RGB2BGR)
            cv2.imwrite(str(out / f"{name.replace(' ', '_')}_{number}.png"), picture)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("part", nargs="?", choices=("shares", "necks"), help="one part only (default: both)")
    parser.add_argument("--out", type=Path, default=Path(tempfile.gettempdir()) / "seg7_necks")
    arguments = parser.parse_args()
    if arguments.part in (None, "necks"):
        neck_pairs(arguments.out)
    if arguments.part in (None, "shares"):
        shares()


if __name__ == "__main__":
    main()
