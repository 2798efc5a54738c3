"""Colour names a person would agree with: an object's dominant colour, and a second one when it has two.

An object's pixels are white-balanced for the frame (:mod:`annotators.image.white_balance`: grey-edge) and
grouped into surfaces, highlights, shadows and edge pixels discounted (:mod:`annotators.image.color_surfaces`).
Each surface is named (:func:`name_surface`):

* an unsaturated surface (inside the achromatic ellipse, which is wider along the daylight locus where white
  balance errs) is white when its lit luminance is about the frame's surround luminance or above (and it is not
  dark in absolute terms), black when it is dark both absolutely and against the surround, else grey;
* a saturated surface is named in CIELAB by CIEDE2000 distances to the colour-name prototypes of
  :mod:`annotators.image.color_prototypes` (the xkcd colour survey), as a kernel density classifier: each term's
  prototypes vote with a Gaussian of their distance (``kernel_width``) averaged per term, and the winning term's share
  of the votes is the name's certainty; brown gets no vote from a colour of chroma C* at least ``brown_max_chroma``
  (brown surfaces are of moderate chroma; a dim yellow or orange print is not brown) or of a hue outside the survey's
  browns' (:data:`BROWN_HUES`), and a colour of a hue outside the survey's pinks' (:data:`PINK_HUES`) is not named
  pink; against the object's own white, lit by the same light (:func:`_related_to_white`): brown gets no vote from a
  surface nearly as light as that white (``brown_below_white``: brown is a yellow or orange clearly darker than white,
  not a cream in a dim frame), and yellow and orange are told apart at the lightness the surface has when the white is
  lifted to a white's luminance (``white_luminance``);
* the near-black pool is a dark colour (a navy mug) when its mean colour is clearly saturated, else black; it
  counts only when it is a sizeable part of the object or has the name of one of its lit surfaces (shadows are
  dropped).

Lit saturated surfaces that are shades of one colour (CIEDE2000 neighbours, or one paint lit and in shade: a darker
surface of about the same hue, whichever is larger) are named together by their pooled votes
(:func:`_pool_shades`). A name's share is the share of the named pixels its surfaces hold; grey beside white is the
white's shaded side and is left out (it names no colour of its own, and counted with the white it would hide a print
as large as the white it is printed on). Likewise a lit surface named black that is darker than a lit grey of
about its hue is that grey in shade (:func:`_greys_in_shade`: a cloth's folds) and counts as grey. The dominant
colour is the largest share; a second colour is reported when its share and its confidence (share x certainty) are
large enough.

The annotator names all the hypotheses of a frame together (:func:`name_objects_colors`): their pixels are
picked and grouped in one pass over the frame, and every surface's prototype votes and every pair of shades come
from one CIEDE2000 computation each (compiled, :mod:`annotators.image.delta_e_loops`, equal to the NumPy form of
:func:`~annotators.image.color_space.delta_e_2000` to the last bit), with the same results as naming each object
alone (:func:`name_colors`).

:data:`COLOR_TERMS` is the one list of names this namer reports: the lower-case labels of the ontology's colour
classes (``rk:Color`` in ontology/perception.ttl); the annotator's capability is derived from it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from annotators.image.color_prototypes import prototypes
from annotators.image.color_space import linear_to_lab
from annotators.image.color_surfaces import (
    DEFAULT_PARAMETERS,
    NamingParameters,
    Surface,
    is_shade_of,
    is_unsaturated,
    look,
    objects_pixels,
    objects_surfaces,
    tint,
)
from annotators.image.pixel_expert import image_and_hypotheses
from annotators.image.white_balance import NEUTRAL_LIGHT, FrameLight, estimate_frame_light
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

_ALL_TERMS, _ALL_LAB, _ALL_NAMES = prototypes(COLOR_TERMS)
_CHROMATIC = np.array([term in CHROMATIC_TERMS for term in _ALL_TERMS])
_PROTOTYPE_TERMS = tuple(t for t, chromatic in zip(_ALL_TERMS, _CHROMATIC, strict=True) if chromatic)
_PROTOTYPE_LAB = _ALL_LAB[_CHROMATIC]
_PROTOTYPE_LAB32 = _PROTOTYPE_LAB.astype(np.float32)
"""The prototypes in single precision: the votes' CIEDE2000 distances are computed in it (twice as fast; their
differences from double precision, about 1e-4 relative, are far below the kernel's width)."""
_PROTOTYPE_CODES = np.array([CHROMATIC_TERMS.index(t) for t in _PROTOTYPE_TERMS])
_TERM_AVERAGE = np.eye(len(CHROMATIC_TERMS))[_PROTOTYPE_CODES] / np.bincount(_PROTOTYPE_CODES)
"""Prototypes x terms: averages the prototypes' votes per term."""


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


