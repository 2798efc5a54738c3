"""The surfaces of an object: its pixels grouped into the few colours a person would see on it.

Pixels on strong colour edges (print outlines, the object's border) mix two surfaces and are left out when
enough remain. Pixels with a clipped channel and no dark channel are highlights or an over-exposed white: they
are white when they are most of the object, else left out. Near-black pixels form a dark pool (shadows or a black
surface), judged apart by the namer. The other pixels are grouped in the log-chroma plane (:func:`chroma_plane`),
where the lit and the shaded side of a surface stay together. A surface's colour is its median chromaticity
``(a*, b*) / (L* + 16)`` (unchanged by a uniform change of light where L* > 8) at its lit lightness (a high
percentile of its L*): people name the lit side. An unsaturated group (:func:`is_unsaturated`) is split into
black and the rest; a group whose colour is a blend of two larger ones (pixels mixing a red and a white print)
joins the nearer of the two; a lighter, paler group that is a blend of a saturated one with white (a specular
highlight on it, or a white part its colour bleeds into on a small or blurred object) is the saturated surface's
highlight when it is mostly that colour, else the white it is mixed with (:func:`_merge_white_blends`); and a
darker group of nearly the same hue as a larger one, as saturated or paler, is its shaded side.

The per-pixel steps (:mod:`annotators.image.color_pixels`), the grouping and the groups' order statistics
(:mod:`annotators.image.color_groups`) run compiled, for all the objects of a frame at once; the pixels are held in
single precision (:func:`chroma_plane` and :func:`tints` are the NumPy form of the per-pixel steps).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import cv2
import numpy as np

from annotators.image.color_space import RELATIVE_XYZ32, UINT8_TO_LINEAR32, linear_to_lab
from annotators.image.white_balance import LUMINANCE, NEUTRAL_LIGHT, FrameLight
from robokudo.core.types import ObjectHypothesis

WHITE_LAB = np.array([100.0, 0.0, 0.0])


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
    highlight_tint: float = 1.5
    """... and whose tint (:func:`is_unsaturated`'s ellipse measure) is at most this: clipping distorts the hue of
    a white, but a clipped bright yellow stays clearly yellow."""
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
    min_white_blend: float = 0.1
    """A paler, lighter surface on the line from a saturated one to white is a blend of the two (a highlight, or
    a white bleeding into the colour) when at least this share of it is white."""
    shade_hue: float = 30.0
    """A saturated surface within this many degrees of hue of a larger one ..."""
    shade_lightness: float = 8.0
    """... at least this much darker (L*) ..."""
    shade_saturation: float = 1.6
    """... and whose saturation C*/(L* + 16) is at most this factor of the larger one's (any paler: the ambient
    light of a shaded side is paler than the direct light) is its shaded side."""
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
    """An unsaturated surface darker than this lit L* ..."""
    black_surround_ratio: float = 0.5
    """... and than this fraction of the surround's luminance is black (else grey)."""
    shade_delta_e: float = 15.0
    """Lit saturated surfaces less than this CIEDE2000 apart (linked in a chain) are shades of one colour and
    are named together."""
    kernel_width: float = 8.0
    """Width (CIEDE2000 units) of each prototype's vote."""
    brown_max_chroma: float = 48.0
    """A surface at least this colourful (C*) is not brown: brown surfaces (wood, cardboard, tins) are of moderate
    chroma, while the survey's browns are display colours that a dim yellow or orange print matches by lightness
    alone (tuned on the "tune" split: its browns reach C* 33, its yellows named brown 57)."""
    brown_below_white: float = 0.56
    """A lit surface whose luminance is at least this fraction of the lightest white surface of its object is not
    brown: brown is a yellow or orange clearly darker than white (lit by the same light as the object's white, the
    ratio does not depend on how dim the frame is). Not tuned: in the ISCC-NBS colour names the yellowish browns
    give way to the pale and light orange yellows at Munsell value 7.5 (Y = 0.51; between the centroids of "light
    yellowish brown", L* 67, and "pale orange yellow", L* 83), and a white surface is about value 9.5 (Y = 0.90):
    0.51 / 0.90 = 0.56."""
    white_luminance: float = 0.90
    """The luminance (Y) of a white surface: Munsell value 9.5, white paper. Yellow and orange are told apart at
    the lightness a surface has when its object's white is lifted to this (not tuned)."""
    second_share: float = 0.3
    """A second colour is reported when its share of the named pixels is at least this ..."""
    second_confidence: float = 0.1
    """... and its confidence at least this."""


DEFAULT_PARAMETERS = NamingParameters()


