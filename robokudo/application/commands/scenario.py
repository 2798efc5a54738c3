"""``robokudo scenario storage``: the RoboKudo paper's storage mission on one running engine, scored.

Each run (seeded: ``--seed`` + run number) puts a person at a random place behind the built-in kitchen's table,
has her point at a random table object, grasp it, walk to the fridge and point at it, with a random layout of
objects blocking places on the fridge's upper shelf; one answering service (engine ticking in the background over
the live kitchen camera, the served root of ``robokudo serve``) answers the four queries in sequence, each swapped
into the task slot (:mod:`robokudo.application.scenario.mission`). The runs are scored against the scene's ground
truth (:mod:`robokudo.application.scenario.scoring`); printed are one line per run, the Table-I-style table
(successes / runs and %: pointing, following, free space, process handling) and the per-expert run times (median,
p90) from the engine's timing records; ``--plot PNG`` draws their box plot. Exit status 0, or 1 when the process
handling failed in some run.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from annotators.readers.streams import CLOCKS
from robokudo.application.scenario.campaign import DEFAULT_CLOCK, run_storage_scenario
from robokudo.application.scenario.report import expert_stats, expert_table, plot_expert_times, success_table
from robokudo.application.scenario.scoring import DEFAULT_FOLLOW_TOLERANCE, success_counts

HELP = "run the paper's storage scenario on one running engine and score it"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Arguments of ``robokudo scenario``."""
    kinds = parser.add_subparsers(dest="scenario", required=True, metavar="SCENARIO")
    storage = kinds.add_parser("storage", help="detect, watch pointing, follow, free space (the paper's Table I)")
    storage.add_argument("--runs", type=_positive, default=5, metavar="N", help="how many runs (default 5)")
    storage.add_argument("--seed", type=int, default=0, metavar="S", help="seed of the first run (default 0)")
    storage.add_argument("--plot", type=Path, metavar="PNG", help="write a box plot of the per-expert run times")
    storage.add_argument(
        "--follow-tolerance",
        type=float,
        default=DEFAULT_FOLLOW_TOLERANCE,
        metavar="M",
        help=f"metres a tracked position may be from her body's centre (default {DEFAULT_FOLLOW_TOLERANCE:g})",
    )
    storage.add_argument(
        "--clock",
        choices=CLOCKS,
        default=DEFAULT_CLOCK,
        help="how the scene advances: one camera period per frame (frames, default: the runs do not depend on how "
        "busy the machine is) or with the wall clock (wall: a slow tracking loop misses frames of her walk)",
    )
    storage.add_argument("--json", action="store_true", help="print the runs and results as JSON")
    storage.add_argument("--quiet", action="store_true", help="no per-phase progress on stderr")


def _positive(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be at least 1, not {value}")
    return value


def run(args: argparse.Namespace) -> int:
    """Run the scenario and print the tables."""
    if args.follow_tolerance <= 0:
        raise ValueError("--follow-tolerance must be a positive number of metres")
    if args.plot is not None and not args.plot.parent.is_dir():
        raise ValueError(f"--plot: no folder {args.plot.parent}")

    def log(line: str) -> None:
        if not args.quiet:
            print(line, file=sys.stderr, flush=True)

    result = run_storage_scenario(args.runs, args.seed, args.follow_tolerance, log, args.clock)
    records, scores = list(result.records), list(result.scores)
    samples = result.expert_ms
    if args.plot is not None:
        plot_expert_times(samples, args.plot, f"storage scenario, {args.runs} runs: per-expert run times")
    if args.json:
        print(json.dumps(_as_json(records, scores, samples), indent=2))
    else:
        print(
            f"storage scenario: {args.runs} runs (seeds {args.seed}..{args.seed + args.runs - 1}, {args.clock} clock)"
        )
        print(success_table(scores))
        print()
        print(expert_table(samples))
        if args.plot is not None:
            print(f"\nbox plot: {args.plot}")
    return 0 if all(s.process for s in scores) else 1


def _as_json(records: list, scores: list, samples: dict) -> dict:
    runs = [
        {
            "seed": r.seed,
            "target": r.target,
            "pointed_object": r.pointed_object,
            "pointed_region": r.pointed_region,
            "follow_frames": len(r.follow),
            "follow_max_error_m": max((s.error for s in r.follow), default=None),
            "placements": [len(scan.placements) for scan in r.free_space],
            "goals": len(r.goals),
            "scores": {
                "pointing": s.pointing,
                "following": s.following,
                "free_space": s.free_space,
                "process": s.process,
            },
            "why": list(s.why),
            "error": r.error,
        }
        for r, s in zip(records, scores, strict=True)
    ]
    stats = {name: {"median_ms": m, "p90_ms": p, "runs": n} for name, (m, p, n) in expert_stats(samples).items()}
    return {"runs": runs, "successes": success_counts(scores), "experts": stats}
