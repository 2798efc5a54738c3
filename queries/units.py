"""Numbers with units: parsing ``30cm`` into an SI :class:`~queries.model.Number`.

Supported units (value -> SI): length ``mm cm dm m km``; time ``ms s min h``;
angle ``deg rad``; mass ``mg g kg``.  A number without a unit keeps unit
``None``.  Integers become exact floats (``12`` -> ``12.0``).
"""

from __future__ import annotations

import math
import re
from types import MappingProxyType

from queries.model import Number

QUANTITY = re.compile(r"(-?\d+(?:\.\d+)?(?:[eE][+-]?\d+)?)([A-Za-z]*)")
"""A number with an optional unit written right after it (``0.5m``, ``2s``)."""

# unit -> (SI unit, multiplier, divisor); dividing keeps 30cm == 0.3 exactly.
UNITS: MappingProxyType[str, tuple[str, float, float]] = MappingProxyType(
    {
        "mm": ("m", 1.0, 1000.0),
        "cm": ("m", 1.0, 100.0),
        "dm": ("m", 1.0, 10.0),
        "m": ("m", 1.0, 1.0),
        "km": ("m", 1000.0, 1.0),
        "ms": ("s", 1.0, 1000.0),
        "s": ("s", 1.0, 1.0),
        "min": ("s", 60.0, 1.0),
        "h": ("s", 3600.0, 1.0),
        "deg": ("rad", math.pi, 180.0),
        "rad": ("rad", 1.0, 1.0),
        "mg": ("kg", 1.0, 1_000_000.0),
        "g": ("kg", 1.0, 1000.0),
        "kg": ("kg", 1.0, 1.0),
    }
)
"""Known units and how to convert them to SI."""


class UnitError(ValueError):
    """A quantity with an unknown unit or a value out of range."""


def parse_quantity(text: str) -> Number:
    """Parse ``"30cm"`` into ``Number(0.3, "m")``; raise :class:`UnitError`."""
    match = QUANTITY.fullmatch(text)
    if match is None:
        raise UnitError(f"'{text}' is not a number")
    digits, unit = match.groups()
    value = float(digits)
    si_unit: str | None = None
    if unit:
        conversion = UNITS.get(unit.lower())
        if conversion is None:
            known = ", ".join(UNITS)
            raise UnitError(f"unknown unit '{unit}' (known units: {known})")
        si_unit, multiplier, divisor = conversion
        value = value * multiplier / divisor
    if not math.isfinite(value):
        raise UnitError(f"number '{text}' is out of range")
    return Number(value + 0.0, si_unit)
