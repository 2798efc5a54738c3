"""Benchmark of the paper's storage scenario (``robokudo scenario storage``) over many seeded runs.

One answering service serves the built-in kitchen camera with a scripted person for all runs; per run the four
queries (detect the table objects, watch her point at one, follow her while she walks to the fridge and watch her
point at it, free space on its shelf) are swapped into the running engine's task slot. Printed: the Table-I-style
table, each goal of issue 16 (pointing >= 95 %, following >= 95 %, free space 100 %, process handling 100 %) with
met / NOT met, how far the worst tracked position of a run was from her (median and largest over the runs), and
the per-expert run times (median, p90 ms) from the engine's timing records (``--plot PNG`` draws their box plot,
the paper's Fig. 8).

Run: ``.venv/bin/python bench/bench_scenario.py [--runs 50] [--seed 0] [--plot bench/output/scenario.png]``
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from annotators.readers.streams import CLOCKS  # noqa: E402
from robokudo.application.scenario.campaign import DEFAULT_CLOCK, run_storage_scenario  # noqa: E402
from robokudo.application.scenario.report import expert_table, plot_expert_times, success_table  # noqa: E402
from robokudo.application.scenario.scoring import DEFAULT_FOLLOW_TOLERANCE, success_counts  # noqa: E402

GOALS = {"pointing": 0.95, "following": 0.95, "free space": 1.0, "process handling": 1.0}
"""Issue 16's goals: the share of runs that must succeed per criterion."""


def _load() -> str:
    """The machine's 1-minute load average at the end (the runs share the machine)."""
    try:
        return f"{os.getloadavg()[0]:.1f}"
    except OSError:
        return "unknown"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=50)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--tolerance", type=float, default=DEFAULT_FOLLOW_TOLERANCE)
    parser.add_argument("--plot", type=Path)
    parser.add_argument("--clock", choices=CLOCKS, default=DEFAULT_CLOCK)
    parser.add_argument("--minutes", type=float, help="start no run after this many minutes (as many runs as fit)")
    parser.add_argument("--verbose", action="store_true", help="per-run progress on stderr")
    args = parser.parse_args()
    started = time.perf_counter()

    def log(line: str) -> None:
        if args.verbose:
            print(line, file=sys.stderr, flush=True)

    budget = None if args.minutes is None else 60.0 * args.minutes
    result = run_storage_scenario(args.runs, args.seed, args.tolerance, log, args.clock, budget)
    elapsed = time.perf_counter() - started
    runs = len(result.scores)
    seeds = f"seeds {args.seed}..{args.seed + runs - 1}"
    print(f"storage scenario: {runs} runs ({seeds}, {args.clock} clock), {elapsed:.0f} s, load {_load()}")
    print(success_table(result.scores))
    print()
    counts = success_counts(result.scores)
    for name, share in GOALS.items():
        got = counts[name] / runs
        print(f"goal {name} >= {share:.0%}: {got:.1%} {'met' if got >= share else 'NOT met'}")
    worst = [max(sample.error for sample in record.follow) for record in result.records if record.follow]
    if worst:
        print(
            f"following: the worst tracked position per run is {statistics.median(worst):.3f} m from her body's centre"
            f" (median of {len(worst)} runs), {max(worst):.3f} m at most (tolerance {args.tolerance:g} m)"
        )
    if any(score.why for score in result.scores):
        print("\nwhy runs failed:")
        for score, record in zip(result.scores, result.records, strict=True):
            for why in score.why:
                print(f"  seed {record.seed}: {why}")
    print()
    print(expert_table(result.expert_ms))
    if args.plot is not None:
        args.plot.parent.mkdir(parents=True, exist_ok=True)
        plot_expert_times(result.expert_ms, args.plot, f"storage scenario, {runs} runs: per-expert run times")
        print(f"\nbox plot: {args.plot}")


if __name__ == "__main__":
    main()