def _term_votes(labs: np.ndarray, parameters: NamingParameters) -> np.ndarray:
    """The chromatic terms' shares of the prototype votes for CIELAB colours (Sx3 in, S x terms out; each row
    sums to 1, all on the nearest prototype's term when the colour is far from every prototype). The distances
    are computed in single precision, the votes from them in double."""
    from annotators.image.delta_e_loops import delta_e_2000_outer  # numba is loaded with the first objects

    labs = np.asarray(labs, dtype=np.float32).reshape(-1, 3)
    distances = delta_e_2000_outer(labs, _PROTOTYPE_LAB32).astype(np.float64)  # delta_e_2000's, compiled
    density = np.exp(-0.5 * (distances / parameters.kernel_width) ** 2) @ _TERM_AVERAGE
    total = density.sum(axis=1)
    far = total <= 1e-300
    votes = density / np.where(far, 1.0, total)[:, None]
    if np.any(far):
        votes[far] = np.eye(len(CHROMATIC_TERMS))[_PROTOTYPE_CODES[np.argmin(distances[far], axis=1)]]
    return _without_colourful_brown(votes, labs, parameters)


_BROWN = CHROMATIC_TERMS.index("brown")
_PINK = CHROMATIC_TERMS.index("pink")


def _hue_degrees(labs: np.ndarray) -> np.ndarray:
    """The CIELAB hue angles h_ab (0..360 degrees) of colours (...x3)."""
    return np.degrees(np.arctan2(labs[..., 2], labs[..., 1])) % 360.0


def _prototype_hue_arc(term: str) -> tuple[float, float]:
    """The shortest arc of CIELAB hues (start, end in degrees, counter-clockwise; start > end when it crosses
    0) that holds the hue of every survey prototype of ``term``: the circle less the widest gap between them."""
    hues = np.sort(_hue_degrees(_PROTOTYPE_LAB[np.array(_PROTOTYPE_TERMS) == term]))
    gaps = np.diff(np.append(hues, hues[0] + 360.0))
    widest = int(np.argmax(gaps))
    return float(hues[(widest + 1) % len(hues)]), float(hues[widest])


def _outside_arc(hue: np.ndarray, arc: tuple[float, float]) -> np.ndarray:
    """Which hues (degrees) lie outside an arc from :func:`_prototype_hue_arc`."""
    start, end = arc
    if start <= end:
        return (hue < start) | (hue > end)
    return (hue > end) & (hue < start)  # the arc crosses 0


BROWN_HUES: tuple[float, float] = _prototype_hue_arc("brown")
"""The range of CIELAB hues (degrees) the survey's brown prototypes span, from the reddest ("reddish brown") to the
greenest ("greenish brown"): no colour people called brown lies outside it."""

PINK_HUES: tuple[float, float] = _prototype_hue_arc("pink")
"""The arc of CIELAB hues (degrees, crossing 0) the survey's pink prototypes span, from the bluest pinks (about
327) to the most orange ones (about 34, "orange pink"): no colour people called pink is yellower than that."""


