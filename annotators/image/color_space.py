"""CIELAB and the CIEDE2000 colour difference: the perceptual space colour names are decided in.

sRGB (IEC 61966-2-1, D65 white) is linearised, converted to XYZ and then to CIELAB (CIE 15:2004) relative to the
D65 white. :func:`delta_e_2000` is the CIEDE2000 formula as stated by Sharma, Wu and Dalal (2005), "The CIEDE2000
color-difference formula: implementation notes, supplementary test data, and mathematical observations", Color
Research & Application 30(1).
"""

from __future__ import annotations

import math

import numpy as np

SRGB_TO_XYZ = np.array(
    [
        [0.4124564, 0.3575761, 0.1804375],
        [0.2126729, 0.7151522, 0.0721750],
        [0.0193339, 0.1191920, 0.9503041],
    ]
)
"""Linear sRGB (D65) to CIE XYZ."""

D65_WHITE = SRGB_TO_XYZ.sum(axis=1)
"""XYZ of the sRGB white (Y = 1)."""

_RELATIVE_XYZ = SRGB_TO_XYZ.T / D65_WHITE
"""Linear sRGB (rows) to XYZ relative to the white: ``linear @ _RELATIVE_XYZ``."""

RELATIVE_XYZ32 = _RELATIVE_XYZ.astype(np.float32)
""":data:`_RELATIVE_XYZ` in single precision, as :func:`linear_to_lab` converts single-precision colours."""


def _decode(values: np.ndarray) -> np.ndarray:
    return np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4)


_UINT8_TO_LINEAR = _decode(np.arange(256) / 255.0)
UINT8_TO_LINEAR32 = _UINT8_TO_LINEAR.astype(np.float32)
"""Linear-light value of each sRGB level (0..255), in single precision."""


def srgb_to_linear(rgb: np.ndarray) -> np.ndarray:
    """Linear-light values (float64, 0..1) of sRGB values (uint8 0..255 or float 0..1), any shape ``...x3``."""
    values = np.asarray(rgb)
    if values.dtype == np.uint8:
        return _UINT8_TO_LINEAR[values]
    return _decode(values.astype(np.float64))


def linear_to_srgb(linear: np.ndarray) -> np.ndarray:
    """sRGB values (float, 0..1, clipped) of linear-light values."""
    values = np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0)
    return np.where(values <= 0.0031308, values * 12.92, 1.055 * values ** (1 / 2.4) - 0.055)


def linear_to_lab(linear: np.ndarray) -> np.ndarray:
    """CIELAB (D65) of linear sRGB values, any shape ``...x3`` (values above 1 are allowed: L* above 100), in
    single precision for single-precision input, else in double."""
    values = np.asarray(linear)
    dtype = np.float32 if values.dtype == np.float32 else np.float64
    epsilon, kappa = 216 / 24389, 24389 / 27
    if values.shape == (3,) and dtype == np.float64:  # one colour: the same operations on Python floats
        xyz = values.astype(dtype, copy=False) @ _RELATIVE_XYZ
        fx, fy, fz = (
            root if value > epsilon else (kappa * value + 16) / 116
            for value, root in zip(xyz.tolist(), np.cbrt(xyz).tolist(), strict=True)
        )
        return np.array([116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)])
    xyz = values.astype(dtype, copy=False) @ (RELATIVE_XYZ32 if dtype == np.float32 else _RELATIVE_XYZ)
    f = np.cbrt(xyz)
    dim = xyz <= epsilon  # the linear segment near black (the cube root elsewhere)
    if np.any(dim):
        f[dim] = (kappa * xyz[dim] + 16) / 116
    lab = np.empty(f.shape, dtype=dtype)
    lab[..., 0] = 116 * f[..., 1] - 16
    lab[..., 1] = 500 * (f[..., 0] - f[..., 1])
    lab[..., 2] = 200 * (f[..., 1] - f[..., 2])
    return lab


