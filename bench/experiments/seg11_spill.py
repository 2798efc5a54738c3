"""Evidence for seg11 (bench/profiles/seg11-analysis.txt): where the clutter segmenter's dependence on the cell phase
comes from, and one rule tried against it.

The convexity step grows each object's label by up to ``grow`` coarse pixels into the pixels no trusted patch
covers, to the nearest seed in the image (a plain distance transform). The growth does not look at depth, so pixels
of the surface behind an object's outline can take the object's label. Where those pixels fall depends on the
cells. The rule tried here keeps a grown pixel only if its own surface (depth-continuous, ``label_parts`` of the
candidates without depth seams) holds a trusted patch of that label, or no trusted patch at all.

Modes:
* ``mosd``: per variant (``grid``, today's segmenter; ``surface``, with the rule) the 45 labelled mOSD learn
  scenes at ``n`` x ``n`` crop offsets (``--scale`` coarse pixels apart, as bench/score_guards.py moves the crop):
  per category the median and least recall, precision and overlap F over the offsets.
* ``scenes``: the scenes whose scores differ between the two variants at one offset (``--at DY DX``).

Run from the repository root:
``PYTHONPATH=$PWD python bench/experiments/seg11_spill.py mosd --offsets 3 --scale 2``.
The inputs are bench/experiments/seg9_grown.py's (prepared once into ``--inputs``).
"""

from __future__ import annotations

import argparse
import collections
import statistics
import sys
from pathlib import Path

import numpy as np
from scipy import ndimage

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))
sys.path.insert(0, str(ROOT / "bench" / "experiments"))

from score_guards import ORIGINAL_BOX, with_offset  # noqa: E402
from seg9_grown import DATA, load, segment  # noqa: E402

import annotators.cloud.clutter as clutter  # noqa: E402
import annotators.geometry.convexity as convexity  # noqa: E402
from annotators.readers.pcd_io import read_pcd  # noqa: E402
from reasoning.evaluation.mosd import object_labels, scene_category  # noqa: E402
from reasoning.evaluation.segmentation import SegmentationScore, score_segmentation, summarize  # noqa: E402

CATEGORIES = ("boxes", "stacked", "occluded", "cylindric", "all")
ORIGINAL_GROUPS = clutter.convex_objects
ORIGINAL_PARTS = clutter.label_parts
ORIGINAL_NORMALS = clutter.grid_normals


class SurfaceRule:
    """The rule as hooks on the segmenter's module: the first ``label_parts`` after the normals are the surfaces;
    ``convex_objects`` drops grown pixels whose surface holds trusted patches but none of their label."""

    def __init__(self) -> None:
        self.on = False
        self.behind_only = False
        self.surfaces: np.ndarray | None = None
        self._next_parts_are_surfaces = False

    def install(self) -> None:
        """Put the hooks in place of the segmenter module's functions (the rule is off until ``on``)."""
        clutter.grid_normals = self.normals
        clutter.label_parts = self.parts
        clutter.convex_objects = self.groups

    def normals(self, *args: object, **kwargs: object) -> np.ndarray:
        self._next_parts_are_surfaces = True
        return ORIGINAL_NORMALS(*args, **kwargs)

    def parts(self, *args: object, **kwargs: object) -> np.ndarray:
        found = ORIGINAL_PARTS(*args, **kwargs)
        if self._next_parts_are_surfaces:
            self.surfaces, self._next_parts_are_surfaces = found, False
        return found

    def groups(
        self,
        patches: np.ndarray,
        points: np.ndarray,
        rules: convexity.ConvexityRules,
        between: np.ndarray | None = None,
        grow: float = 0.0,
        footprint: float | None = None,
    ) -> convexity.ConvexObjects:
        objects = ORIGINAL_GROUPS(patches, points, rules, between, grow, footprint)
        labels = objects.labels
        if not self.on or grow <= 0 or self.surfaces is None:
            return objects
        planes = convexity.patch_planes(patches, points)
        trusted = (planes.thickness <= rules.max_thickness) & (planes.width >= rules.min_width)
        usable = np.concatenate([[False], (planes.counts >= rules.min_patch) & trusted])
        seeds = usable[patches] & (labels > 0)
        surfaces = self.surfaces.astype(np.int64)
        count = int(surfaces.max()) + 1
        seeded = np.zeros(count * (int(labels.max()) + 1), dtype=bool)
        seeded[surfaces[seeds] + count * labels[seeds]] = True
        has_seed = np.zeros(count, dtype=bool)
        has_seed[surfaces[seeds]] = True
        grown = (labels > 0) & ~seeds & (surfaces > 0)
        keep = seeded[surfaces[grown] + count * labels[grown]] | ~has_seed[surfaces[grown]]
        if self.behind_only:  # only pixels farther than the seed they grew from (what an occluder hides) are dropped
            _, (seed_rows, seed_cols) = ndimage.distance_transform_edt(~seeds, return_indices=True)
            depth = points[..., 2]
            farther = depth[grown] > depth[seed_rows[grown], seed_cols[grown]]
            keep |= ~farther
        kept = labels.copy()
        rows, cols = np.nonzero(grown)
        kept[rows[~keep], cols[~keep]] = 0
        return convexity.ConvexObjects(kept, objects.seeded, objects.grow)


