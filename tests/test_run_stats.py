"""RunStats: the counters and the median over the most recent ``window`` runs."""

from __future__ import annotations

import statistics

from hypothesis import given
from hypothesis import strategies as st

from robokudo.core.stats import RunStats

durations = st.lists(st.floats(0.0, 10.0, allow_nan=False), max_size=60)


@given(durations, st.integers(1, 20))
def test_stats_summarise_the_recorded_runs(seconds: list[float], window: int) -> None:
    stats = RunStats(window=window)
    for value in seconds:
        stats.record(value)
    assert stats.count == len(seconds)
    assert stats.total_seconds == sum(seconds)
    assert stats.max_seconds == max(seconds, default=0.0)
    assert stats.last_seconds == (seconds[-1] if seconds else 0.0)
    assert stats.median_seconds == (statistics.median(seconds[-window:]) if seconds else 0.0)