def _without_colourful_brown(votes: np.ndarray, labs: np.ndarray, parameters: NamingParameters) -> np.ndarray:
    """The votes with brown's taken away (the others' shares renormalised) for colours whose chroma C* is at
    least ``brown_max_chroma`` (too colourful for a brown surface, they are a yellow or orange seen in less light)
    or whose hue lies outside :data:`BROWN_HUES` (an olive print greener than any brown people named is a dark
    green, whatever the many yellowish browns near it say); a colour whose every vote is brown keeps them. Then
    :func:`_not_pink_outside_its_hues`."""
    hue = _hue_degrees(labs)
    outside = _outside_arc(hue, BROWN_HUES)
    votes = _without_brown(votes, (np.hypot(labs[:, 1], labs[:, 2]) >= parameters.brown_max_chroma) | outside)
    return _not_pink_outside_its_hues(votes, hue)


def _not_pink_outside_its_hues(votes: np.ndarray, hue: np.ndarray) -> np.ndarray:
    """The votes with pink's taken away (the others' renormalised) for the colours they would name pink whose
    hue (degrees) lies outside :data:`PINK_HUES`: a pale reddish brown tin in a bright frame, more orange than any
    pink people named, takes its next name (brown). The survey's pinks reach down to low chroma, where CIEDE2000
    counts hue differences little, so their votes reach far in hue; only the name is corrected, not every vote (a
    small pink share of a colour named otherwise is left as it is)."""
    named_pink = votes.argmax(axis=1) == _PINK
    if not np.any(named_pink):
        return votes
    return _without_term(votes, named_pink & _outside_arc(hue, PINK_HUES), _PINK)


def _without_brown(votes: np.ndarray, chosen: np.ndarray) -> np.ndarray:
    """The votes (S x terms) with brown's share taken away and the others' renormalised in the ``chosen`` rows;
    a row whose every vote is brown keeps them."""
    return _without_term(votes, chosen, _BROWN)


def _without_term(votes: np.ndarray, chosen: np.ndarray, term: int) -> np.ndarray:
    """The votes (S x terms) with term ``term``'s share taken away and the others' renormalised in the
    ``chosen`` rows; a row whose every vote is that term keeps them."""
    rest = 1.0 - votes[:, term]
    change = chosen & (rest > 1e-12)
    if np.any(change):
        votes = votes.copy()
        votes[change, term] = 0.0
        votes[change] /= rest[change, None]
    return votes


LIGHTNESS_RELATIVE_TERMS: tuple[str, ...] = ("yellow", "orange")
"""The hue names a dim light moves between: a yellow seen darker looks orange, then brown (yellow is the hue whose
dim version changes name; Buck 2015, "Brown", Current Biology 25(13)). A surface first named one of these is named
again at its lightness relative to its object's white (:func:`_related_to_white`) and takes that name when it is
one of these too. Brown is not among them: lifted by a dim white, a brown lid or tin would come out orange."""

_LIGHTNESS_RELATIVE = np.array([term in LIGHTNESS_RELATIVE_TERMS for term in CHROMATIC_TERMS])


def _white_lightness(
    surfaces: list[Surface], vote_labs: list[np.ndarray | None], surround: float, parameters: NamingParameters
) -> float | None:
    """The lit lightness (L*) of an object's lightest white surface (a lit surface named white by its lightness),
    or None when it has none."""
    whites = [
        float(surface.lab[0])
        for surface, lab in zip(surfaces, vote_labs, strict=True)
        if lab is None and surface.kind != "dark" and _lightness_name(surface, surround, parameters).name == "white"
    ]
    return max(whites) if whites else None


