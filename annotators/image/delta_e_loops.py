"""CIEDE2000 differences of a few colour pairs in compiled passes, equal to the last bit to
:func:`~annotators.image.color_space.delta_e_2000`.

:func:`delta_e_2000_pairs` computes the formula in three compiled passes over the pairs instead of some sixty NumPy
calls, each with its fixed cost (about 10 times faster on the dozen pairs of shades of a frame; on thousands of
pairs NumPy's vectorised passes are as fast, so the prototype votes keep the NumPy form). The two transcendental
steps, the mean hue's arctangent and the rotation term's exponential, stay NumPy calls between the passes: NumPy's
vectorised ``arctan2`` and ``exp`` round differently from the C library numba calls, and the results must not
change. Every other step is the same IEEE operation, in the same order and precision (single or double, as the
input), as the NumPy form; its constants are held in the input's precision as NumPy casts them. Pairs of opposite
hues (whose mean hue needs the formula's case analysis) are left to the NumPy form. Compiled by numba (machine code
cached on disk next to this file); import this module where it is needed, not at start-up.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from annotators.image.color_space import delta_e_2000

_CONSTANTS = (
    1.5, 0.5, 25.0**7, 2.0, 1.0, 0.17, 0.24, 0.32, 0.20,
    math.cos(math.radians(30.0)), math.sin(math.radians(30.0)),
    math.cos(math.radians(6.0)), math.sin(math.radians(6.0)),
    math.cos(math.radians(63.0)), math.sin(math.radians(63.0)),
    50.0, 0.015, 20.0, 0.045, 2.0 * math.pi, math.radians(275.0), 1.0 / math.radians(25.0), math.radians(60.0),
    1e-6,
)  # fmt: skip
"""The formula's constants as :func:`~annotators.image.color_space.delta_e_2000` writes them, in its order of
use; held in the input's precision (as NumPy casts a Python float against a single-precision array)."""
_SINE_SERIES = tuple((-1.0) ** k / math.factorial(2 * k + 1) for k in range(10))
"""Taylor coefficients of sin(x)/x in powers of x^2, as the NumPy form's ``_small_sine`` uses them."""
_FIELDS = 4
"""Per pair, kept between the passes: the squared terms' sum (L, C, H), the chroma and hue terms, mean C'."""


@njit(cache=True, nogil=True, error_model="numpy")
def _seventh_power_ratio(chroma, big):  # type: ignore[no-untyped-def]
    """``sqrt(C^7 / (C^7 + 25^7))`` with ``big`` = 25^7."""
    squared = chroma * chroma
    seventh = squared * squared * squared * chroma
    return math.sqrt(seventh / (seventh + big))


@njit(cache=True, nogil=True, error_model="numpy")
def _first_pass(lab1, lab2, factors, constants):  # type: ignore[no-untyped-def]
    """The mean hue's cosine and sine of every pair, the terms kept for the last pass, and whether any pair
    has opposite hues."""
    count = lab1.shape[0]
    dtype = lab1.dtype
    cos_out = np.empty(count, dtype=dtype)
    sin_out = np.empty(count, dtype=dtype)
    kept = np.empty((_FIELDS, count), dtype=dtype)
    (three_halves, half, pow25, two, one, t1, t2, t3, t4, cos30, sin30, cos6, sin6, cos63, sin63, fifty, f015, twenty,
     f045) = (constants[0], constants[1], constants[2], constants[3], constants[4], constants[5], constants[6],
              constants[7], constants[8], constants[9], constants[10], constants[11], constants[12], constants[13],
              constants[14], constants[15], constants[16], constants[17], constants[18])  # fmt: skip
    tiny = constants[23]
    zero = one - one
    k_l, k_c, k_h = factors[0], factors[1], factors[2]
    opposite = False
    for k in range(count):
        l1, a1, b1 = lab1[k, 0], lab1[k, 1], lab1[k, 2]
        l2, a2, b2 = lab2[k, 0], lab2[k, 1], lab2[k, 2]
        chroma1 = math.sqrt(a1 * a1 + b1 * b1)
        g1 = three_halves - half * _seventh_power_ratio((chroma1 + math.sqrt(a2 * a2 + b2 * b2)) * half, pow25)
        a1p, a2p = g1 * a1, g1 * a2
        c1p, c2p = math.sqrt(a1p * a1p + b1 * b1), math.sqrt(a2p * a2p + b2 * b2)
        chroma_product = c1p * c2p
        x1 = a1p / c1p if c1p > zero else zero
        y1 = b1 / c1p if c1p > zero else zero
        x2 = a2p / c2p if c2p > zero else zero
        y2 = b2 / c2p if c2p > zero else zero
        dx, dy = x1 - x2, y1 - y2
        d_h = math.copysign(math.sqrt(chroma_product * (dx * dx + dy * dy)), x1 * y2 - y1 * x2)
        x, y = x1 + x2, y1 + y2
        length = math.sqrt(x * x + y * y)
        neutral_both = (c1p == zero) & (c2p == zero)
        c = one if neutral_both else x / length
        s = zero if neutral_both else y / length
        opposite |= (not neutral_both) & (not length >= tiny + tiny)  # near-opposite hues or NaN: NumPy decides
        c2, s2 = two * c * c - one, two * s * c
        c3, s3 = c * (two * c2 - one), s * (two * c2 + one)
        c4, s4 = two * c2 * c2 - one, two * s2 * c2
        t = one - t1 * (c * cos30 + s * sin30) + t2 * c2 + t3 * (c3 * cos6 - s3 * sin6) - t4 * (c4 * cos63 + s4 * sin63)
        l_offset = (l1 + l2) * half - fifty
        l_offset = l_offset * l_offset
        s_l = one + f015 * l_offset / math.sqrt(twenty + l_offset)
        cp_mean = (c1p + c2p) * half
        s_c = one + f045 * cp_mean
        s_h = one + f015 * cp_mean * t
        term_l, term_c, term_h = (l2 - l1) / (k_l * s_l), (c2p - c1p) / (k_c * s_c), d_h / (k_h * s_h)
        cos_out[k], sin_out[k] = c, s
        kept[0, k] = term_l * term_l + term_c * term_c + term_h * term_h
        kept[1, k], kept[2, k], kept[3, k] = term_c, term_h, cp_mean
    return cos_out, sin_out, kept, opposite


