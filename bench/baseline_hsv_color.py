"""The colour namer as it was before CIELAB naming (HSV rules, one name per object), kept as the baseline that
bench/bench_color.py compares the current namer with. Not used by the system."""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np


@dataclass(frozen=True)
class ColorRule:
    """A colour name for pixels whose hue (degrees), saturation and value (0..1) lie in these half-open ranges."""

    name: str
    hues: tuple[tuple[float, float], ...] = ((0.0, 360.1),)
    saturation: tuple[float, float] = (0.0, 1.01)
    value: tuple[float, float] = (0.0, 1.01)


ACHROMATIC_SATURATION = 0.28
"""Pixels less saturated than this count as achromatic: white, grey or black."""

DARK_VALUE = 0.25
"""Pixels darker than this count as achromatic unless they are at least ``DARK_SATURATION`` saturated."""

DARK_SATURATION = 0.6
"""Dark pixels (value at least ``BLACK_VALUE``) this saturated keep their hue (a navy mug is blue, not black)."""

BLACK_VALUE = 0.1
"""Pixels darker than this are always achromatic."""

ACHROMATIC_RULES: tuple[ColorRule, ...] = (
    ColorRule("black", value=(0.0, 0.22)),
    ColorRule("grey", value=(0.22, 0.52)),
    ColorRule("white", value=(0.52, 1.01)),
)
"""How an object's achromatic pixels are named, by the 80th percentile of their value."""

COLOR_RULES: tuple[ColorRule, ...] = (
    ColorRule("brown", hues=((8.0, 45.0),), value=(0.0, 0.55)),
    ColorRule("pink", hues=((330.0, 360.0), (0.0, 8.0)), saturation=(0.0, 0.5), value=(0.75, 1.01)),
    ColorRule("red", hues=((345.0, 360.0), (0.0, 8.0))),
    ColorRule("orange", hues=((8.0, 42.0),)),
    ColorRule("yellow", hues=((42.0, 70.0),)),
    ColorRule("green", hues=((70.0, 165.0),)),
    ColorRule("blue", hues=((165.0, 255.0),)),
    ColorRule("purple", hues=((255.0, 290.0),)),
    ColorRule("pink", hues=((290.0, 345.0),)),
)
"""Chromatic colour names; the first matching rule names a pixel."""

COLOR_NAMES: tuple[str, ...] = tuple(dict.fromkeys(r.name for r in ACHROMATIC_RULES + COLOR_RULES))
"""Every colour name this annotator can report."""

ACHROMATIC = len(COLOR_NAMES)
"""The code :func:`classify_pixels` gives unsaturated (or very dark) pixels."""

_RULE_CODES = tuple(COLOR_NAMES.index(rule.name) for rule in COLOR_RULES)


def _in_ranges(values: np.ndarray, ranges: tuple[tuple[float, float], ...]) -> np.ndarray:
    hit = np.zeros(values.shape, dtype=bool)
    for low, high in ranges:
        hit |= (values >= low) & (values < high)
    return hit


def classify_pixels(rgb: np.ndarray) -> np.ndarray:
    """Colour codes (indices into :data:`COLOR_NAMES`, or :data:`ACHROMATIC`) of N RGB pixels (Nx3 uint8)."""
    hsv = cv2.cvtColor(np.ascontiguousarray(rgb, dtype=np.uint8).reshape(-1, 1, 3), cv2.COLOR_RGB2HSV_FULL)
    hsv = hsv.reshape(-1, 3).astype(np.float32)
    hue = hsv[:, 0] * np.float32(360.0 / 256.0)
    saturation = hsv[:, 1] * np.float32(1 / 255)
    value = hsv[:, 2] * np.float32(1 / 255)
    codes = np.full(hue.shape, ACHROMATIC, dtype=np.int64)
    bright = (saturation >= ACHROMATIC_SATURATION) & (value >= DARK_VALUE)
    dark = (saturation >= DARK_SATURATION) & (value >= BLACK_VALUE)
    open_ = bright | dark
    for rule, code in zip(COLOR_RULES, _RULE_CODES, strict=True):
        hit = open_ & _in_ranges(hue, rule.hues)
        if rule.saturation != (0.0, 1.01):
            hit &= (saturation >= rule.saturation[0]) & (saturation < rule.saturation[1])
        if rule.value != (0.0, 1.01):
            hit &= (value >= rule.value[0]) & (value < rule.value[1])
        codes[hit] = code
        open_ &= ~hit
    return codes


def classify_names(rgb: np.ndarray) -> list[str]:
    """The colour name of each of N RGB pixels (``"achromatic"`` for unsaturated ones)."""
    names = (*COLOR_NAMES, "achromatic")
    return [names[code] for code in classify_pixels(rgb)]


def achromatic_name(rgb: np.ndarray) -> str:
    """White, grey or black for a set of unsaturated pixels (Nx3), by the 80th percentile of their value."""
    brightness = np.sort(rgb.max(axis=1))
    value = float(brightness[round(0.8 * (brightness.size - 1))]) / 255.0
    for rule in ACHROMATIC_RULES:
        if rule.value[0] <= value < rule.value[1]:
            return rule.name
    return ACHROMATIC_RULES[-1].name


def name_color(rgb: np.ndarray) -> tuple[str, float, dict[str, float]]:
    """The dominant colour name of N RGB pixels, its share, and the share of every name present (largest first)."""
    if rgb.shape[0] == 0:
        raise ValueError("no pixels to name a colour for")
    codes = classify_pixels(rgb)
    achromatic = codes == ACHROMATIC
    if achromatic.any():
        codes[achromatic] = COLOR_NAMES.index(achromatic_name(rgb[achromatic]))
    counts = np.bincount(codes, minlength=len(COLOR_NAMES))
    order = np.argsort(-counts, kind="stable")
    shares = {COLOR_NAMES[i]: counts[i] / codes.size for i in order if counts[i]}
    winner = COLOR_NAMES[int(order[0])]
    return winner, shares[winner], shares