def _anchored_lab(lab: np.ndarray, white_lightness: float, parameters: NamingParameters) -> np.ndarray:
    """A colour (CIELAB) at the lightness it has when its object's white (lit L* ``white_lightness``) is lifted to
    the luminance of a white surface (``white_luminance``), its chromaticity (a*, b*) / (L* + 16) kept; a white
    already as light leaves it as it is."""
    white = ((white_lightness + 16.0) / 116.0) ** 3
    gain = max(1.0, parameters.white_luminance / white)
    luminance = min(1.0, ((float(lab[0]) + 16.0) / 116.0) ** 3 * gain)
    lightness = 116.0 * luminance ** (1.0 / 3.0) - 16.0
    return np.array([lightness, *(np.asarray(lab[1:], dtype=np.float64) * (lightness + 16.0) / (float(lab[0]) + 16.0))])


def _related_to_white(
    vote_rows: np.ndarray, labs: list[np.ndarray], whites: list[float | None], parameters: NamingParameters
) -> np.ndarray:
    """The surfaces' votes (one row per colour of ``labs``, each with its object's white lightness or None) judged
    against that white: brown's votes taken away (:func:`_without_brown`) for a surface whose luminance is at
    least ``brown_below_white`` of the white's (a cream box in a dim frame is as light against its white print as
    a cream is); then those named by a :data:`LIGHTNESS_RELATIVE_TERMS` term replaced by the votes of their colour
    anchored to the white (:func:`_anchored_lab`) when those name one of these terms too (a yellow chair in a dark
    room is yellow, not orange)."""
    near_white = np.array(
        [
            white is not None
            and ((float(lab[0]) + 16.0) / 116.0) ** 3 >= parameters.brown_below_white * ((white + 16.0) / 116.0) ** 3
            for lab, white in zip(labs, whites, strict=True)
        ],
        dtype=bool,
    )
    first = vote_rows.argmax(axis=1)
    relative = _LIGHTNESS_RELATIVE[first] | (near_white & (first == _BROWN))  # a cream first named brown too
    vote_rows = _without_brown(vote_rows, near_white)
    chosen = [
        i
        for i, white in enumerate(whites)
        if relative[i] and white is not None and parameters.white_luminance > ((white + 16.0) / 116.0) ** 3
    ]
    if not chosen:
        return vote_rows
    anchored = _term_votes(np.array([_anchored_lab(labs[i], whites[i], parameters) for i in chosen]), parameters)
    anchored = _without_brown(anchored, near_white[chosen])
    keep = _LIGHTNESS_RELATIVE[anchored.argmax(axis=1)]
    if not np.any(keep):
        return vote_rows
    vote_rows = vote_rows.copy()
    vote_rows[np.array(chosen)[keep]] = anchored[keep]
    return vote_rows


def _name_of_votes(votes: np.ndarray) -> SurfaceName:
    best = int(np.argmax(votes))
    return SurfaceName(CHROMATIC_TERMS[best], float(votes[best]))


def _srgb_spread(linear: np.ndarray) -> tuple[float, float]:
    """The spread of a linear RGB colour's sRGB levels (0..255): max - min, and that over max."""
    levels = [
        255.0 * (v * 12.92 if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055)
        for v in (min(max(float(c), 0.0), 1.0) for c in linear)
    ]
    span = max(levels) - min(levels)
    return span, span / max(max(levels), 1e-9)


def _vote_lab(surface: Surface, parameters: NamingParameters) -> np.ndarray | None:
    """The CIELAB colour the prototypes name a surface by, or None when it is named by lightness (white, grey or
    black): a saturated surface's own colour, or a saturated dark pool's mean chromaticity a little lighter."""
    if surface.kind == "dark":
        span, saturation = _srgb_spread(surface.linear)
        if saturation >= parameters.dark_saturation and span >= parameters.dark_span:
            mean = linear_to_lab(surface.linear)
            lightness = max(float(mean[0]), parameters.dark_lightness * 2.0)
            return np.array([lightness, *(mean[1:] / (mean[0] + 16.0) * (lightness + 16.0))])
        return None
    return None if is_unsaturated(surface.lab, parameters) else surface.lab


