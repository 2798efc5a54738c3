"""Colour names a person would agree with: an object's dominant colour, and a second one when it has two.

How an object's pixels are named (:func:`name_colors`):

1. **White balance and surround** (:func:`estimate_frame_light`, once per frame). The illuminant is estimated
   with the grey-edge hypothesis (van de Weijer, Gevers and Gijsenij 2007: the average colour derivative of a
   scene is achromatic; first order, Minkowski norm 1, Gaussian sigma 1) and divided out in linear RGB (von
   Kries). Grey-world and the support plane are no good references on wooden or coloured tables. The surround
   is the frame's median luminance after the correction: it anchors white against grey.
2. **Highlights, shadows, edges** (:func:`object_surfaces`). Pixels with a clipped channel and no dark channel
   are highlights or an over-exposed white surface: they count as white only when they are most of the object.
   Near-black pixels form a dark pool: shadows, left out unless the object is dark overall or the pool has the
   colour of one of the object's surfaces (a black drill grip, a navy mug's shaded side). Pixels on strong
   colour edges (print outlines, the object's border) mix two surfaces and are left out when enough remain.
3. **Surfaces**. The other pixels are grouped in the log-chroma plane (:func:`chroma_plane`: CIELAB hue as
   direction, log chroma as radius), where the lit and the shaded side of a surface stay together. A surface's
   colour is its median chromaticity ``(a*, b*) / (L* + 16)`` (unchanged by shading) at its lit lightness (a high
   percentile of its L*): people name the lit surface. An unsaturated group is split into black and the rest.
   A group whose colour is a mixture of two larger groups (pixels blending a red and a white print) joins the
   nearer of the two.
4. **Names** (:func:`name_surface`). An unsaturated surface is white when its lit luminance is near the
   surround's or above, else grey, or black when dark. A saturated one is named in CIELAB by CIEDE2000 distances
   to the colour-name prototypes of :mod:`annotators.image.color_prototypes` (the xkcd colour survey), as a
   kernel density classifier: each term's prototypes vote with a Gaussian of their distance, and the term's
   share of the votes is the name's certainty.
5. **Dominant and second colour**. A name's share is the share of the named pixels its surfaces hold; the
   second colour is reported when its share reaches ``second_share``. Confidence = share x certainty.

:data:`COLOR_TERMS` is the one list of names this namer reports: they are the lower-case labels of the
ontology's colour classes (``rk:Color`` in ontology/perception.ttl), and the annotator's capability is derived
from it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import cv2
import numpy as np

from annotators.image.color_prototypes import prototypes
from annotators.image.color_space import delta_e_2000, linear_to_lab, linear_to_srgb, srgb_to_linear
from annotators.image.pixel_expert import image_and_hypotheses
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CasType, ColorImage, ObjectHypothesis, SemanticColor

COLOR_TERMS: tuple[str, ...] = (
    "red", "orange", "yellow", "green", "blue", "purple", "pink", "brown", "white", "grey", "black",
)  # fmt: skip
"""The colour names reported: the eleven basic colour terms of Berlin and Kay, as the ontology labels them."""

ACHROMATIC_TERMS: tuple[str, ...] = ("white", "grey", "black")
"""The names of unsaturated surfaces, decided by lightness rather than by prototypes."""

CHROMATIC_TERMS: tuple[str, ...] = tuple(t for t in COLOR_TERMS if t not in ACHROMATIC_TERMS)
"""The names decided by the colour-name prototypes."""

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
"""Relative luminance Y of linear sRGB."""

WHITE_LAB = np.array([100.0, 0.0, 0.0])

_PROTOTYPE_TERMS, _PROTOTYPE_LAB, _ = prototypes(CHROMATIC_TERMS)
_PROTOTYPE_CODES = np.array([CHROMATIC_TERMS.index(t) for t in _PROTOTYPE_TERMS])


@dataclass(frozen=True)
class NamingParameters:
    """The constants of colour naming (see the module docstring for what each step does)."""

    edge_step: float = 18.0
    """Pixels whose colour changes by more than this many sRGB levels per pixel lie on an edge."""
    min_interior_share: float = 0.4
    """Edge pixels are left out only when at least this share of the pixels remains."""
    clipped_level: int = 240
    """A channel at or above this sRGB level is clipped."""
    highlight_floor: int = 170
    """A clipped pixel whose channels are all at least this level is a highlight (or an over-exposed white,
    whose hue clipping has made unreliable); a clipped saturated pixel (a bright yellow) keeps its hue."""
    highlight_keep_share: float = 0.5
    """Highlights count as white when at least this share of the object is highlight."""
    dark_lightness: float = 15.0
    """Pixels darker than this L* (after white balance) form the dark pool."""
    dark_keep_share: float = 0.25
    """The dark pool counts on its own when at least this share of the object is in it."""
    dark_saturation: float = 0.35
    """The dark pool is a dark colour, not black, when its mean sRGB colour is this saturated ((max-min)/max)."""
    dark_span: int = 8
    """... and its channels differ by at least this many sRGB levels."""
    chroma_softness: float = 20.0
    """Chroma scale of the log-chroma plane pixels are grouped in."""
    group_radius: float = 0.3
    """Radius of a surface group in the log-chroma plane."""
    min_group_share: float = 0.08
    """Groups smaller than this share of the object are noise (small print, mixed pixels)."""
    max_groups: int = 5
    mixture_tolerance: float = 0.02
    """A group whose rg-chromaticity lies this close to the segment between two larger groups is their mixture."""
    lit_percentile: float = 80.0
    """The lit lightness of a surface: this percentile of its L*."""
    achromatic_chroma: float = 12.0
    """Surfaces whose a* (green-magenta) and b* (blue-yellow) lie within the ellipse of this radius along a* ..."""
    daylight_chroma: float = 20.0
    """... and this radius along b* are unsaturated: white, grey or black. Residual white-balance errors run along
    the daylight locus (bluish or yellowish whites), and people discount casts along it most."""
    dark_tint_ratio: float = 0.2
    """For dark colours the ellipse's radii are at most this (along a*) and 1.5 x this (along b*) times L* + 16."""
    white_surround_ratio: float = 0.85
    """An unsaturated surface whose lit luminance is at least this fraction of the surround's is white."""
    white_lightness: float = 55.0
    """... and its lit L* is at least this (a surface darker than this is not seen as white even in the dark)."""
    black_lightness: float = 38.0
    """An unsaturated surface darker than this lit L* (and not white) is black."""
    lightness_factor: float = 1.0
    """CIEDE2000 k_L when comparing with the prototypes."""
    chroma_factor: float = 1.0
    """CIEDE2000 k_C when comparing with the prototypes (camera colours are less saturated than the survey's)."""
    kernel_width: float = 8.0
    """Width (CIEDE2000 units) of each prototype's vote."""
    second_share: float = 0.2
    """A second colour is reported when its share of the named pixels is at least this ..."""
    second_confidence: float = 0.1
    """... and its confidence at least this."""