@dataclass(frozen=True)
class Surface:
    """One surface of an object: its colour (CIELAB at its lit lightness), its mean linear RGB, its pixel
    count and its kind: ``"regular"`` or ``"dark"`` (the near-black pool)."""

    lab: np.ndarray
    linear: np.ndarray
    pixels: int
    kind: str


def edge_strength(image: np.ndarray, where: np.ndarray | None = None) -> np.ndarray:
    """Per-pixel colour step (sRGB levels per pixel, the largest over the channels) of an RGB image, at the
    pixels ``where`` (HxW bool) is set (all pixels, as HxW, when it is None)."""
    gx = cv2.Sobel(image, cv2.CV_16S, 1, 0, ksize=3)
    gy = cv2.Sobel(image, cv2.CV_16S, 0, 1, ksize=3)
    if where is not None:
        gx, gy = gx[where], gy[where]
    squared = gx.astype(np.float32) ** 2 + gy.astype(np.float32) ** 2
    return np.sqrt(np.maximum(np.maximum(squared[..., 0], squared[..., 1]), squared[..., 2])) / 8.0


def chroma_plane(lab: np.ndarray, softness: float) -> np.ndarray:
    """Pixels (CIELAB, Nx3) in the log-chroma plane: hue as direction, ``log(1 + C*/softness)`` as radius.

    Distances there compare saturated colours by hue and chroma ratio (shading scales chroma), while the hue
    of a nearly neutral pixel, which is noise, hardly counts."""
    chroma = np.hypot(lab[:, 1], lab[:, 2])
    scale = np.log1p(chroma / softness) / np.maximum(chroma, 1e-9)
    return lab[:, 1:] * scale[:, None]


def _rg(linear: np.ndarray) -> np.ndarray:
    return linear[:2] / max(float(linear.sum()), 1e-9)


def _mixture_target(surface: Surface, larger: list[Surface], tolerance: float) -> int | None:
    """The index (in ``larger``) of the surface that ``surface`` is mostly made of when its chromaticity lies
    on the segment between two larger surfaces (a blend of the two), else None.

    A blend's place on the segment weighs each part by its intensity (R + G + B in linear light): a pixel half
    covered by a dark purple print and half by white paper lies near the white end. The share of the blend
    that is each part's area undoes that weighting."""
    point = _rg(surface.linear)
    chromaticities = [_rg(larger_surface.linear) for larger_surface in larger]
    for i, first in enumerate(larger):
        for j in range(i + 1, len(larger)):
            a, b = chromaticities[i], chromaticities[j]
            segment = b - a
            length = float(segment @ segment)
            if length < 1e-8:
                continue
            t = float((point - a) @ segment) / length
            if 0.1 <= t <= 0.9 and np.linalg.norm(a + t * segment - point) <= tolerance:
                first_intensity, second_intensity = float(first.linear.sum()), float(larger[j].linear.sum())
                second_area = t * first_intensity / (t * first_intensity + (1.0 - t) * second_intensity)
                return i if second_area < 0.5 else j
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


NEUTRAL_RG = np.array([1.0 / 3.0, 1.0 / 3.0])
"""The rg chromaticity of a neutral (white-balanced) colour."""


def _white_blend(host: Surface, surface: Surface, parameters: NamingParameters) -> tuple[float, np.ndarray] | None:
    """How much of ``surface`` is white (0..1) and that white's CIELAB, when ``surface`` is an additive blend of
    ``host`` and an unsaturated colour, else None.

    Blends in linear light lie on straight lines in rg chromaticity (the dichromatic reflection model puts a
    highlight on the line from the body colour to the light's). The line from the host through the surface is
    followed to where it passes nearest to neutral; that point is the white when it is unsaturated
    (:func:`is_unsaturated`, at the surface's lightness) and the surface lies between it and the host."""
    start, through = _rg(host.linear), _rg(surface.linear)
    direction = through - start
    length = float(direction @ direction)
    if length < 1e-8:
        return None
    reach = float((NEUTRAL_RG - start) @ direction) / length  # the nearest point to neutral, in units of direction
    if reach <= 1.0:
        return None
    end = start + reach * direction
    white = np.array([end[0], end[1], 1.0 - end[0] - end[1]])
    if white.min() <= 0.0:
        return None
    white_lab = linear_to_lab(white * float(surface.linear @ LUMINANCE) / float(white @ LUMINANCE))
    white_lab[0] = surface.lab[0]
    if not is_unsaturated(white_lab, parameters):
        return None
    return 1.0 / reach, white_lab