def _lightness_name(surface: Surface, surround: float, parameters: NamingParameters) -> SurfaceName:
    """The name of a surface without a hue: a dark pool is black; an unsaturated surface is white, grey or black
    by its lit lightness against the surround (see the module docstring)."""
    if surface.kind == "dark":
        saturation = _srgb_spread(surface.linear)[1]
        return SurfaceName("black", 0.5 + 0.5 * max(0.0, 1.0 - saturation / parameters.dark_saturation))
    lightness = float(surface.lab[0])
    certainty = 0.5 + 0.5 * (1.0 - tint(surface.lab, parameters))
    luminance = ((lightness + 16.0) / 116.0) ** 3
    if luminance >= parameters.white_surround_ratio * surround and lightness >= parameters.white_lightness:
        return SurfaceName("white", certainty)
    black = lightness < parameters.black_lightness and luminance < parameters.black_surround_ratio * surround
    return SurfaceName("black" if black else "grey", certainty)


def _shade_groups(linked_to: np.ndarray) -> list[list[int]]:
    """The single-linkage groups of colours given which pairs are linked (``linked_to[i, j]`` for j < i), as
    lists of indices."""
    groups: list[list[int]] = []
    for index in range(linked_to.shape[0]):
        linked = [g for g in groups if any(linked_to[index, j] for j in g)]
        merged = [index] + [j for g in linked for j in g]
        groups = [g for g in groups if g not in linked] + [sorted(merged)]
    return groups


def _lit_chromatic(surfaces: list[Surface], names: list[SurfaceName]) -> list[int]:
    """The indices of the lit surfaces named by a hue."""
    return [i for i, s in enumerate(surfaces) if s.kind != "dark" and names[i].name in CHROMATIC_TERMS]


def _shade_links(labs_per_object: list[list[np.ndarray]], max_difference: float) -> list[np.ndarray]:
    """For each object's colours (CIELAB), which pairs are closer than ``max_difference`` in CIEDE2000 (a
    square boolean matrix per object), from one computation over all the objects' pairs."""
    links = [np.zeros((len(labs), len(labs)), dtype=bool) for labs in labs_per_object]
    pairs = [(k, i, j) for k, labs in enumerate(labs_per_object) for i in range(len(labs)) for j in range(i)]
    if pairs:
        from annotators.image.delta_e_loops import delta_e_2000_pairs  # numba is loaded with the first objects

        first = np.array([labs_per_object[k][i] for k, i, _ in pairs])
        second = np.array([labs_per_object[k][j] for k, _, j in pairs])
        differences = delta_e_2000_pairs(first, second)  # delta_e_2000's, compiled: a few pairs, few calls
        for (k, i, j), close in zip(pairs, (differences < max_difference).tolist(), strict=True):
            links[k][i, j] = close
    return links


def _shade_sides(labs: list[np.ndarray], parameters: NamingParameters) -> np.ndarray:
    """Which pairs of an object's lit saturated colours (CIELAB) are one paint lit and in shade (either way
    round, :func:`~annotators.image.color_surfaces.is_shade_of`): a square boolean matrix."""
    looks = [look(lab, parameters) for lab in labs]
    sides = np.zeros((len(labs), len(labs)), dtype=bool)
    for i in range(len(labs)):
        for j in range(i):
            sides[i, j] = is_shade_of(looks[i], looks[j], parameters) or is_shade_of(looks[j], looks[i], parameters)
    return sides


def _pool_shades(
    surfaces: list[Surface],
    names: list[SurfaceName],
    votes: list[np.ndarray | None],
    links: np.ndarray,
) -> list[SurfaceName]:
    """The names with the lit saturated surfaces (:func:`_lit_chromatic`) that are shades of one colour (linked
    in a chain by ``links``: CIEDE2000 neighbours from :func:`_shade_links` with ``shade_delta_e``, or lit and
    shaded sides from :func:`_shade_sides`) named together, by their
    pixel-weighted term votes (``votes``: each surface's, None for the surfaces named by lightness): a brown tin
    whose print and shading spread it over reddish, pinkish and orange-brown surfaces is brown, one colour."""
    chromatic = _lit_chromatic(surfaces, names)
    pooled = list(names)
    for group in _shade_groups(links):
        if len(group) < 2:
            continue
        members = [chromatic[g] for g in group]
        pooled_votes = sum(surfaces[i].pixels * votes[i] for i in members)
        pooled_votes = pooled_votes / float(pooled_votes.sum())
        best = int(np.argmax(pooled_votes))
        for i in members:
            pooled[i] = SurfaceName(CHROMATIC_TERMS[best], float(pooled_votes[best]))
    return pooled