DEFAULT_PARAMETERS = NamingParameters()


@dataclass(frozen=True)
class FrameLight:
    """The light of one frame: linear-RGB white-balance gains and the surround's luminance after them."""

    gains: np.ndarray
    surround: float


NEUTRAL_LIGHT = FrameLight(gains=np.ones(3), surround=0.18)
"""No white-balance correction and a mid-grey surround (for pixels without their frame)."""


@dataclass(frozen=True)
class Surface:
    """One surface of an object: its colour (CIELAB at its lit lightness), its mean linear RGB, its pixel
    count and its kind: ``"regular"`` or ``"dark"`` (the near-black pool)."""

    lab: np.ndarray
    linear: np.ndarray
    pixels: int
    kind: str


@dataclass(frozen=True)
class SurfaceName:
    """The name of one surface colour and how certain it is (0..1)."""

    name: str
    certainty: float


@dataclass(frozen=True)
class NamedColor:
    """One colour of an object: its name, its share of the named pixels and its confidence."""

    name: str
    share: float
    confidence: float


def grey_edge_illuminant(linear: np.ndarray, sigma: float = 1.0) -> np.ndarray:
    """The illuminant colour (3 values with mean 1) of a linear RGB image by first-order grey-edge (p = 1)."""
    smooth = cv2.GaussianBlur(linear.astype(np.float32), (0, 0), sigma)
    gx = cv2.Sobel(smooth, cv2.CV_32F, 1, 0)
    gy = cv2.Sobel(smooth, cv2.CV_32F, 0, 1)
    magnitude = np.sqrt(gx * gx + gy * gy).reshape(-1, 3)
    unclipped = linear.reshape(-1, 3).max(axis=1) < 0.97
    if np.count_nonzero(unclipped) >= 100:
        magnitude = magnitude[unclipped]
    illuminant = magnitude.astype(np.float64).mean(axis=0)
    if not np.all(illuminant > 0):
        return np.ones(3)
    return illuminant / illuminant.mean()


