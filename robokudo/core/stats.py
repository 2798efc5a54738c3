"""Per-node run-time statistics."""

from __future__ import annotations

import statistics
from dataclasses import dataclass, field


@dataclass(slots=True)
class RunStats:
    """Durations of an annotator's runs: count, total, maximum and the last; keeps the most recent ``window``
    samples for the median.

    Recording is on every node's tick path, so it only updates counters and overwrites one slot of a ring
    buffer; the median is computed when asked."""

    window: int = 1000
    count: int = 0
    max_seconds: float = 0.0
    total_seconds: float = 0.0
    last_seconds: float = 0.0
    _recent: list[float] = field(default_factory=list, repr=False)
    _oldest: int = field(default=0, repr=False)  # index of the oldest sample once the window is full

    def record(self, seconds: float) -> None:
        """Add one run's duration."""
        self.count += 1
        self.total_seconds += seconds
        self.last_seconds = seconds
        if seconds > self.max_seconds:
            self.max_seconds = seconds
        recent = self._recent
        if len(recent) < self.window:
            recent.append(seconds)
        elif recent:
            recent[self._oldest] = seconds
            self._oldest = (self._oldest + 1) % len(recent)

    @property
    def samples(self) -> tuple[float, ...]:
        """The recent runs' durations in seconds (at most ``window``; once it is full, not in run order)."""
        return tuple(self._recent)

    @property
    def median_seconds(self) -> float:
        """Median of the recent runs (0 when there were none)."""
        return statistics.median(self._recent) if self._recent else 0.0

    def summary(self) -> str:
        """``count, median and max`` in milliseconds, for tables."""
        return f"n={self.count} median={self.median_seconds * 1e3:.2f}ms max={self.max_seconds * 1e3:.2f}ms"
