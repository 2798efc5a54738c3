"""Evidence for seg9 (bench/profiles/seg9-analysis.txt): grown patches (annotators/geometry/flat_patches.py) against
the grid cells in the clutter segmenter, over crop offsets.

The inputs are those of bench/check_clutter_labels.py (prepared once into ``--inputs``). An offset ``(dy, dx)``
starts the segmenter's crop ``dy`` rows and ``dx`` columns (coarse pixels) before the candidates' bounding box would:
for the grid cells that is a cell phase (seg8's "phase"), for grown patches it should change nothing.

Modes:
* ``mosd``: the 45 labelled mOSD learn scenes scored per category (recall / precision at box IoU >= 0.5, overlap F,
  as bench/bench_segmentation.py scores them) for each variant at each of the ``cell`` x ``cell`` offsets; per
  category the median, minimum and maximum F over the offsets.
* ``guards``: per real guard input, segment counts over the offsets and at how many offsets the labels equal those at
  the first (pixel for pixel).
* ``render``: PNGs of the colour image and each variant's segments (``--name`` inputs) in /tmp/seg9-renders.
* ``timing``: least CPU ms of segment_clutter per ``--name`` input and variant, the variants alternating.

Run from the repository root:
``PYTHONPATH=$PWD python bench/experiments/seg9_grown.py mosd --variant grid --variant grown:16``.
"""

from __future__ import annotations

import argparse
import collections
import statistics
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

from score_guards import ORIGINAL_BOX, with_offset  # noqa: E402  (the crop moved as in the guard scores)

import annotators.cloud.clutter as clutter  # noqa: E402
from annotators.readers.pcd_io import read_pcd  # noqa: E402
from reasoning.evaluation.mosd import object_labels, scene_category  # noqa: E402
from reasoning.evaluation.segmentation import score_segmentation, summarize  # noqa: E402

DATA = ROOT.parent / "shared" / "data"
CATEGORIES = ("boxes", "stacked", "occluded", "cylindric")
ORIGINAL_PATCHES = clutter.flat_patches


def parameters(variant: str) -> clutter.ClutterParameters:
    """``grid`` (today's cells), ``grown`` (grown patches, their defaults) or ``grown:WEIGHT[:SPACING[:RELATIVE]]``
    (RELATIVE: the height term's scale, by default the depth-jump scale ``jump_relative``; 0 for none)."""
    base = clutter.ClutterParameters()
    if variant == "grid":
        return base
    parts = variant.split(":")
    weight = float(parts[1]) if len(parts) > 1 else base.patch_weight
    spacing = int(parts[2]) if len(parts) > 2 else base.patch_spacing
    relative = float(parts[3]) if len(parts) > 3 else None

    def patches(*args: object) -> np.ndarray:  # the height term's scale alone replaced
        return ORIGINAL_PATCHES(*args[:5], args[5] if relative is None else relative)

    clutter.flat_patches = patches
    return replace(base, grown_patches=True, patch_weight=weight, patch_spacing=spacing)


def segment(data: dict, p: clutter.ClutterParameters) -> np.ndarray:
    """HxW int32 labels of the clutter segments, larger first where masks overlap (as the bench's trees give)."""
    found = clutter.segment_clutter(data["points"], data["mask"], data["model"], data["plane"], p, data["colors"])
    labels = np.zeros(data["points"].shape[:2], dtype=np.int32)
    for number, s in enumerate(sorted(found, key=lambda s: -int(np.count_nonzero(s.mask))), start=1):
        labels[s.mask & (labels == 0)] = number
    return labels


def load(inputs: Path) -> dict[str, dict]:
    """The prepared inputs by name (prepared on first use)."""
    from check_clutter_labels import prepare

    if not any(inputs.glob("*.npz")):
        inputs.mkdir(parents=True, exist_ok=True)
        prepare(inputs)
    return {path.stem: dict(np.load(path)) for path in sorted(inputs.glob("*.npz"))}


def mosd(inputs: dict[str, dict], variants: list[str], offsets: list[tuple[int, int]]) -> None:
    """Per variant and offset the F per category; then the median / min / max over the offsets."""
    learn = DATA / "pcl_mosd_tabletop" / "learn"
    truths = {}
    for name in inputs:
        if name.startswith("learn"):
            frame = read_pcd(learn / f"{name}.pcd")
            truths[name] = (object_labels(frame.labels), np.isfinite(frame.points[..., 2]))
    for variant in variants:
        p = parameters(variant)
        per_offset: dict[str, list[float]] = collections.defaultdict(list)
        for dy, dx in offsets:
            with_offset(dy, dx)
            scores = collections.defaultdict(list)
            for name, (truth, valid) in truths.items():
                score = score_segmentation(truth, segment(inputs[name], p), valid)
                scores[scene_category(f"{name}.pcd")].append(score)
                scores["all"].append(score)
            line = []
            for category in (*CATEGORIES, "all"):
                s = summarize(scores[category])
                per_offset[category].append(s.overlap_f)
                line.append(f"{category} {s.recall:.2f}/{s.precision:.3f}/{s.overlap_f:.4f}")
            print(f"{variant} offset ({dy}, {dx}): " + "  ".join(line), flush=True)
        for category in (*CATEGORIES, "all"):
            values = per_offset[category]
            print(
                f"{variant} {category:<10} median {statistics.median(values):.4f}  min {min(values):.4f}  "
                f"max {max(values):.4f}  (0,0) {values[0]:.4f}",
                flush=True,
            )
    clutter.bounding_box = ORIGINAL_BOX