def estimate_frame_light(image: np.ndarray, max_gain: float = 2.0) -> FrameLight:
    """White-balance gains (grey-edge, each within ``1/max_gain..max_gain``) and surround luminance of an RGB
    frame (HxWx3 uint8)."""
    linear = srgb_to_linear(image).astype(np.float32)
    gains = np.clip(1.0 / grey_edge_illuminant(linear), 1.0 / max_gain, max_gain)
    surround = float(np.median(linear.reshape(-1, 3) @ (gains * LUMINANCE).astype(np.float32)))
    return FrameLight(gains=gains, surround=max(surround, 1e-4))


def edge_strength(image: np.ndarray) -> np.ndarray:
    """Per-pixel colour step (sRGB levels per pixel, the largest over the channels) of an RGB image."""
    values = image.astype(np.float32)
    gx = cv2.Sobel(values, cv2.CV_32F, 1, 0, ksize=3)
    gy = cv2.Sobel(values, cv2.CV_32F, 0, 1, ksize=3)
    return np.sqrt(gx * gx + gy * gy).max(axis=2) / 8.0


def chroma_plane(lab: np.ndarray, softness: float) -> np.ndarray:
    """Pixels (CIELAB, Nx3) in the log-chroma plane: hue as direction, ``log(1 + C*/softness)`` as radius.

    Distances there compare saturated colours by hue and chroma ratio (shading scales chroma), while the hue
    of a nearly neutral pixel, which is noise, hardly counts."""
    chroma = np.hypot(lab[:, 1], lab[:, 2])
    scale = np.log1p(chroma / softness) / np.maximum(chroma, 1e-9)
    return lab[:, 1:] * scale[:, None]


def _modes(features: np.ndarray, radius: float, min_count: float, max_groups: int) -> np.ndarray:
    """Centres of the densest modes of 2-D features: flat-kernel mean shift from the fullest histogram cell,
    each mode taking the features within ``radius``; modes with fewer than ``min_count`` members are dropped."""
    remaining = np.ones(features.shape[0], dtype=bool)
    centres: list[np.ndarray] = []
    edges = np.arange(-4.0, 4.0 + radius / 2, radius / 2)
    for _ in range(4 * max_groups):
        if len(centres) == max_groups or np.count_nonzero(remaining) < min_count:
            break
        points = features[remaining]
        counts, x_edges, y_edges = np.histogram2d(points[:, 0], points[:, 1], bins=(edges, edges))
        i, j = np.unravel_index(int(np.argmax(counts)), counts.shape)
        centre = np.array([(x_edges[i] + x_edges[i + 1]) / 2, (y_edges[j] + y_edges[j + 1]) / 2])
        for _ in range(10):
            near = np.linalg.norm(points - centre, axis=1) < radius
            if not near.any():
                break
            centre = points[near].mean(axis=0)
        member = remaining & (np.linalg.norm(features - centre, axis=1) < radius)
        remaining &= ~member
        if np.count_nonzero(member) >= min_count:
            centres.append(centre)
    return np.array(centres).reshape(-1, 2)


def _surface(lab: np.ndarray, linear: np.ndarray, percentile: float, kind: str) -> Surface:
    """A surface from its pixels: median chromaticity at the ``percentile`` lightness, mean linear RGB."""
    lit = float(np.percentile(lab[:, 0], percentile))
    direction = np.median(lab[:, 1:] / (lab[:, :1] + 16.0), axis=0)
    return Surface(np.array([lit, *(direction * (lit + 16.0))]), linear.mean(axis=0), lab.shape[0], kind)


