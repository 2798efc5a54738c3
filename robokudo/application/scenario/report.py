"""The storage scenario's report: a Table-I-style table of successes per criterion and per-expert run times
(median, p90), and the box plot of the per-expert times (the paper's Fig. 8)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from robokudo.application.scenario.scoring import RunScore, success_counts


def success_table(scores: Sequence[RunScore]) -> str:
    """Successes / runs and % per criterion (pointing, following, free space, process handling)."""
    runs = len(scores)
    lines = [f"{'criterion':18s} {'successes':>11s} {'%':>7s}"]
    for name, count in success_counts(scores).items():
        share = 100.0 * count / runs if runs else 0.0
        lines.append(f"{name:18s} {f'{count}/{runs}':>11s} {share:7.1f}")
    return "\n".join(lines)


def expert_stats(samples: Mapping[str, Sequence[float]]) -> dict[str, tuple[float, float, int]]:
    """Per expert: median ms, p90 ms and the number of runs (experts without runs left out)."""
    return {
        name: (float(np.median(values)), float(np.percentile(values, 90)), len(values))
        for name, values in samples.items()
        if len(values)
    }


def expert_table(samples: Mapping[str, Sequence[float]]) -> str:
    """The per-expert run times, slowest median first."""
    stats = expert_stats(samples)
    lines = [f"{'expert':28s} {'median ms':>10s} {'p90 ms':>10s} {'runs':>6s}"]
    for name, (median, p90, count) in sorted(stats.items(), key=lambda item: -item[1][0]):
        lines.append(f"{name:28s} {median:10.2f} {p90:10.2f} {count:6d}")
    return "\n".join(lines)


def plot_expert_times(samples: Mapping[str, Sequence[float]], path: Path, title: str = "") -> None:
    """Write a box plot of the per-expert run times (ms, log scale) to ``path`` (PNG)."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib import pyplot

    stats = expert_stats(samples)
    names = sorted(stats, key=lambda name: -stats[name][0])
    figure, axes = pyplot.subplots(figsize=(max(6.0, 0.6 * len(names) + 2), 4.5))
    try:
        axes.boxplot([list(samples[name]) for name in names], showfliers=True)
        axes.set_xticks(range(1, len(names) + 1), names, rotation=40, ha="right")
        axes.set_yscale("log")
        axes.set_ylabel("run time per call (ms)")
        axes.set_title(title or "per-expert run times")
        axes.grid(axis="y", alpha=0.3)
        figure.tight_layout()
        figure.savefig(path, format="png", dpi=120)
    finally:
        pyplot.close(figure)
