"""Per-node run-time statistics."""

from __future__ import annotations

import statistics
from collections import deque
from dataclasses import dataclass, field


@dataclass
class RunStats:
    """Durations of an annotator's runs: count, total, maximum and the last; keeps the most recent ``window``
    samples for the median."""

    window: int = 1000
    count: int = 0
    max_seconds: float = 0.0
    total_seconds: float = 0.0
    last_seconds: float = 0.0
    _recent: deque[float] = field(default_factory=deque, repr=False)

    def record(self, seconds: float) -> None:
        """Add one run's duration."""
        self.count += 1
        self.total_seconds += seconds
        self.last_seconds = seconds
        self.max_seconds = max(self.max_seconds, seconds)
        self._recent.append(seconds)
        if len(self._recent) > self.window:
            self._recent.popleft()

    @property
    def median_seconds(self) -> float:
        """Median of the recent runs (0 when there were none)."""
        return statistics.median(self._recent) if self._recent else 0.0

    def summary(self) -> str:
        """``count, median and max`` in milliseconds, for tables."""
        return f"n={self.count} median={self.median_seconds * 1e3:.2f}ms max={self.max_seconds * 1e3:.2f}ms"
