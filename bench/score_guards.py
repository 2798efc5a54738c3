"""Score the clutter segmenter object by object on the hand-labelled uoc frames
(tests/data/labels/guard_objects.json), instead of judging renders by eye: each object whole, cut, merged, spilling
over or missed (reasoning/evaluation/object_verdicts.py says how each is decided).

Variants: ``grid`` (the default segmenter) and ``grown`` (``ClutterParameters(grown_patches=True)``), side by side.
``--offsets N`` scores each variant at N x N crop offsets instead (the segmenter's crop started ``dy`` rows and
``dx`` columns, in coarse pixels, before the candidates' box, as bench/experiments/seg9_grown.py does): the grid
cells' phase moves with the crop, grown patches do not; it prints the whole objects per offset (median, min, max)
and how often each object is not whole.
Run from the repository root: ``PYTHONPATH=$PWD python bench/score_guards.py [--variant grid --variant grown]
[--offsets 6]``.
"""

from __future__ import annotations

import argparse
import collections
import json
import statistics
import sys
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import annotators.cloud.clutter as clutter  # noqa: E402
from annotators.cloud.clutter import ClutterParameters  # noqa: E402
from reasoning.evaluation.object_verdicts import load_labelled_objects, object_verdicts  # noqa: E402
from tests.annotators.guard_frames import LABELS, crop_moved, segment_frame  # noqa: E402

ORIGINAL_BOX = clutter.bounding_box


def parameters(variant: str) -> ClutterParameters:
    """``grid``: the default segmenter's settings; ``grown``: the same with grown patches."""
    base = ClutterParameters()
    return base if variant == "grid" else replace(base, grown_patches=True)


def with_offset(dy: int, dx: int) -> None:
    """Make the segmenter's crop (the candidates' box of margin 2) start ``dy`` rows and ``dx`` columns earlier."""
    clutter.bounding_box = crop_moved(dy, dx)


def over_offsets(variants: list[str], size: int) -> None:
    """Per variant: whole objects at each of ``size`` x ``size`` crop offsets, and each object's faults."""
    frames = load_labelled_objects(LABELS)
    total = sum(len(objects) for objects in frames.values())
    for variant in variants:
        per_offset, faults = [], collections.Counter()
        for dy in range(size):
            for dx in range(size):
                with_offset(dy, dx)
                whole = 0
                for (input_name, index), objects in frames.items():
                    labels = segment_frame(input_name, index, parameters(variant))
                    for name, verdict in object_verdicts(labels, objects).items():
                        whole += verdict.kind == "whole"
                        if verdict.kind != "whole":
                            faults[f"{Path(input_name).stem}#{index} {name}: {verdict.kind}"] += 1
                per_offset.append(whole)
        clutter.bounding_box = ORIGINAL_BOX
        print(
            f"{variant}: whole of {total} over {len(per_offset)} offsets: median {statistics.median(per_offset)}, "
            f"min {min(per_offset)}, max {max(per_offset)}, at (0, 0) {per_offset[0]}; "
            f"all whole at {per_offset.count(total)} offsets"
        )
        for fault, count in faults.most_common():
            print(f"  {fault} at {count} offsets")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--variant", action="append", choices=("grid", "grown"), default=[])
    parser.add_argument("--json", action="store_true", help="print the verdicts as JSON")
    parser.add_argument("--offsets", type=int, default=0, help="score at N x N crop offsets")
    args = parser.parse_args()
    variants = args.variant or ["grid", "grown"]
    if args.offsets:
        over_offsets(variants, args.offsets)
        return
    results: dict[str, dict[str, dict[str, str]]] = {}
    for (input_name, index), objects in load_labelled_objects(LABELS).items():
        results[f"{Path(input_name).stem}#{index}"] = {
            v: {
                name: str(verdict)
                for name, verdict in object_verdicts(segment_frame(input_name, index, parameters(v)), objects).items()
            }
            for v in variants
        }
    if args.json:
        print(json.dumps(results, indent=1))
        return
    whole = dict.fromkeys(variants, 0)
    count = 0
    for key, by_variant in results.items():
        print(key)
        for name in by_variant[variants[0]]:
            print(f"  {name:<15} " + "  |  ".join(f"{v}: {by_variant[v][name]}" for v in variants))
            count += 1
            for v in variants:
                whole[v] += by_variant[v][name] == "whole"
    print("whole: " + "  ".join(f"{v} {whole[v]}/{count}" for v in variants))


if __name__ == "__main__":
    main()
