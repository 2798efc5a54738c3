"""A continuous task's target is lost once it was not seen for longer than lost_after (frame times)."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from robokudo.application.target_watch import TargetWatch


@given(
    st.floats(0.0, 5.0),
    st.lists(st.tuples(st.floats(0.0, 1.0), st.booleans()), min_size=1, max_size=50),
)
def test_lost_exactly_when_the_time_since_the_last_sighting_exceeds_lost_after(
    lost_after: float, runs: list[tuple[float, bool]]
) -> None:
    watch = TargetWatch(lost_after, "the human")
    stamp, since = 100.0, None
    for step, seen in runs:
        stamp += step
        since = stamp if since is None else since
        if seen:
            since = stamp
        reason = watch.observe(stamp, seen)
        if stamp - since > lost_after:
            assert reason is not None and reason.startswith("target lost: the human not seen for ")
            assert f"{stamp - since:.2f} s" in reason
            return
        assert reason is None


@pytest.mark.parametrize("bad", [-1.0, float("nan"), float("inf")])
def test_a_bad_lost_after_is_refused(bad: float) -> None:
    with pytest.raises(ValueError, match="lost_after"):
        TargetWatch(bad)


def test_time_goes_on_when_a_looped_recording_starts_its_stamps_again() -> None:
    watch = TargetWatch(1.0, "the human")
    loop = [1000.0, 1000.25, 1000.5]
    reasons = [watch.observe(stamp, False) for stamp in loop * 3]
    # watch time: 0, .25, .5, then .75, 1.0, 1.25 (each restart one frame period on): lost at the sixth frame
    assert reasons[:5] == [None] * 5
    assert reasons[5] == "target lost: the human not seen for 1.25 s (lost after 1 s)"


def test_a_sighting_after_a_loop_restart_resets_the_unseen_time() -> None:
    watch = TargetWatch(0.6, "the cup")
    assert watch.observe(10.0, True) is None
    assert watch.observe(10.25, False) is None
    assert watch.observe(10.0, True) is None  # the loop restarted: watch time 0.5, seen
    assert watch.observe(10.25, False) is None  # 0.25 unseen
    assert watch.observe(10.5, False) is None  # 0.5 unseen
    assert watch.observe(10.0, False) is not None  # 0.75 unseen