@njit(cache=True, nogil=True, error_model="numpy")
def _rotation_exponents(mean, constants):  # type: ignore[no-untyped-def]
    """-rotation^2 of every pair from its mean hue (radians, -pi..pi from the arctangent)."""
    two_pi, centre, scale = constants[19], constants[20], constants[21]
    out = np.empty_like(mean)
    for k in range(mean.size):
        hue = mean[k]
        if hue < 0:
            hue = hue + two_pi
        rotation = (hue - centre) * scale
        out[k] = -rotation * rotation
    return out


@njit(cache=True, nogil=True, error_model="numpy")
def _last_pass(exponentials, kept, constants, series):  # type: ignore[no-untyped-def]
    """The differences from exp(-rotation^2) and the kept terms."""
    two, pow25, sixty = constants[3], constants[2], constants[22]
    out = np.empty_like(exponentials)
    last = series.size - 1
    for k in range(exponentials.size):
        x = sixty * exponentials[k]
        squared = x * x
        value = series[last]
        for n in range(last - 1, -1, -1):
            value = value * squared
            value = value + series[n]
        term_c, term_h = kept[1, k], kept[2, k]
        r_t = -(x * value) * two * _seventh_power_ratio(kept[3, k], pow25)
        out[k] = math.sqrt(kept[0, k] + r_t * term_c * term_h)
    return out


def _compiled(lab1: np.ndarray, lab2: np.ndarray, factors: tuple[float, float, float]) -> np.ndarray | None:
    """The differences, or None when a pair has opposite hues."""
    dtype = np.float32 if lab1.dtype == np.float32 and lab2.dtype == np.float32 else np.float64
    first = np.ascontiguousarray(lab1, dtype=dtype).reshape(-1, 3)
    second = np.ascontiguousarray(lab2, dtype=dtype).reshape(-1, 3)
    constants = np.array(_CONSTANTS, dtype=dtype)
    cos, sin, kept, opposite = _first_pass(first, second, np.array(factors, dtype=dtype), constants)
    if opposite:
        return None
    exponents = _rotation_exponents(np.arctan2(sin, cos), constants)
    return _last_pass(np.exp(exponents), kept, constants, np.array(_SINE_SERIES, dtype=dtype))


def delta_e_2000_pairs(
    lab1: np.ndarray, lab2: np.ndarray, k_l: float = 1.0, k_c: float = 1.0, k_h: float = 1.0
) -> np.ndarray:
    """CIEDE2000 differences of the colour pairs ``lab1[k]``, ``lab2[k]`` (Nx3 each): N, equal to
    ``delta_e_2000(lab1, lab2, k_l, k_c, k_h)`` to the last bit."""
    lab1, lab2 = np.asarray(lab1), np.asarray(lab2)
    if lab1.shape != lab2.shape:
        raise ValueError(f"colour pairs need two lists of one length, got {lab1.shape} and {lab2.shape}")
    if lab1.shape[0]:
        found = _compiled(lab1, lab2, (k_l, k_c, k_h))
        if found is not None:
            return found
    return delta_e_2000(lab1, lab2, k_l, k_c, k_h)
