"""Values an object holds at once: a red-and-white can is red and white.

The colour expert states an object's dominant colour and, when it has two, its second one, in one sighting; the
fusion weighs an attribute's values as rivals (one of them is the object's colour), so a second colour is never
more likely than not and a query for it would not find the object. For the attributes of :data:`SEEN_TOGETHER` a
belief also answers to every value stated when the attribute was last stated (:func:`last_stated`), and an answer
shows them beside the fused value.
"""

from __future__ import annotations

from collections.abc import Mapping

from reasoning.fusion.rule import ValueSupport
from robokudo.core.types import SemanticColor

SEEN_TOGETHER = frozenset({SemanticColor.attribute})
"""The attributes whose values an object can hold at once (its colours)."""


def last_stated(values: Mapping[str, ValueSupport]) -> list[str]:
    """The values whose latest statement is the attribute's latest (stated together in the last sighting that
    stated any), in the values' order; [] for no values."""
    if not values:
        return []
    latest = max(support.last_seen for support in values.values())
    return [value for value, support in values.items() if support.last_seen == latest]