def _rg(linear: np.ndarray) -> np.ndarray:
    return linear[:2] / max(float(linear.sum()), 1e-9)


def _mixture_target(surface: Surface, larger: list[Surface], tolerance: float) -> int | None:
    """The index (in ``larger``) of the surface that ``surface`` is mostly made of when its chromaticity lies
    on the segment between two larger surfaces (a blend of the two), else None."""
    point = _rg(surface.linear)
    for i, first in enumerate(larger):
        for j in range(i + 1, len(larger)):
            a, b = _rg(first.linear), _rg(larger[j].linear)
            segment = b - a
            length = float(segment @ segment)
            if length < 1e-8:
                continue
            t = float((point - a) @ segment) / length
            if 0.1 <= t <= 0.9 and np.linalg.norm(a + t * segment - point) <= tolerance:
                return i if t < 0.5 else j
    return None


def _merge_mixtures(surfaces: list[Surface], tolerance: float) -> list[Surface]:
    """Surfaces with every blend of two larger ones merged into the nearer of the two (largest first)."""
    ordered = sorted(surfaces, key=lambda s: -s.pixels)
    kept: list[Surface] = []
    for surface in ordered:
        target = _mixture_target(surface, kept, tolerance) if len(kept) >= 2 else None
        if target is None:
            kept.append(surface)
        else:
            host = kept[target]
            kept[target] = Surface(host.lab, host.linear, host.pixels + surface.pixels, host.kind)
    return kept


def object_surfaces(
    pixels: np.ndarray,
    light: FrameLight = NEUTRAL_LIGHT,
    edges: np.ndarray | None = None,
    parameters: NamingParameters = DEFAULT_PARAMETERS,
) -> tuple[list[Surface], int]:
    """The surfaces of an object's RGB pixels (Nx3 uint8) and how many pixels were considered (after edge
    pixels were left out); the dark pool comes last."""
    rgb = np.asarray(pixels, dtype=np.uint8).reshape(-1, 3)
    if rgb.shape[0] == 0:
        raise ValueError("no pixels to name a colour for")
    if edges is not None:
        interior = np.asarray(edges).reshape(-1) <= parameters.edge_step
        if np.count_nonzero(interior) >= parameters.min_interior_share * rgb.shape[0]:
            rgb = rgb[interior]
    count = rgb.shape[0]
    linear = srgb_to_linear(rgb) * light.gains
    lab = linear_to_lab(linear)
    highlight = (rgb.max(axis=1) >= parameters.clipped_level) & (rgb.min(axis=1) >= parameters.highlight_floor)
    dark = ~highlight & (lab[:, 0] < parameters.dark_lightness)
    regular = ~highlight & ~dark
    if np.count_nonzero(highlight) >= parameters.highlight_keep_share * count:
        # an over-exposed white surface: its clipped pixels are white, and group with its unclipped ones
        lab[highlight] = WHITE_LAB
        regular |= highlight
    min_count = max(3.0, parameters.min_group_share * count)
    surfaces: list[Surface] = []
    if np.count_nonzero(regular) >= min_count:
        colors, colors_linear = lab[regular], linear[regular]
        features = chroma_plane(colors, parameters.chroma_softness)
        centres = _modes(features, parameters.group_radius, min_count, parameters.max_groups)
        if centres.size:
            owner = np.argmin(np.linalg.norm(features[:, None, :] - centres[None], axis=2), axis=1)
            for group in range(centres.shape[0]):
                member = owner == group
                if np.count_nonzero(member) < min_count:
                    continue
                surface = _surface(colors[member], colors_linear[member], parameters.lit_percentile, "regular")
                if not is_unsaturated(surface.lab, parameters):
                    surfaces.append(surface)
                    continue
                blackish = member & (colors[:, 0] < parameters.black_lightness)
                for part in (member & ~blackish, blackish):  # black print on white: two surfaces
                    if np.count_nonzero(part) >= min_count:
                        surfaces.append(
                            _surface(colors[part], colors_linear[part], parameters.lit_percentile, "regular")
                        )
    if not surfaces and np.count_nonzero(regular):  # too few pixels for a group: they are one surface
        surfaces.append(_surface(lab[regular], linear[regular], parameters.lit_percentile, "regular"))
    surfaces = _merge_mixtures(surfaces, parameters.mixture_tolerance)
    if np.count_nonzero(dark):
        surfaces.append(_surface(lab[dark], linear[dark], 50.0, "dark"))
    if not surfaces:  # only highlights, too few of them to count as a white surface otherwise
        surfaces.append(Surface(WHITE_LAB, linear[highlight].mean(axis=0), int(np.count_nonzero(highlight)), "regular"))
    return surfaces, count


