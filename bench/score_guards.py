"""Score the clutter segmenter object by object on the hand-labelled uoc frames
(tests/data/labels/guard_objects.json), instead of judging renders by eye: each object whole, cut, merged, spilling
over or missed (reasoning/evaluation/object_verdicts.py says how each is decided).

Variants: ``grid`` (the default segmenter) and ``grown`` (``ClutterParameters(grown_patches=True)``), side by side.
Run from the repository root: ``PYTHONPATH=$PWD python bench/score_guards.py [--variant grid --variant grown]``.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from annotators.cloud.clutter import ClutterParameters  # noqa: E402
from reasoning.evaluation.object_verdicts import load_labelled_objects, object_verdicts  # noqa: E402
from tests.annotators.guard_frames import LABELS, segment_frame  # noqa: E402


def parameters(variant: str) -> ClutterParameters:
    """``grid``: the default segmenter's settings; ``grown``: the same with grown patches."""
    base = ClutterParameters()
    return base if variant == "grid" else replace(base, grown_patches=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--variant", action="append", choices=("grid", "grown"), default=[])
    parser.add_argument("--json", action="store_true", help="print the verdicts as JSON")
    args = parser.parse_args()
    variants = args.variant or ["grid", "grown"]
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
