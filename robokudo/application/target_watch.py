"""When a continuous task's target counts as lost: not seen for longer than ``lost_after`` seconds.

The watch is told, after every run of the task's loop, the time of the frame the run analysed and whether the run
saw the target. Until the first sighting the time counts from the first run's frame. Frame times are the frames'
timestamps, so the time an expert needs to analyse a frame does not make a target lost that was in view. A frame
stamped earlier than the one before (a looped recording starting again) counts as one frame period (the last gap
between two frames) after it, so the watch's time goes on across loops.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field


@dataclass
class TargetWatch:
    """Says when the target named ``target`` was not seen for longer than ``lost_after`` seconds (see the module)."""

    lost_after: float
    target: str = "the target"
    first: float | None = field(default=None, init=False)
    last_seen: float | None = field(default=None, init=False)
    _previous: float | None = field(default=None, init=False)
    """The stamp of the last frame observed, as the source gave it."""
    _now: float = field(default=0.0, init=False)
    """The watch's time of the last frame observed (frame stamps, continued across loops)."""
    _period: float = field(default=0.0, init=False)
    """The last positive gap between two frames' stamps."""

    def __post_init__(self) -> None:
        if isinstance(self.lost_after, bool) or not isinstance(self.lost_after, int | float):
            raise TypeError(f"lost_after must be a number of seconds, not {self.lost_after!r}")
        if not math.isfinite(self.lost_after) or self.lost_after < 0:
            raise ValueError(f"lost_after must be a finite number of seconds >= 0, not {self.lost_after!r}")

    def unseen_for(self, stamp: float) -> float:
        """Seconds from the last sighting (or the first run) to ``stamp`` (0 before any run)."""
        since = self.last_seen if self.last_seen is not None else self.first
        return 0.0 if since is None else max(0.0, stamp - since)

    def observe(self, stamp: float, seen: bool) -> str | None:
        """Record a run; the reason the task ends when the target is now lost, else None."""
        stamp = self._continued(stamp)
        if self.first is None:
            self.first = stamp
        if seen:
            self.last_seen = stamp if self.last_seen is None else max(self.last_seen, stamp)
            return None
        unseen = self.unseen_for(stamp)
        if unseen > self.lost_after:
            return f"target lost: {self.target} not seen for {unseen:.2f} s (lost after {self.lost_after:g} s)"
        return None

    def _continued(self, stamp: float) -> float:
        """``stamp`` on the watch's time: the source's stamps, shifted so that a backward jump (a loop) goes on."""
        if self._previous is None:
            self._now = stamp
        elif stamp >= self._previous:
            gap = stamp - self._previous
            self._period = gap if gap > 0 else self._period
            self._now += gap
        else:
            self._now += self._period
        self._previous = stamp
        return self._now
