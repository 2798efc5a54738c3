"""CIEDE2000 differences of colour pairs in compiled passes, equal to the last bit to
:func:`~annotators.image.color_space.delta_e_2000`.

:func:`delta_e_2000_pairs` (colour pairs: a frame's shades) and :func:`delta_e_2000_outer` (every colour of one list
against every colour of another: the surfaces against the colour-name prototypes) compute the formula in three
compiled passes over the pairs, held as columns, instead of some sixty NumPy calls with a temporary each (4 times
faster on the 17,000 pairs of a frame's prototype votes, 10 times on the dozen pairs of its shades). The two
transcendental steps, the mean hue's arctangent and the rotation term's exponential, stay NumPy calls between the
passes: NumPy's vectorised ``arctan2`` and ``exp`` round differently from the C library numba calls, and the results
must not change. Every other step is the same IEEE operation, in the same order and precision (single or double, as
the input), as the NumPy form; its constants are held in the input's precision as NumPy casts them. Pairs of
opposite hues (whose mean hue needs the formula's case analysis) are left to the NumPy form. Compiled by numba
(machine code cached on disk next to this file); import this module where it is needed, not at start-up.
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


@njit(cache=True, nogil=True, error_model="numpy")
def _seventh_power_ratio(chroma, big):  # type: ignore[no-untyped-def]
    """``sqrt(C^7 / (C^7 + 25^7))`` with ``big`` = 25^7."""
    squared = chroma * chroma
    seventh = squared * squared * squared * chroma
    return math.sqrt(seventh / (seventh + big))


@njit(cache=True, nogil=True, error_model="numpy")
def _first_pass(first, second, factors, constants):  # type: ignore[no-untyped-def]
    """For the pairs of colours given as columns (``first``, ``second``: 3xN, L*, a*, b* rows): the mean hue's
    cosine and sine, the terms kept for the last pass (the squared lightness, chroma and hue terms' sum, the
    chroma and hue terms, mean C') and whether the hues are (nearly) opposite, each an N array. One branch-free
    loop over contiguous arrays, which the compiler runs on several pairs at once."""
    count = first.shape[1]
    cos_out, sin_out = np.empty(count, dtype=first.dtype), np.empty(count, dtype=first.dtype)
    squares, chroma_terms = np.empty(count, dtype=first.dtype), np.empty(count, dtype=first.dtype)
    hue_terms, mean_chromas = np.empty(count, dtype=first.dtype), np.empty(count, dtype=first.dtype)
    opposite = np.empty(count, dtype=np.bool_)
    (three_halves, half, pow25, two, one, t1, t2, t3, t4, cos30, sin30, cos6, sin6, cos63, sin63, fifty, f015, twenty,
     f045) = (constants[0], constants[1], constants[2], constants[3], constants[4], constants[5], constants[6],
              constants[7], constants[8], constants[9], constants[10], constants[11], constants[12], constants[13],
              constants[14], constants[15], constants[16], constants[17], constants[18])  # fmt: skip
    tiny = constants[23]
    zero = one - one
    k_l, k_c, k_h = factors[0], factors[1], factors[2]
    l1s, a1s, b1s, l2s, a2s, b2s = first[0], first[1], first[2], second[0], second[1], second[2]
    for k in range(count):
        l1, a1, b1, l2, a2, b2 = l1s[k], a1s[k], b1s[k], l2s[k], a2s[k], b2s[k]
        mean_chroma = (math.sqrt(a1 * a1 + b1 * b1) + math.sqrt(a2 * a2 + b2 * b2)) * half
        g1 = three_halves - half * _seventh_power_ratio(mean_chroma, pow25)
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
        opposite[k] = (not neutral_both) & (not length >= tiny + tiny)  # near-opposite hues: NumPy decides
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
        squares[k] = term_l * term_l + term_c * term_c + term_h * term_h
        chroma_terms[k], hue_terms[k], mean_chromas[k] = term_c, term_h, cp_mean
    return cos_out, sin_out, (squares, chroma_terms, hue_terms, mean_chromas), opposite


@njit(cache=True, nogil=True, error_model="numpy")
def _rotation_exponents(mean, constants):  # type: ignore[no-untyped-def]
    """-rotation^2 of every pair from its mean hue (radians, -pi..pi from the arctangent)."""
    two_pi, centre, scale = constants[19], constants[20], constants[21]
    zero = two_pi - two_pi
    out = np.empty_like(mean)
    for k in range(mean.size):
        hue = mean[k]
        hue = hue + two_pi if hue < zero else hue
        rotation = (hue - centre) * scale
        out[k] = -rotation * rotation
    return out


@njit(cache=True, nogil=True, error_model="numpy")
def _last_pass(exponentials, kept, constants, series):  # type: ignore[no-untyped-def]
    """The differences from exp(-rotation^2) and the terms :func:`_first_pass` kept."""
    two, pow25, sixty = constants[3], constants[2], constants[22]
    squares, chroma_terms, hue_terms, mean_chromas = kept
    (s0, s1, s2, s3, s4, s5, s6, s7, s8, s9) = (series[0], series[1], series[2], series[3], series[4], series[5],
                                                series[6], series[7], series[8], series[9])  # fmt: skip
    out = np.empty_like(exponentials)
    for k in range(exponentials.size):
        x = sixty * exponentials[k]
        squared = x * x
        value = ((((((((s9 * squared + s8) * squared + s7) * squared + s6) * squared + s5) * squared + s4) * squared
                  + s3) * squared + s2) * squared + s1) * squared + s0  # fmt: skip
        r_t = -(x * value) * two * _seventh_power_ratio(mean_chromas[k], pow25)
        out[k] = math.sqrt(squares[k] + r_t * chroma_terms[k] * hue_terms[k])
    return out


def _compiled(
    lab1: np.ndarray, lab2: np.ndarray, outer: bool, factors: tuple[float, float, float]
) -> np.ndarray | None:
    """The differences (of the pairs, or of every colour of ``lab1`` against every colour of ``lab2`` when
    ``outer``, row by row, flat), or None when the NumPy form must decide (opposite hues, values not finite)."""
    dtype = np.float32 if lab1.dtype == np.float32 and lab2.dtype == np.float32 else np.float64
    first = np.asarray(lab1, dtype=dtype).reshape(-1, 3)
    second = np.asarray(lab2, dtype=dtype).reshape(-1, 3)
    if not (np.isfinite(first).all() and np.isfinite(second).all()):
        return None
    if outer:  # the pairs spelt out, as columns
        first, second = np.repeat(first.T, second.shape[0], axis=1), np.tile(second.T, (1, first.shape[0]))
    else:
        first, second = np.ascontiguousarray(first.T), np.ascontiguousarray(second.T)
    constants = np.array(_CONSTANTS, dtype=dtype)
    cos, sin, kept, opposite = _first_pass(first, second, np.array(factors, dtype=dtype), constants)
    if opposite.any():
        return None
    exponents = _rotation_exponents(np.arctan2(sin, cos), constants)
    return _last_pass(np.exp(exponents), kept, constants, np.array(_SINE_SERIES, dtype=dtype))


def delta_e_2000_outer(
    lab1: np.ndarray, lab2: np.ndarray, k_l: float = 1.0, k_c: float = 1.0, k_h: float = 1.0
) -> np.ndarray:
    """CIEDE2000 differences of every colour of ``lab1`` (Nx3) against every colour of ``lab2`` (Mx3): NxM,
    equal to ``delta_e_2000(lab1[:, None, :], lab2[None, :, :], k_l, k_c, k_h)`` to the last bit."""
    lab1, lab2 = np.asarray(lab1), np.asarray(lab2)
    if lab1.shape[0] and lab2.shape[0]:
        found = _compiled(lab1, lab2, True, (k_l, k_c, k_h))
        if found is not None:
            return found.reshape(lab1.shape[0], lab2.shape[0])
    return delta_e_2000(lab1[:, None, :], lab2[None, :, :], k_l, k_c, k_h)


def delta_e_2000_pairs(
    lab1: np.ndarray, lab2: np.ndarray, k_l: float = 1.0, k_c: float = 1.0, k_h: float = 1.0
) -> np.ndarray:
    """CIEDE2000 differences of the colour pairs ``lab1[k]``, ``lab2[k]`` (Nx3 each): N, equal to
    ``delta_e_2000(lab1, lab2, k_l, k_c, k_h)`` to the last bit."""
    lab1, lab2 = np.asarray(lab1), np.asarray(lab2)
    if lab1.shape != lab2.shape:
        raise ValueError(f"colour pairs need two lists of one length, got {lab1.shape} and {lab2.shape}")
    if lab1.shape[0]:
        found = _compiled(lab1, lab2, False, (k_l, k_c, k_h))
        if found is not None:
            return found
    return delta_e_2000(lab1, lab2, k_l, k_c, k_h)