def _tint(lab: np.ndarray, parameters: NamingParameters) -> float:
    """How far a colour is from neutral relative to the achromatic ellipse (below 1: inside); the ellipse
    shrinks for dark colours, where a small chroma is already a clear hue (a dark blue panel)."""
    scale = float(lab[0]) + 16.0
    radius_a = min(parameters.achromatic_chroma, parameters.dark_tint_ratio * scale)
    radius_b = min(parameters.daylight_chroma, 1.5 * parameters.dark_tint_ratio * scale)
    return float(np.hypot(lab[1] / radius_a, lab[2] / radius_b))


def is_unsaturated(lab: np.ndarray, parameters: NamingParameters = DEFAULT_PARAMETERS) -> bool:
    """Whether a surface colour (CIELAB) is white, grey or black rather than a hue (see ``daylight_chroma``)."""
    return _tint(lab, parameters) < 1.0


def _chromatic_name(lab: np.ndarray, parameters: NamingParameters) -> SurfaceName:
    distances = delta_e_2000(
        lab[None, :], _PROTOTYPE_LAB, k_l=parameters.lightness_factor, k_c=parameters.chroma_factor
    )
    votes = np.exp(-0.5 * (distances / parameters.kernel_width) ** 2)
    density = np.array([votes[code == _PROTOTYPE_CODES].mean() for code in range(len(CHROMATIC_TERMS))])
    total = float(density.sum())
    if total <= 1e-300:  # far from every prototype: the nearest one decides
        return SurfaceName(_PROTOTYPE_TERMS[int(np.argmin(distances))], 0.0)
    best = int(np.argmax(density))
    return SurfaceName(CHROMATIC_TERMS[best], float(density[best] / total))


def name_surface(surface: Surface, surround: float, parameters: NamingParameters = DEFAULT_PARAMETERS) -> SurfaceName:
    """The name of one surface against the frame's surround luminance (see the module docstring)."""
    if surface.kind == "dark":
        srgb = 255.0 * linear_to_srgb(surface.linear)
        span = float(srgb.max() - srgb.min())
        saturation = span / max(float(srgb.max()), 1e-9)
        if saturation >= parameters.dark_saturation and span >= parameters.dark_span:
            mean = linear_to_lab(surface.linear)  # judged as the same chromaticity a little lighter
            lightness = max(float(mean[0]), parameters.dark_lightness * 2.0)
            return _chromatic_name(
                np.array([lightness, *(mean[1:] / (mean[0] + 16.0) * (lightness + 16.0))]), parameters
            )
        return SurfaceName("black", 0.5 + 0.5 * max(0.0, 1.0 - saturation / parameters.dark_saturation))
    if not is_unsaturated(surface.lab, parameters):
        return _chromatic_name(surface.lab, parameters)
    lightness = float(surface.lab[0])
    certainty = 0.5 + 0.5 * (1.0 - _tint(surface.lab, parameters))
    luminance = ((lightness + 16.0) / 116.0) ** 3
    if luminance >= parameters.white_surround_ratio * surround and lightness >= parameters.white_lightness:
        return SurfaceName("white", certainty)
    return SurfaceName("black" if lightness < parameters.black_lightness else "grey", certainty)