def srgb_to_lab(rgb: np.ndarray) -> np.ndarray:
    """CIELAB (D65) of sRGB values (uint8 or float 0..1), any shape ``...x3``."""
    return linear_to_lab(srgb_to_linear(rgb))


_TWO_PI = 2.0 * math.pi
_ROTATION_CENTRE, _ROTATION_SCALE, _SIXTY_DEGREES = math.radians(275.0), 1.0 / math.radians(25.0), math.radians(60.0)
"""The rotation term's hue centre (275 degrees), 1 / its width (25 degrees) and its largest angle (60 degrees)."""
_POW25_7 = 25.0**7
_T_TERMS = tuple((math.cos(math.radians(d)), math.sin(math.radians(d))) for d in (30.0, 6.0, 63.0))
"""cos and sin of the phase offsets of the hue weighting T: 30, 6 and 63 degrees."""
_SINE_SERIES = tuple((-1.0) ** k / math.factorial(2 * k + 1) for k in range(10))
"""Taylor coefficients of sin(x)/x in powers of x^2 (1, -1/3!, 1/5!, ...): exact to rounding for |x| <= pi/3."""


def _seventh_power_ratio(chroma: np.ndarray) -> np.ndarray:
    """``sqrt(C^7 / (C^7 + 25^7))``, the chroma factor of the G and R_C terms."""
    squared = chroma * chroma
    seventh = squared * squared * squared * chroma
    return np.sqrt(seventh / (seventh + _POW25_7))


def _small_sine(x: np.ndarray) -> np.ndarray:
    """sin(x) for 0 <= x <= pi/3 by its Taylor series (cheaper than ``np.sin`` on many values)."""
    squared = x * x
    series = np.full_like(x, _SINE_SERIES[-1])
    for coefficient in _SINE_SERIES[-2::-1]:
        series *= squared
        series += coefficient
    return x * series


