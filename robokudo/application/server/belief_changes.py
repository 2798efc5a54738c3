"""The ``/robokudo/beliefs`` topic's message: what one frame changed in the belief store."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from reasoning.beliefs.answer import designator
from reasoning.fusion.tracking import TrackStep


def belief_changes(step: TrackStep, tick: int, label_of: Callable[[str], str]) -> dict[str, Any]:
    """The message for one frame's changes: the ids created, missed (expected in view, not seen) and marked gone,
    and every changed belief as an object designator (as query results carry them)."""
    return {
        "tick": tick,
        "created": list(step.created),
        "missed": list(step.missed),
        "gone": list(step.gone),
        "changed": [designator(belief, label_of=label_of).to_dict() for belief in step.changed],
    }