def _merge_white_blends(surfaces: list[Surface], parameters: NamingParameters) -> list[Surface]:
    """Surfaces with every saturated surface that is a lighter, paler blend of a more saturated one with white
    (:func:`_white_blend`) resolved: mostly white (at least half) it becomes that white (a white part the
    colour bleeds into), else it joins the saturated surface (its highlight). Blends with less than
    ``min_white_blend`` white are left alone (shading and noise move a colour that little)."""
    result = list(surfaces)
    merged: set[int] = set()
    whitened: set[int] = set()
    lit_saturated = [s.kind != "dark" and not is_unsaturated(s.lab, parameters) for s in surfaces]
    saturation = [_saturation(s.lab) for s in surfaces]
    lightness = [float(s.lab[0]) for s in surfaces]
    for index, surface in enumerate(surfaces):
        if not lit_saturated[index]:
            continue
        for host_index, host in enumerate(surfaces):
            if (
                host_index == index
                or host_index in merged
                or host_index in whitened
                or not lit_saturated[host_index]
                or saturation[host_index] <= saturation[index]
                or lightness[host_index] >= lightness[index]
            ):
                continue
            blend = _white_blend(host, surface, parameters)
            if blend is None or blend[0] < parameters.min_white_blend:
                continue
            share, white_lab = blend
            if share >= 0.5:
                result[index] = Surface(white_lab, surface.linear, surface.pixels, surface.kind)
                whitened.add(index)
            else:
                target = result[host_index]
                result[host_index] = Surface(target.lab, target.linear, target.pixels + surface.pixels, target.kind)
                merged.add(index)
            break
    return [surface for index, surface in enumerate(result) if index not in merged]


def _hue(lab: np.ndarray) -> float:
    return math.degrees(math.atan2(float(lab[2]), float(lab[1]))) % 360.0


def _saturation(lab: np.ndarray) -> float:
    return math.hypot(float(lab[1]), float(lab[2])) / (float(lab[0]) + 16.0)


def _merge_shaded(surfaces: list[Surface], parameters: NamingParameters) -> list[Surface]:
    """Surfaces with every saturated surface that is a shaded side of a larger one (a hue within ``shade_hue``
    degrees, at most ``shade_saturation`` times as saturated, at least ``shade_lightness`` darker) merged into it:
    a yellow brick's shaded side turns orange in a camera image, but the brick is yellow; and a side turned away
    from the light is lit by the room's paler ambient light, so it is paler as well as darker (a yellow box's
    shaded side looks brown), but it is the same yellow."""
    ordered = sorted(surfaces, key=lambda s: -s.pixels)
    kept: list[Surface] = []
    kept_looks: list[tuple[bool, float, float, float]] = []  # each kept surface's colour, which merging keeps
    for surface in ordered:
        host_index = None
        unsaturated, hue, saturation, lightness = _look(surface.lab, parameters)
        if not unsaturated:
            for index, host_look in enumerate(kept_looks):
                if is_shade_of((unsaturated, hue, saturation, lightness), host_look, parameters):
                    host_index = index
                    break
        if host_index is None:
            kept.append(surface)
            kept_looks.append((unsaturated, hue, saturation, lightness))
        else:
            host = kept[host_index]
            kept[host_index] = Surface(host.lab, host.linear, host.pixels + surface.pixels, host.kind)
    return kept


Look = tuple[bool, float, float, float]
"""What :func:`is_shade_of` compares of a colour: whether it is unsaturated, its hue, saturation and L*."""


def _look(lab: np.ndarray, parameters: NamingParameters) -> Look:
    return is_unsaturated(lab, parameters), _hue(lab), _saturation(lab), float(lab[0])


def look(lab: np.ndarray, parameters: NamingParameters = DEFAULT_PARAMETERS) -> Look:
    """What :func:`is_shade_of` compares of a colour (CIELAB)."""
    return _look(lab, parameters)


def is_shade_of(shaded: Look, lit: Look, parameters: NamingParameters = DEFAULT_PARAMETERS) -> bool:
    """Whether a saturated colour can be a saturated ``lit`` colour's shaded side: a hue within ``shade_hue``
    degrees, at most ``shade_saturation`` times as saturated and at least ``shade_lightness`` darker (see
    :func:`_merge_shaded`)."""
    unsaturated, hue, saturation, lightness = shaded
    lit_unsaturated, lit_hue, lit_saturation, lit_lightness = lit
    if unsaturated or lit_unsaturated:
        return False
    offset = abs((hue - lit_hue + 180.0) % 360.0 - 180.0)
    ratio = saturation / max(lit_saturation, 1e-9)
    return (
        offset <= parameters.shade_hue
        and ratio <= parameters.shade_saturation
        and lit_lightness - lightness >= parameters.shade_lightness
    )