def truths(inputs: dict[str, dict]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per mOSD input: its object labels and where it has depth."""
    found = {}
    for name in inputs:
        if name.startswith("learn"):
            frame = read_pcd(DATA / "pcl_mosd_tabletop" / "learn" / f"{name}.pcd")
            found[name] = (object_labels(frame.labels), np.isfinite(frame.points[..., 2]))
    return found


def score(inputs: dict[str, dict], truth: dict, name: str) -> SegmentationScore:
    """The default segmenter's scores on one mOSD input (the hooks as they are set)."""
    labels, valid = truth[name]
    return score_segmentation(labels, segment(inputs[name], clutter.ClutterParameters()), valid)


def mosd(inputs: dict[str, dict], rule: SurfaceRule, offsets: list[tuple[int, int]]) -> None:
    """Per variant: per category the median (least) recall, precision and F over the offsets."""
    truth = truths(inputs)
    for variant in ("grid", "surface"):
        rule.on = variant == "surface"
        figures: dict[str, list[tuple[float, float, float]]] = collections.defaultdict(list)
        for dy, dx in offsets:
            with_offset(dy, dx)
            scores = collections.defaultdict(list)
            for name in truth:
                result = score(inputs, truth, name)
                scores[scene_category(f"{name}.pcd")].append(result)
                scores["all"].append(result)
            for category in CATEGORIES:
                summary = summarize(scores[category])
                figures[category].append((summary.recall, summary.precision, summary.overlap_f))
        clutter.bounding_box = ORIGINAL_BOX
        cells = []
        for category in CATEGORIES:
            columns = list(zip(*figures[category], strict=True))
            cells.append(f"{category} " + "/".join(f"{statistics.median(c):.3f}({min(c):.3f})" for c in columns))
        print(f"{variant:<8} R/P/F median(least): " + "  ".join(cells), flush=True)


def scenes(inputs: dict[str, dict], rule: SurfaceRule, at: tuple[int, int]) -> None:
    """The scenes whose objects found / segments / F differ between the variants at one offset."""
    truth = truths(inputs)
    with_offset(*at)
    for name in sorted(truth, key=lambda n: int(n.removeprefix("learn"))):
        cells = []
        for on in (False, True):
            rule.on = on
            result = score(inputs, truth, name)
            cells.append(
                f"{result.matched}/{result.objects} found, {result.segments} segments, F {result.overlap_f:.3f}"
            )
        if cells[0] != cells[1]:
            print(f"{name} ({scene_category(name + '.pcd')}): {cells[0]} -> {cells[1]}", flush=True)
    clutter.bounding_box = ORIGINAL_BOX


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("part", choices=("mosd", "scenes"))
    parser.add_argument("--inputs", type=Path, default=Path("/tmp/seg9-inputs"))
    parser.add_argument("--offsets", type=int, default=3, help="n: n x n offsets")
    parser.add_argument("--scale", type=int, default=2, help="offsets in steps of this many coarse pixels")
    parser.add_argument("--at", type=int, nargs=2, default=(0, 0), metavar=("DY", "DX"))
    parser.add_argument("--behind-only", action="store_true", help="drop only pixels farther than their seed")
    args = parser.parse_args()
    inputs = load(args.inputs)
    rule = SurfaceRule()
    rule.behind_only = args.behind_only
    rule.install()
    if args.part == "mosd":
        offsets = [(args.scale * dy, args.scale * dx) for dy in range(args.offsets) for dx in range(args.offsets)]
        mosd(inputs, rule, offsets)
    else:
        scenes(inputs, rule, tuple(args.at))


if __name__ == "__main__":
    main()