def name_surface(surface: Surface, surround: float, parameters: NamingParameters = DEFAULT_PARAMETERS) -> SurfaceName:
    """The name of one surface against the frame's surround luminance (see the module docstring)."""
    lab = _vote_lab(surface, parameters)
    if lab is None:
        return _lightness_name(surface, surround, parameters)
    return _name_of_votes(_term_votes(lab, parameters)[0])


def _greys_in_shade(
    surfaces: list[Surface], names: list[SurfaceName], parameters: NamingParameters
) -> list[SurfaceName]:
    """The names with each lit surface named black renamed grey when it is a lit grey surface's shaded side:
    darker, and of about its hue (within ``shade_hue`` degrees; shading changes how much light a surface sends,
    not its chromaticity). A grey cloth's folds are the cloth in shade (people name a surface by its lit side),
    as a white's shaded side, named grey, is the white's."""
    greys = [
        look(surface.lab, parameters)
        for surface, named in zip(surfaces, names, strict=True)
        if surface.kind != "dark" and named.name == "grey"
    ]
    if not greys:
        return names
    result = list(names)
    for i, (surface, named) in enumerate(zip(surfaces, names, strict=True)):
        if surface.kind == "dark" or named.name != "black":
            continue
        _, hue, _, lightness = look(surface.lab, parameters)
        if any(
            grey_lightness > lightness and abs((hue - grey_hue + 180.0) % 360.0 - 180.0) <= parameters.shade_hue
            for _, grey_hue, _, grey_lightness in greys
        ):
            result[i] = SurfaceName("grey", named.certainty)
    return result


def _object_colors(
    surfaces: list[Surface], names: list[SurfaceName], count: int, parameters: NamingParameters
) -> tuple[NamedColor, ...]:
    """The dominant colour and, when the object has two, the second one, from its named surfaces."""
    weights: dict[str, float] = {}
    certainties: dict[str, float] = {}
    names = _greys_in_shade(surfaces, names, parameters)
    lit_names = {n.name for s, n in zip(surfaces, names, strict=True) if s.kind != "dark"}
    for surface, named in zip(surfaces, names, strict=True):
        shadow = lit_names and named.name not in lit_names and surface.pixels < parameters.dark_keep_share * count
        if surface.kind == "dark" and shadow:
            continue  # shadows of the object's surfaces
        weights[named.name] = weights.get(named.name, 0.0) + surface.pixels
        certainties[named.name] = certainties.get(named.name, 0.0) + surface.pixels * named.certainty
    if "white" in weights and "grey" in weights:  # the white's shaded sides: they name nothing new
        del weights["grey"], certainties["grey"]
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