def _hue_units(ap: np.ndarray, b: np.ndarray, cp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The hue unit vector (a'/C', b/C') of colours, (0, 0) for a neutral one (C' = 0)."""
    chromatic = cp > 0
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(chromatic, ap / cp, 0.0), np.where(chromatic, b / cp, 0.0)


def _mean_hue(
    units: tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
    neutral_both: np.ndarray,
    primes: tuple[np.ndarray, ...],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The mean hue (radians, 0..2 pi) and its cosine and sine, from the two hue unit vectors ``units`` (x1, y1,
    x2, y2): the direction of their sum is the bisector of the smaller arc, as the mean hue is, and a neutral
    colour adds nothing (its hue counts as 0). Where the hues are opposite (the sum vanishes) the mean hue comes
    from the angles of ``primes`` (a1', b1, a2', b2) by the formula's case analysis."""
    x1, y1, x2, y2 = units
    x, y = x1 + x2, y1 + y2
    length = np.sqrt(x * x + y * y)
    with np.errstate(invalid="ignore", divide="ignore"):
        cos, sin = np.where(neutral_both, 1.0, x / length), np.where(neutral_both, 0.0, y / length)
    mean = np.arctan2(sin, cos)
    mean = np.where(mean < 0.0, mean + _TWO_PI, mean)
    opposite = ~neutral_both & (length < 1e-6)
    if np.any(opposite):
        a1p, b1, a2p, b2 = (np.broadcast_to(v, opposite.shape)[opposite] for v in primes)
        h1, h2 = np.arctan2(b1, a1p) % _TWO_PI, np.arctan2(b2, a2p) % _TWO_PI
        total = h1 + h2
        fixed = np.where(
            np.abs(h2 - h1) <= np.pi,
            total * 0.5,
            np.where(total < _TWO_PI, (total + _TWO_PI) * 0.5, (total - _TWO_PI) * 0.5),
        )
        mean[opposite], cos[opposite], sin[opposite] = fixed, np.cos(fixed), np.sin(fixed)
    return mean, cos, sin


def delta_e_2000(
    lab1: np.ndarray, lab2: np.ndarray, k_l: float = 1.0, k_c: float = 1.0, k_h: float = 1.0
) -> np.ndarray:
    """CIEDE2000 differences between CIELAB colours; the inputs broadcast against each other (``...x3``).

    ``k_l``, ``k_c`` and ``k_h`` are the formula's parametric factors (1 for the reference conditions; a larger
    factor makes differences in lightness, chroma or hue count less). Computed with few trigonometric calls
    (they dominate on many pairs): the hue difference term and the mean hue from the hue unit vectors (radians),
    T's four cosines from the mean hue's cosine and sine by multiple-angle identities, and the rotation term's
    sine by its Taylor series. Computed in single precision when both inputs are single precision (about 1e-4
    relative from double precision), else in double."""
    lab1, lab2 = np.asarray(lab1), np.asarray(lab2)
    dtype = np.float32 if lab1.dtype == np.float32 and lab2.dtype == np.float32 else np.float64
    lab1, lab2 = lab1.astype(dtype, copy=False), lab2.astype(dtype, copy=False)
    l1, a1, b1 = lab1[..., 0], lab1[..., 1], lab1[..., 2]
    l2, a2, b2 = lab2[..., 0], lab2[..., 1], lab2[..., 2]
    g1 = 1.5 - 0.5 * _seventh_power_ratio((np.sqrt(a1 * a1 + b1 * b1) + np.sqrt(a2 * a2 + b2 * b2)) * 0.5)  # 1 + G
    a1p, a2p = g1 * a1, g1 * a2
    c1p, c2p = np.sqrt(a1p * a1p + b1 * b1), np.sqrt(a2p * a2p + b2 * b2)
    chroma_product = c1p * c2p
    (x1, y1), (x2, y2) = _hue_units(a1p, b1, c1p), _hue_units(a2p, b2, c2p)
    # 2 sqrt(C1' C2') sin(dh / 2) = sqrt(C1' C2') |u1 - u2|, signed as dh = h2' - h1' wrapped to (-pi, pi]
    dx, dy = x1 - x2, y1 - y2
    d_h = np.copysign(np.sqrt(chroma_product * (dx * dx + dy * dy)), x1 * y2 - y1 * x2)
    h_mean, c, s = _mean_hue((x1, y1, x2, y2), (c1p == 0) & (c2p == 0), (a1p, b1, a2p, b2))
    c2, s2 = 2.0 * c * c - 1.0, 2.0 * s * c
    c3, s3 = c * (2.0 * c2 - 1.0), s * (2.0 * c2 + 1.0)
    c4, s4 = 2.0 * c2 * c2 - 1.0, 2.0 * s2 * c2
    (cos30, sin30), (cos6, sin6), (cos63, sin63) = _T_TERMS
    t = (
        1.0
        - 0.17 * (c * cos30 + s * sin30)
        + 0.24 * c2
        + 0.32 * (c3 * cos6 - s3 * sin6)
        - 0.20 * (c4 * cos63 + s4 * sin63)
    )
    l_offset = (l1 + l2) * 0.5 - 50.0
    l_offset = l_offset * l_offset
    s_l = 1.0 + 0.015 * l_offset / np.sqrt(20.0 + l_offset)
    cp_mean = (c1p + c2p) * 0.5
    s_c = 1.0 + 0.045 * cp_mean
    s_h = 1.0 + 0.015 * cp_mean * t
    rotation = (h_mean - _ROTATION_CENTRE) * _ROTATION_SCALE
    r_t = -_small_sine(_SIXTY_DEGREES * np.exp(-rotation * rotation)) * 2.0 * _seventh_power_ratio(cp_mean)
    term_l, term_c, term_h = (l2 - l1) / (k_l * s_l), (c2p - c1p) / (k_c * s_c), d_h / (k_h * s_h)
    return np.sqrt(term_l * term_l + term_c * term_c + term_h * term_h + r_t * term_c * term_h)