def guards(inputs: dict[str, dict], variants: list[str], offsets: list[tuple[int, int]]) -> None:
    """Per real guard input and variant: segment counts over the offsets, and at how many offsets the labels equal
    those at the first offset."""
    names = [n for n in inputs if not n.startswith("learn") and n != "milk_cartoon_all_small_clorox"]
    for variant in variants:
        p = parameters(variant)
        for name in names:
            counts: collections.Counter = collections.Counter()
            same, first = 0, None
            for dy, dx in offsets:
                with_offset(dy, dx)
                labels = segment(inputs[name], p)
                counts[int(labels.max())] += 1
                if first is None:
                    first = labels
                same += int(np.array_equal(labels, first))
            print(f"{variant} {name}: counts {dict(sorted(counts.items()))}; same as first {same}/{len(offsets)}")
    clutter.bounding_box = ORIGINAL_BOX


def render(inputs: dict[str, dict], variants: list[str], folder: Path, names: list[str]) -> None:
    """Per input, a PNG with the colour image and each variant's segments (random colours, their pixel counts)."""
    import cv2

    folder.mkdir(parents=True, exist_ok=True)
    for name in names:
        data = inputs[name]
        panels = [cv2.cvtColor(np.ascontiguousarray(data["colors"]), cv2.COLOR_RGB2BGR)]
        for variant in variants:
            labels = segment(data, parameters(variant))
            palette = np.random.default_rng(1).integers(60, 255, (int(labels.max()) + 1, 3)).astype(np.uint8)
            palette[0] = 0
            panel = (0.35 * panels[0] + 0.65 * palette[labels]).astype(np.uint8)
            for label in range(1, int(labels.max()) + 1):
                rows, cols = np.nonzero(labels == label)
                text = f"{label}:{rows.size}"
                cv2.putText(panel, text, (int(cols.mean()) - 20, int(rows.mean())), 0, 0.4, (255, 255, 255), 1)
            cv2.putText(panel, f"{variant} {int(labels.max())}", (5, 15), 0, 0.5, (0, 255, 255), 1)
            panels.append(panel)
        cv2.imwrite(str(folder / f"{name}.png"), np.hstack(panels))
        print(f"wrote {folder / f'{name}.png'}", flush=True)


def timing(inputs: dict[str, dict], variants: list[str], names: list[str], rounds: int = 20) -> None:
    """Least CPU ms of segment_clutter per input and variant, the variants alternating in one process."""
    import time

    with_offset(0, 0)
    least: dict[tuple[str, str], float] = collections.defaultdict(lambda: float("inf"))
    for _ in range(rounds):
        for name in names:
            for variant in variants:
                p = parameters(variant)
                start = time.process_time()
                segment(inputs[name], p)
                least[name, variant] = min(least[name, variant], 1000 * (time.process_time() - start))
    for name in names:
        cells = "  ".join(f"{v} {least[name, v]:.1f}" for v in variants)
        print(f"{name}: {cells}  ratio {least[name, variants[-1]] / least[name, variants[0]]:.2f}", flush=True)
    clutter.bounding_box = ORIGINAL_BOX


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("part", choices=("mosd", "guards", "render", "timing"))
    parser.add_argument("--variant", action="append", default=[])
    parser.add_argument("--inputs", type=Path, default=Path("/tmp/seg9-inputs"))
    parser.add_argument("--offsets", type=int, default=clutter.ClutterParameters().cell, help="n: n x n offsets")
    parser.add_argument("--name", action="append", default=[], help="render: the inputs to render")
    parser.add_argument("--scale", type=int, default=1, help="offsets in steps of this many coarse pixels")
    args = parser.parse_args()
    inputs = load(args.inputs)
    offsets = [(args.scale * dy, args.scale * dx) for dy in range(args.offsets) for dx in range(args.offsets)]
    variants = args.variant or ["grid"]
    if args.part == "mosd":
        mosd(inputs, variants, offsets)
    elif args.part == "guards":
        guards(inputs, variants, offsets)
    elif args.part == "timing":
        timing(inputs, variants, args.name)
    else:
        render(inputs, variants, Path("/tmp/seg9-renders"), args.name)


if __name__ == "__main__":
    main()