DARK_GROUP = 1
"""The kind of a dark pool's row in :func:`~annotators.image.color_groups.all_groups`' result."""


def pixel_settings(parameters: NamingParameters) -> np.ndarray:
    """The constants :func:`~annotators.image.color_pixels.pixel_features` takes the pixels' steps with, in its
    order."""
    return np.array(
        [
            parameters.edge_step,
            parameters.min_interior_share,
            parameters.clipped_level,
            parameters.highlight_floor,
            parameters.highlight_tint,
            parameters.highlight_keep_share,
            parameters.dark_lightness,
            parameters.chroma_softness,
            parameters.group_radius,
            parameters.achromatic_chroma,
            parameters.daylight_chroma,
            parameters.dark_tint_ratio,
        ]
    )


def group_settings(parameters: NamingParameters) -> np.ndarray:
    """The constants :func:`~annotators.image.color_groups.all_groups` groups pixels with, in its order."""
    return np.array(
        [
            parameters.group_radius,
            parameters.min_group_share,
            parameters.lit_percentile,
            parameters.black_lightness,
            parameters.achromatic_chroma,
            parameters.daylight_chroma,
            parameters.dark_tint_ratio,
        ]
    )


def object_surfaces(
    pixels: np.ndarray,
    light: FrameLight = NEUTRAL_LIGHT,
    edges: np.ndarray | None = None,
    parameters: NamingParameters = DEFAULT_PARAMETERS,
) -> tuple[list[Surface], int]:
    """The surfaces of an object's RGB pixels (Nx3 uint8) and how many pixels were considered (after edge
    pixels were left out); the dark pool comes last. ``edges`` (N, from :func:`edge_strength`) lets pixels on
    colour edges be left out."""
    return objects_surfaces([(pixels, edges)], light, parameters)[0]


def objects_surfaces(
    objects: Sequence[tuple[np.ndarray, np.ndarray | None]],
    light: FrameLight = NEUTRAL_LIGHT,
    parameters: NamingParameters = DEFAULT_PARAMETERS,
) -> list[tuple[list[Surface], int]]:
    """:func:`object_surfaces` of several objects of one frame (each its RGB pixels and their edge strengths or
    None): the per-pixel steps and the grouping (:func:`~annotators.image.color_groups.all_groups`) run once
    over all the objects' pixels, the merging of the groups per object."""
    rgb_parts = [np.asarray(pixels, dtype=np.uint8).reshape(-1, 3) for pixels, _ in objects]
    sizes = np.array([part.shape[0] for part in rgb_parts], dtype=np.int64)
    if not rgb_parts:
        return []
    if sizes.min() == 0:
        raise ValueError("no pixels to name a colour for")
    from annotators.image.color_groups import all_groups  # numba is loaded with the first objects named
    from annotators.image.color_pixels import pixel_features

    edge_parts = [
        np.zeros(size, dtype=np.float32) if edges is None else np.asarray(edges, dtype=np.float32).reshape(-1)
        for (_, edges), size in zip(objects, sizes, strict=True)
    ]
    rows, px, py, cells, regular, dark, highlight, counts = pixel_features(
        np.concatenate(rgb_parts),
        np.concatenate(edge_parts),
        sizes,
        UINT8_TO_LINEAR32,
        np.asarray(light.gains, dtype=np.float32),
        RELATIVE_XYZ32,
        pixel_settings(parameters),
    )
    ends = np.cumsum(counts)
    groups = all_groups(rows, px, py, cells, regular, dark, ends, group_settings(parameters), parameters.max_groups)
    firsts = np.searchsorted(groups[:, 0], np.arange(len(objects) + 1)).tolist()
    labs, linears = groups[:, 2:5].copy(), groups[:, 5:8].copy()  # each surface's colours: rows of these
    kinds = ["dark" if kind == DARK_GROUP else "regular" for kind in groups[:, 1].tolist()]
    sizes_of_groups = groups[:, 8].astype(np.int64).tolist()
    result = []
    for index, count in enumerate(counts.tolist()):
        found = [
            Surface(labs[row], linears[row], sizes_of_groups[row], kinds[row])
            for row in range(firsts[index], firsts[index + 1])
        ]
        surfaces = [s for s in found if s.kind == "regular"]
        if len(surfaces) > 1:  # a single surface merges with nothing
            surfaces = _merge_mixtures(surfaces, parameters.mixture_tolerance)
            surfaces = _merge_shaded(_merge_white_blends(surfaces, parameters), parameters)
        surfaces += [s for s in found if s.kind == "dark"]
        if not surfaces:  # only highlights, too few of them to count as a white surface otherwise
            part = slice(int(ends[index]) - count, int(ends[index]))
            highlights = highlight[part]
            white_linear = rows[3:, part].compress(highlights, axis=1).mean(axis=1, dtype=np.float64)
            surfaces.append(Surface(WHITE_LAB, white_linear, int(np.count_nonzero(highlights)), "regular"))
        result.append((surfaces, count))
    return result