def name_objects_colors(
    objects: Sequence[tuple[np.ndarray, np.ndarray | None]],
    light: FrameLight = NEUTRAL_LIGHT,
    parameters: NamingParameters = DEFAULT_PARAMETERS,
) -> list[tuple[NamedColor, ...]]:
    """:func:`name_colors` for the objects of one frame at once (each its RGB pixels and their edge strengths or
    None): the pixels are grouped together and every surface's prototype votes come from one computation."""
    found = objects_surfaces(objects, light, parameters)
    vote_labs = [[_vote_lab(surface, parameters) for surface in surfaces] for surfaces, _ in found]
    voted = [lab for labs in vote_labs for lab in labs if lab is not None]
    vote_rows = _term_votes(np.array(voted), parameters) if voted else np.zeros((0, len(CHROMATIC_TERMS)))
    whites = [
        _white_lightness(surfaces, labs, light.surround, parameters)
        for (surfaces, _), labs in zip(found, vote_labs, strict=True)
    ]
    vote_rows = _related_to_white(
        vote_rows,
        voted,
        [white for labs, white in zip(vote_labs, whites, strict=True) for lab in labs if lab is not None],
        parameters,
    )
    winners = vote_rows.argmax(axis=1)  # each voted surface's name, as _name_of_votes picks it
    all_votes = iter(vote_rows)
    all_names = iter(
        SurfaceName(CHROMATIC_TERMS[best], share)
        for best, share in zip(winners.tolist(), vote_rows[np.arange(len(voted)), winners].tolist(), strict=True)
    )
    named = []
    for (surfaces, _), labs in zip(found, vote_labs, strict=True):
        votes = [None if lab is None else next(all_votes) for lab in labs]
        names = [
            _lightness_name(surface, light.surround, parameters) if lab is None else next(all_names)
            for surface, lab in zip(surfaces, labs, strict=True)
        ]
        named.append((votes, names))
    lit_labs = [
        [surfaces[i].lab for i in _lit_chromatic(surfaces, names)]
        for (surfaces, _), (_, names) in zip(found, named, strict=True)
    ]
    links = [
        close | _shade_sides(labs, parameters)
        for close, labs in zip(_shade_links(lit_labs, parameters.shade_delta_e), lit_labs, strict=True)
    ]
    return [
        _object_colors(surfaces, _pool_shades(surfaces, names, votes, linked), count, parameters)
        for (surfaces, count), (votes, names), linked in zip(found, named, links, strict=True)
    ]


def name_colors(
    pixels: np.ndarray,
    light: FrameLight = NEUTRAL_LIGHT,
    edges: np.ndarray | None = None,
    parameters: NamingParameters = DEFAULT_PARAMETERS,
) -> tuple[NamedColor, ...]:
    """The colours of an object from its RGB pixels (Nx3 uint8): the dominant one, then a second one when the
    object has two; ``edges`` (N, from :func:`~annotators.image.color_surfaces.edge_strength`) lets pixels on
    colour edges be left out."""
    return name_objects_colors([(pixels, edges)], light, parameters)[0]


def name_color(pixels: np.ndarray, light: FrameLight = NEUTRAL_LIGHT) -> tuple[str, float, dict[str, float]]:
    """The dominant colour name of N RGB pixels, its share, and the share of every reported name."""
    named = name_colors(pixels, light)
    return named[0].name, named[0].share, {c.name: c.share for c in named}


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
        self, max_pixels: int = 1000, parameters: NamingParameters = DEFAULT_PARAMETERS, name: str | None = None
    ) -> None:
        super().__init__(name=name)
        self.max_pixels = max_pixels
        self.parameters = parameters

    def analyse(self) -> None:
        """Name the colours of each hypothesis with pixels; fail on missing or inconsistent input."""
        image, hypotheses = image_and_hypotheses(self, "name colours for")
        light = estimate_frame_light(image)
        for hypothesis in hypotheses:
            if hypothesis.mask.shape != image.shape[:2]:
                self.fail(f"hypothesis mask {hypothesis.mask.shape} and colour image {image.shape[:2]} sizes differ")
        picked = objects_pixels(image, hypotheses, self.max_pixels)
        named = [hypothesis for hypothesis, (pixels, _) in zip(hypotheses, picked, strict=True) if pixels.shape[0]]
        objects = [(pixels, edges) for pixels, edges in picked if pixels.shape[0]]
        for hypothesis, colors in zip(named, name_objects_colors(objects, light, self.parameters), strict=True):
            for color in colors:
                self.attach(hypothesis, SemanticColor(color=color.name, ratio=color.share, confidence=color.confidence))
        if not named:
            self.fail("every object hypothesis has an empty mask")