def name_colors(
    pixels: np.ndarray,
    light: FrameLight = NEUTRAL_LIGHT,
    edges: np.ndarray | None = None,
    parameters: NamingParameters = DEFAULT_PARAMETERS,
) -> tuple[NamedColor, ...]:
    """The colours of an object from its RGB pixels (Nx3 uint8): the dominant one, then a second one when the
    object has two; ``edges`` (N, from :func:`edge_strength`) lets pixels on colour edges be left out."""
    surfaces, count = object_surfaces(pixels, light, edges, parameters)
    names = [name_surface(surface, light.surround, parameters) for surface in surfaces]
    weights: dict[str, float] = {}
    certainties: dict[str, float] = {}
    lit_names = {n.name for s, n in zip(surfaces, names, strict=True) if s.kind != "dark"}
    for surface, named in zip(surfaces, names, strict=True):
        shadow = lit_names and named.name not in lit_names and surface.pixels < parameters.dark_keep_share * count
        if surface.kind == "dark" and shadow:
            continue  # shadows of the object's surfaces
        weights[named.name] = weights.get(named.name, 0.0) + surface.pixels
        certainties[named.name] = certainties.get(named.name, 0.0) + surface.pixels * named.certainty
    total = sum(weights.values())
    ranked = sorted(weights, key=lambda name: (-weights[name], COLOR_TERMS.index(name)))
    result: list[NamedColor] = []
    for name in ranked[:2]:
        share = weights[name] / total
        certainty = certainties[name] / weights[name]
        if result and (share < parameters.second_share or share * certainty < parameters.second_confidence):
            break
        result.append(NamedColor(name=name, share=share, confidence=share * certainty))
    return tuple(result)


def name_color(pixels: np.ndarray, light: FrameLight = NEUTRAL_LIGHT) -> tuple[str, float, dict[str, float]]:
    """The dominant colour name of N RGB pixels, its share, and the share of every reported name."""
    named = name_colors(pixels, light)
    return named[0].name, named[0].share, {c.name: c.share for c in named}


def object_pixels(image: np.ndarray, hypothesis: ObjectHypothesis, max_pixels: int) -> tuple[np.ndarray, np.ndarray]:
    """Up to ``max_pixels`` RGB pixels of the hypothesis, its outline left out when enough remain (as
    :func:`~annotators.image.pixel_expert.hypothesis_pixels` picks them), and their edge strengths."""
    x0, y0, x1, y1 = hypothesis.roi
    local = hypothesis.mask[y0:y1, x0:x1]
    inner = cv2.erode(local.view(np.uint8), np.ones((3, 3), np.uint8)).view(bool)
    if np.count_nonzero(inner) >= max(20, np.count_nonzero(local) // 3):
        local = inner
    crop = image[y0:y1, x0:x1]
    pixels = crop[local]
    edges = edge_strength(crop)[local]
    step = max(1, pixels.shape[0] // max_pixels)
    return pixels[::step], edges[::step]


class SemanticColorAnnotator(Annotator):
    """Names the dominant colour of every object hypothesis, and its second colour when it has two.

    Attaches one SemanticColor per reported colour, the dominant one first and with the higher confidence;
    ``ratio`` is the colour's share of the object, ``confidence`` its share times the name's certainty.
    """

    inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis, ColorImage)
    outputs: ClassVar[tuple[type[CasType], ...]] = (SemanticColor,)
    capability: ClassVar[Capability] = Capability(
        label="semantic colour annotator",
        colors=tuple(term.capitalize() for term in COLOR_TERMS),
        cost_ms=3.0,
        reliability=0.8,
    )

    def __init__(
        self, max_pixels: int = 2000, parameters: NamingParameters = DEFAULT_PARAMETERS, name: str | None = None
    ) -> None:
        super().__init__(name=name)
        self.max_pixels = max_pixels
        self.parameters = parameters

    def analyse(self) -> None:
        """Name the colours of each hypothesis with pixels; fail on missing or inconsistent input."""
        image, hypotheses = image_and_hypotheses(self, "name colours for")
        light = estimate_frame_light(image)
        named_any = False
        for hypothesis in hypotheses:
            if hypothesis.mask.shape != image.shape[:2]:
                self.fail(f"hypothesis mask {hypothesis.mask.shape} and colour image {image.shape[:2]} sizes differ")
            pixels, edges = object_pixels(image, hypothesis, self.max_pixels)
            if pixels.shape[0] == 0:
                continue
            for color in name_colors(pixels, light, edges, self.parameters):
                self.attach(hypothesis, SemanticColor(color=color.name, ratio=color.share, confidence=color.confidence))
            named_any = True
        if not named_any:
            self.fail("every object hypothesis has an empty mask")