def tints(lab: np.ndarray, parameters: NamingParameters) -> np.ndarray:
    """How far colours (CIELAB, ...x3) are from neutral relative to the achromatic ellipse (below 1: inside);
    the ellipse shrinks for dark colours, where a small chroma is already a clear hue (a dark blue panel)."""
    scale = np.asarray(lab)[..., 0] + 16.0
    radius_a = np.minimum(parameters.achromatic_chroma, parameters.dark_tint_ratio * scale)
    radius_b = np.minimum(parameters.daylight_chroma, 1.5 * parameters.dark_tint_ratio * scale)
    return np.hypot(np.asarray(lab)[..., 1] / radius_a, np.asarray(lab)[..., 2] / radius_b)


def tint(lab: np.ndarray, parameters: NamingParameters = DEFAULT_PARAMETERS) -> float:
    """How far one colour (CIELAB) is from neutral relative to the achromatic ellipse (see :func:`tints`)."""
    lightness, a, b = lab.tolist() if isinstance(lab, np.ndarray) and lab.shape == (3,) else np.reshape(lab, 3).tolist()
    radius_a = min(parameters.achromatic_chroma, parameters.dark_tint_ratio * (lightness + 16.0))
    radius_b = min(parameters.daylight_chroma, 1.5 * parameters.dark_tint_ratio * (lightness + 16.0))
    return math.hypot(a / radius_a, b / radius_b)


def is_unsaturated(lab: np.ndarray, parameters: NamingParameters = DEFAULT_PARAMETERS) -> bool:
    """Whether a surface colour (CIELAB) is white, grey or black rather than a hue (see ``daylight_chroma``)."""
    return tint(lab, parameters) < 1.0


def object_pixels(image: np.ndarray, hypothesis: ObjectHypothesis, max_pixels: int) -> tuple[np.ndarray, np.ndarray]:
    """Up to ``max_pixels`` RGB pixels of the hypothesis, its outline left out when enough remain, and their
    edge strengths (see :func:`objects_pixels`)."""
    return objects_pixels(image, [hypothesis], max_pixels)[0]


def objects_pixels(
    image: np.ndarray, hypotheses: Sequence[ObjectHypothesis], max_pixels: int
) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each hypothesis' pixels (RGB, Nx3 uint8) and their edge strengths, for the hypotheses of one image.

    A hypothesis' pixels are its mask's, its outline left out when enough remain, taken with the stride (in
    raster order) that leaves ``max_pixels`` to twice that, as
    :func:`~annotators.image.pixel_expert.hypothesis_pixels` picks them
    (:func:`~annotators.image.pixel_picking.mask_pixels`). The edge strength of a pixel is :func:`edge_strength`
    of the hypothesis' box cut out of the image, computed at the picked pixels only
    (:func:`~annotators.image.pixel_picking.box_pixels_and_edges`)."""
    from annotators.image.pixel_picking import box_pixels_and_edges, mask_pixels  # numba loads on first use

    rows_parts, cols_parts, boxes, sizes = [], [], [], []
    for hypothesis in hypotheses:
        x0, y0, x1, y1 = (int(v) for v in hypothesis.roi)
        rows, cols = mask_pixels(hypothesis.mask, y0, y1, x0, x1, max_pixels, 20)
        rows_parts.append(rows)
        cols_parts.append(cols)
        boxes.append((y0, y1, x0, x1))
        sizes.append(rows.size)
    if not sizes:
        return []
    pixels, edges = box_pixels_and_edges(
        np.ascontiguousarray(image, dtype=np.uint8),
        np.concatenate(rows_parts),
        np.concatenate(cols_parts),
        np.array(boxes, dtype=np.int64).reshape(-1, 4),
        np.repeat(np.arange(len(sizes)), sizes),
    )
    ends = np.cumsum(sizes)
    return [(pixels[end - size : end], edges[end - size : end]) for end, size in zip(ends.tolist(), sizes, strict=True)]
