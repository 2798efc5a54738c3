"""Classification by knowledge: each hypothesis is compared with the typical properties of candidate classes.

The planner passes one profile per candidate class as plain data::

    {"class": "Milk", "colors": ("white",), "shape": "box", "size": "medium", "texts": ("milk",),
     "brand": None, "kind_texts": (), "handle": False, "open_top": False, "height_to_width": (1.2, 4.0),
     "elongation": None, "waisted": False, "ancestors": ("Milk", "Drink", "FoodOrDrink", "PhysicalObject"),
     "packaged_in": ()}

(colour, shape and size are the ontology's lower-case labels; the form cues - a handle, an open top, the ranges of
height over width and of elongation, a waist - are the ontology's ``rk:hasHandle``, ``rk:openTop``,
``rk:min/maxHeightToWidth``, ``rk:min/maxElongation``, ``rk:waisted``; ``packaged_in`` names the container class the
objects are typically packaged in and its ancestors, ``rk:packagedIn``: a query for a bottle also asks for a
mustard; ``brand`` is the ``rk:brand`` of a branded product, ``kind_texts`` the printed texts it inherits from its
ancestors (what kind of product it is: "crackers" for a Cheez-It box); any key but ``class`` may be missing or None:
the class may have any value).

Scoring. For every cue the hypothesis carries (its most confident SemanticColor, Shape, Size, FormFeatures and,
when read, Text) a profile gets an agreement in [0, 1]:

* colour / shape: 1 when the profile lists the observed value, 0 when it lists others, 0.5 when it says nothing;
* size class: from the largest extent the size expert measured, 1 inside the profile's size class bounds, falling
  to 0 at ``SIZE_FALLOFF`` times beyond a bound (a 13 cm can is nearly small, a 30 cm box is not); without an
  extent 1 when equal, 0.25 when one class apart, 0 when two apart; 0.5 when the profile says nothing; for a body
  standing on a thin wide base (a cup on its saucer) the largest extent is the body's, as the form expert measured
  it above the base (:func:`body_extent`);
* handle: 1 when both say there is one, 0 when one is seen on a class without, ``HANDLE_HIDDEN`` when none is
  seen on a class with one (it may be behind), ``NO_HANDLE`` when neither has one, 0.5 when the profile says
  nothing - but with none seen, a class whose kinds say (a bottle: plain, or a jug) agrees as its best kind;
* open top: 1 when equal, 0 when not, 0.5 when the profile says nothing;
* height over width: 1 inside the profile's range, falling to 0 at ``RATIO_FALLOFF`` times beyond a bound;
* elongation (the longest extent the size expert measured over the second longest): as the height over width,
  counted only for profiles that declare a range (long, narrow classes: a banana, a carrot); the others may be
  any, and a cue every other profile is neutral about would only pull their scores toward 0.5. It tells a banana
  lying on the table from a round tub or tin of the same colour, size and height over width;
* printed label (``rk:printedLabel``), when the object shows several colours (a second colour named, or the
  dominant one short of ``PLAIN_SHARE``; one colour says nothing, a label may be mostly one colour): 1 for a
  profile with a printed label, 0 for a plain one; counted only for profiles that say either (most classes, a
  jar's or a mug's, may be both, and a cue every other profile is neutral about would only pull their scores
  toward 0.5). This is what tells a labelled can from a jar or a plain plastic tub of the same size, form and
  proportions;
* waist (``rk:waisted``), only when one is seen (a middle narrower than the top and the bottom: a drill's grip
  between its body and battery): 1 for a profile with one, 0 for a profile that never has one, not counted for the
  others. None seen says nothing: most objects have none, and a drill lying on its side or seen end-on shows none;
* text: the share of the profile's texts and brand found in the read text (case, spaces and punctuation ignored, one
  OCR error tolerated per 5 letters: :func:`robokudo.core.text_match.phrase_found`), ``TEXT_NONE`` when the profile
  has neither. A brand read also counts the texts the class inherits (``kind_texts``) as read: the brand names the
  product, and with it its kind - a box reading "CHEEZ-IT" is a box of crackers whether or not the small "crackers"
  on it was read - while a variant's own text still tells variants of one brand apart (Fizzy cola, Fizzy lemon).

Colour, shape, size, handle, open-top, printed-label and waist agreements are pulled toward 0.5 by the expert's
confidence (``0.5 + (a - 0.5) * c``), so uncertain evidence counts less. The score is the weighted mean over the
observed cues with :data:`WEIGHTS` (text is strong evidence). The best match is the top score (among related
profiles with that score, the most specific one with the most matched texts when text matched, lactose-free milk
over milk; else the most general one: no evidence for a variant); its lead is how far it scores above the best
rival: a profile not related to it that no form cue rules out (:func:`ruled_out`: a settled open top the class rules
out, a height over width or elongation where the class agrees not at all) - when none can rule out the best class
itself, however the unsettled cues turn out (:func:`standing`; else every unrelated profile is a rival). A closed
can, whatever its colour, is no rival of a mug surely seen open: knowing a blue can does not make a blue mug less
surely a mug. The same holds for a class taken as a whole.

Deciding. The score is not a probability: many classes share colour, shape and size (a cup, a mug and a glass
are all small cylinders). The calibration (``calibration.FITTED``, fitted on labelled objects) turns the best
match's score, lead and whether its printed text went unread into the probability that it is right. A class is
asserted only when it fits (score >= ``min_score``) and that probability reaches :data:`ASSERT_PROBABILITY`; its
Classification confidence is that probability. Otherwise the query's class (``expected``) may break a tie: a match
of that class that fits and scores as high as the best fitting one (within ``margin``: equal but for rounding, so
the cues cannot tell the two classes apart) is asserted with its own (low) calibrated probability - the query never
lifts a poor fit (a class named by printed text whose text went unread is named only as a guess: it must tie with
every fitting class, and the calibration's unread term keeps its probability low; the root class breaks no tie;
a class packaged in the query's class counts as one of it: a mustard for "find all bottles"),
and it decides only what the form cues leave open: no settled form cue (said with confidence 1) may speak against it - a
mug seen surely closed is no mug, whatever else ties with it - nor may its proportions rule the class out
(:func:`ruled_out`: a cup on its saucer, four times as wide as high, is no jug) - and it must stay the best fitting
class (within ``margin``) however the unsettled ones turn out (:func:`cue_outcomes`): the open top as the form expert
said it, and the handle either way, as a view hides or shows it by chance. A mug whose handle the form expert could not
make out ties with a cup, but its handle seen would make it a mug, so "find a cup" does not answer it; nor is half a
bowl, flaring like a handle, a mug for "find all mugs" (surely without a handle it would be a cup). The query says
which class, not which kind of it: when it decides for a subclass of its class that the cues do not tell from another
kind of that class (:func:`kind_settled`: a mug whose handle is not seen ties a cup without a handle), the query's
class itself is asserted ("cup") when its own profile fits, with the probability that the object answers to it as a
whole; a handle seen settles it (every kind without one is contradicted): a mug seen with its handle is a mug. A
query's class without a profile of its own ("container") is no class the cues could name, and is not asserted.
Otherwise the most specific class above the best one (with or without a profile of its own) that, taken as a
whole, fits and reaches :data:`ASSERT_PROBABILITY` is asserted: its score is the best of its own and its
subclasses' profiles, its lead that over the best profile outside it (cues that cannot tell a white ceramic bowl
from a plastic one still say bowl; a cup from a glass, still a container; a carton whose printed text went unread,
still food or drink; :func:`class_evidence`). Everything else is classified :data:`UNKNOWN_CLASS` ("unknown
object") with confidence 1 - probability (how sure the classifier is that naming the best candidate would be wrong).
When the query's class decided for another class (a subclass, or a class packaged in it), the classifier also states
the query's class with the calibrated probability that the object answers to it as a whole (its answering profiles'
best score and lead, :func:`answering_evidence`) when that is higher: the answer shows the class distribution's mass
on the classes that answer to the query (:func:`reasoning.fusion.rule.answer_probability`), and a mustard whose
label went unread is unlikely a mustard but, tying with a lemon soda, as likely a bottle as the tie allows.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from types import MappingProxyType
from typing import ClassVar

import numpy as np

from annotators.classification.calibration import FITTED, Calibration
from annotators.cloud.size import SIZE_CLASS_THRESHOLDS, SIZE_CLASSES
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.text_match import phrase_found
from robokudo.core.types import (
    AnswersTo,
    CasType,
    Classification,
    FormFeatures,
    ObjectHypothesis,
    SemanticColor,
    Shape,
    Size,
    Text,
)

WEIGHTS: Mapping[str, float] = MappingProxyType(
    {
        "color": 1.0,
        "shape": 1.0,
        "size": 1.0,
        "handle": 1.0,
        "open": 1.0,
        "ratio": 1.0,
        "printed": 1.0,
        "waist": 1.0,
        "text": 3.0,
    }
)
"""How much each cue counts in the score. The open top and the size class count as much as the handle: the open top
is what tells a cup, a mug or a bowl from a closed can, jar or tub of the same size, shape and proportions; the size
what tells a mug from a pitcher or a pot (open, with a handle, of the same proportions)."""

HANDLE_HIDDEN = 0.3
"""Handle agreement of a class with a handle when none was seen: it may be on the hidden side, but from most
directions a mug's handle shows (it hides behind the body in roughly a third of the views around it), so not seeing
one speaks against the class: a handle-less cup does not tie with a mug and the query's class cannot make it one.
How sure the form expert is that none is in view (``handle_confidence``) weighs this as any cue."""

NO_HANDLE = 0.6
"""Handle agreement of a class without a handle when none was seen (most objects show none)."""

RATIO_FALLOFF = 1.5
"""Height over width this many times beyond a profile's bound agrees not at all (log-linear in between)."""

SIZE_FALLOFF = 1.5
"""A largest extent this many times beyond a size class's bounds agrees with it not at all (log-linear in between,
as the height over width): a 13 cm can is nearly small, a 30 cm box is not."""

PLAIN_SHARE = 0.8
"""Share of an object's named pixels its dominant colour covers from which the object looks one-coloured (plain);
below it, or with a second colour reported, it shows several colours (a printed label). The colour expert already
discounts shadows, highlights and edge pixels, so a plain surface is named nearly all one colour."""

TEXT_NONE = 0.4
"""Text agreement of a profile without texts when the object has readable text."""

UNKNOWN_CLASS = "PhysicalObject"
"""The class of a hypothesis no profile fits clearly (the root class: it is some object)."""

MIN_SCORE = 0.6
"""Default score a profile needs to fit at all."""

TIE_MARGIN = 1e-6
"""Default score difference within which the query's class may decide between fitting candidates: equal scores
only. A class the cues score lower, however slightly (a can's closed top seen with little confidence, its colour
against a cup's), is not lifted over the one they prefer: the query's class decides only what the cues leave
open (a cup and a glass look alike to a depth camera), so it cannot do the work of the cues."""

ASSERT_PROBABILITY = 0.5
"""Calibrated probability of being right from which a class is asserted (more likely right than wrong)."""


def _names(value: object) -> tuple[str, ...]:
    if value is None:
        return ()
    if isinstance(value, str):
        return (value.lower(),) if value else ()
    return tuple(str(v).lower() for v in value if v)  # type: ignore[attr-defined]


def _flag(data: Mapping[str, object], key: str) -> bool | None:
    value = data.get(key)
    if value is not None and not isinstance(value, bool):
        raise ValueError(f"a profile's {key!r} must be true, false or missing, got {value!r}")
    return value


def _flags(data: Mapping[str, object], key: str) -> frozenset[bool]:
    values = data.get(key) or ()
    if not isinstance(values, (list, tuple)) or not all(isinstance(value, bool) for value in values):
        raise ValueError(f"a profile's {key!r} must be a list of true and false, got {values!r}")
    return frozenset(values)


def _ratio_range(value: object) -> tuple[float, float] | None:
    if value is None:
        return None
    try:
        low, high = (float(v) for v in value)  # type: ignore[attr-defined]
    except (TypeError, ValueError) as error:
        raise ValueError(f"a profile's ratio range must be (min, max), got {value!r}") from error
    if not 0.0 <= low < high:
        raise ValueError(f"a profile's ratio range must have 0 <= min < max, got {value!r}")
    return low, high


def _lineage(name: str, ancestors: object) -> tuple[str, ...]:
    given = [str(a) for a in ancestors] if isinstance(ancestors, Sequence) and not isinstance(ancestors, str) else []  # type: ignore[union-attr]
    return (name, *(a for a in dict.fromkeys(given) if a and a.lower() != name.lower()))


@dataclass(frozen=True)
class Profile:
    """The typical properties of one candidate class (see the module docstring)."""

    class_name: str
    colors: tuple[str, ...] = ()
    shape: str | None = None
    size: str | None = None
    texts: tuple[str, ...] = ()
    ancestors: frozenset[str] = frozenset()
    lineage: tuple[str, ...] = ()
    """The class and its ancestors as named, the most specific first (as the planner orders them)."""
    handle: bool | None = None
    open_top: bool | None = None
    height_to_width: tuple[float, float] | None = None
    printed: bool | None = None
    elongation: tuple[float, float] | None = None
    waisted: bool | None = None
    packaged_in: frozenset[str] = frozenset()
    """The container class the objects are typically packaged in and its ancestors (lower case), or empty."""
    brand: str | None = None
    kind_texts: frozenset[str] = frozenset()
    """The texts (of :attr:`texts`) the class inherits from its ancestors: read when its brand is read."""
    kind_handles: frozenset[bool] = frozenset()
    """For a class that does not say whether it has a handle (:attr:`handle` None): what its kinds say (a bottle
    with none in view agrees as a plain bottle does)."""

    @property
    def named_by_text(self) -> bool:
        """True when printed text or a brand names the class (reading it is what tells the class apart)."""
        return bool(self.texts or self.brand)

    def answers(self, wanted: str) -> bool:
        """True when an object of this class answers a query for ``wanted`` (lower case): it is one, or it is
        typically packaged in one (a mustard is seen as its bottle)."""
        return wanted in self.ancestors or wanted in self.packaged_in

    @classmethod
    def from_mapping(cls, data: Mapping[str, object]) -> Profile:
        """A profile from the planner's plain data; ValueError when it names no class."""
        if not isinstance(data, Mapping):
            raise ValueError(f"a profile must be a mapping, got {type(data).__name__}")
        name = data.get("class")
        if not isinstance(name, str) or not name:
            raise ValueError(f"a profile needs a non-empty 'class', got {data!r}")
        shapes, sizes = _names(data.get("shape")), _names(data.get("size"))
        texts = _names(data.get("texts"))
        brands = _names(data.get("brand"))
        return cls(
            class_name=name,
            colors=_names(data.get("colors")),
            shape=shapes[0] if shapes else None,
            size=sizes[0] if sizes else None,
            texts=texts,
            ancestors=frozenset(_names(data.get("ancestors"))) | {name.lower()},
            lineage=_lineage(name, data.get("ancestors")),
            handle=_flag(data, "handle"),
            open_top=_flag(data, "open_top"),
            height_to_width=_ratio_range(data.get("height_to_width")),
            printed=_flag(data, "printed"),
            elongation=_ratio_range(data.get("elongation")),
            waisted=_flag(data, "waisted"),
            packaged_in=frozenset(_names(data.get("packaged_in"))),
            brand=brands[0] if brands else None,
            kind_texts=frozenset(_names(data.get("kind_texts"))) & frozenset(texts),
            kind_handles=_flags(data, "kind_handles"),
        )

    def related(self, other: Profile) -> bool:
        """True when one of the two classes subsumes the other."""
        return self.class_name.lower() in other.ancestors or other.class_name.lower() in self.ancestors


@dataclass(frozen=True)
class Cues:
    """The cues the experts gave about one hypothesis (None: not given): the most confident colour, shape and
    size class with their confidences, the text read on it, the form cues, the largest extent (metres) the size
    class was named from, the longest extent over the second longest (elongation), whether it shows several colours
    (a printed label) and whether its middle is narrower than its top and bottom (a waist), each with how sure that
    is."""

    color: tuple[str, float] | None = None
    shape: tuple[str, float] | None = None
    size: tuple[str, float] | None = None
    text: str | None = None
    handle: tuple[bool, float] | None = None
    open_top: tuple[bool, float] | None = None
    height_to_width: float | None = None
    extent: float | None = None
    printed: tuple[bool, float] | None = None
    elongation: float | None = None
    waist: tuple[bool, float] | None = None


@dataclass(frozen=True)
class Match:
    """A profile's score for one hypothesis, how many of its texts were found, and whether the profile names
    texts that were not looked for (no text was read on the hypothesis)."""

    profile: Profile
    score: float
    texts_found: int
    unread: bool = False


def _toward_neutral(agreement: float, confidence: float) -> float:
    return 0.5 + (agreement - 0.5) * min(max(confidence, 0.0), 1.0)


def _value_agreement(observed: str, listed: Sequence[str]) -> float:
    return 0.5 if not listed else (1.0 if observed.lower() in listed else 0.0)


def _size_agreement(observed: str, listed: str | None) -> float:
    if listed is None or listed not in SIZE_CLASSES or observed not in SIZE_CLASSES:
        return 0.5
    return (1.0, 0.25, 0.0)[abs(SIZE_CLASSES.index(observed) - SIZE_CLASSES.index(listed))]


def _extent_agreement(extent: float, listed: str | None) -> float | None:
    """Agreement of a largest extent with a size class: 1 inside its bounds (:data:`SIZE_CLASS_THRESHOLDS`),
    falling to 0 at :data:`SIZE_FALLOFF` times beyond; None when either is unknown."""
    if listed not in SIZE_CLASSES or not np.isfinite(extent) or extent <= 0.0:
        return None
    bounds = (0.0, *SIZE_CLASS_THRESHOLDS, np.inf)
    index = SIZE_CLASSES.index(listed)  # type: ignore[arg-type]
    low, high = bounds[index], bounds[index + 1]
    beyond = max(np.log(low / extent) if low > 0 else 0.0, np.log(extent / high) if np.isfinite(high) else 0.0, 0.0)
    return float(max(0.0, 1.0 - beyond / np.log(SIZE_FALLOFF)))


def _handle_agreement(seen: bool, listed: bool | None, kinds: frozenset[bool] = frozenset()) -> float:
    """How a class's handle agrees with one seen or not. A class that does not say agrees halfway, unless none was
    seen and its kinds say (a bottle with none in view agrees as a plain bottle does, a jug's handle may be behind);
    a handle seen is what tells its kinds with one apart (a mug from a cup), so for the class that does not say it
    stays halfway."""
    if listed is None:
        return 0.5 if seen or not kinds else max(_handle_agreement(False, kind) for kind in kinds)
    if seen:
        return 1.0 if listed else 0.0
    return HANDLE_HIDDEN if listed else NO_HANDLE


def _ratio_agreement(ratio: float, listed: tuple[float, float] | None) -> float:
    if listed is None or not np.isfinite(ratio) or ratio <= 0.0:
        return 0.5
    low, high = listed
    beyond = max(np.log(low / ratio) if low > 0 else 0.0, np.log(ratio / high) if np.isfinite(high) else 0.0, 0.0)
    return float(max(0.0, 1.0 - beyond / np.log(RATIO_FALLOFF)))


def score(profile: Profile, cues: Cues) -> Match:
    """The weighted agreement of a profile with a hypothesis's cues (see the module docstring)."""
    total = weight = 0.0
    found = 0
    if cues.color is not None:
        color, confidence = cues.color
        total += WEIGHTS["color"] * _toward_neutral(_value_agreement(color, profile.colors), confidence)
        weight += WEIGHTS["color"]
    if cues.shape is not None:
        shapes = (profile.shape,) if profile.shape else ()
        total += WEIGHTS["shape"] * _toward_neutral(_value_agreement(cues.shape[0], shapes), cues.shape[1])
        weight += WEIGHTS["shape"]
    if cues.size is not None:
        graded = _extent_agreement(cues.extent, profile.size) if cues.extent is not None else None
        agreement = _size_agreement(cues.size[0], profile.size) if graded is None else graded
        total += WEIGHTS["size"] * _toward_neutral(agreement, cues.size[1])
        weight += WEIGHTS["size"]
    if cues.handle is not None:
        agreement = _handle_agreement(cues.handle[0], profile.handle, profile.kind_handles)
        total += WEIGHTS["handle"] * _toward_neutral(agreement, cues.handle[1])
        weight += WEIGHTS["handle"]
    if cues.open_top is not None:
        listed = profile.open_top
        agreement = 0.5 if listed is None else float(listed == cues.open_top[0])
        total += WEIGHTS["open"] * _toward_neutral(agreement, cues.open_top[1])
        weight += WEIGHTS["open"]
    if cues.height_to_width is not None:
        total += WEIGHTS["ratio"] * _ratio_agreement(cues.height_to_width, profile.height_to_width)
        weight += WEIGHTS["ratio"]
    if cues.elongation is not None and profile.elongation is not None:
        total += WEIGHTS["ratio"] * _ratio_agreement(cues.elongation, profile.elongation)
        weight += WEIGHTS["ratio"]
    if cues.printed is not None and profile.printed is not None:
        agreement = float(profile.printed == cues.printed[0])
        total += WEIGHTS["printed"] * _toward_neutral(agreement, cues.printed[1])
        weight += WEIGHTS["printed"]
    if cues.waist is not None and cues.waist[0] and profile.waisted is not None:
        total += WEIGHTS["waist"] * _toward_neutral(float(profile.waisted), cues.waist[1])
        weight += WEIGHTS["waist"]
    if cues.text:
        found = text_found(profile, cues.text)
        names = len(profile.texts) + (profile.brand is not None)
        agreement = found / names if names else TEXT_NONE
        total += WEIGHTS["text"] * agreement
        weight += WEIGHTS["text"]
    return Match(profile, total / weight if weight else 0.0, found, unread=profile.named_by_text and not cues.text)


def text_found(profile: Profile, read: str) -> int:
    """How many of the profile's texts and brand are found in the ``read`` text; a brand found also finds the texts
    the class inherits (:attr:`Profile.kind_texts`: the brand names the product's kind too)."""
    brand = profile.brand is not None and phrase_found(profile.brand, read)
    found = [text for text in profile.texts if (brand and text in profile.kind_texts) or phrase_found(text, read)]
    return len(found) + brand


def best_match(matches: Sequence[Match]) -> Match:
    """The best of the matches of one hypothesis: the highest score; among related profiles with that score the
    most specific one with the most matched texts when text matched, else the most general one."""
    top = max(m.score for m in matches)
    tied = [m for m in matches if m.score >= top - 1e-9]
    if any(m.texts_found for m in tied):
        return max(tied, key=lambda m: (m.texts_found, len(m.profile.ancestors)))
    return min(tied, key=lambda m: len(m.profile.ancestors))


def ruled_out(profile: Profile, cues: Cues | None) -> bool:
    """True when a form cue rules the profile's class out: an open top said with confidence 1 (settled) on a
    closed class or the other way, or a height over width (or, for a class that declares one, an elongation)
    :data:`RATIO_FALLOFF` times or more beyond the class's range, where it agrees not at all. A handle seen rules
    nothing out here: the form expert also sees one in a drill's grip or a toy brick's knobs, objects of no known
    class, and with every class without a handle ruled out, the one class with a handle left would lead by its
    whole score (it still keeps the query from deciding for a class without one: :func:`contradicted`). Colour,
    shape and size never rule a class out (the view or the light can make any of them look wrong). False without
    ``cues``."""
    if cues is None:
        return False
    seen = cues.open_top
    open_top_against = (
        seen is not None and seen[1] >= 1.0 and profile.open_top is not None and profile.open_top != seen[0]
    )
    return (
        open_top_against
        or _beyond(cues.height_to_width, profile.height_to_width)
        or _beyond(cues.elongation, profile.elongation)
    )


def _beyond(ratio: float | None, listed: tuple[float, float] | None) -> bool:
    """True when a measured ratio agrees not at all with a declared range (both known): it lies
    :data:`RATIO_FALLOFF` times or more beyond a bound, where :func:`_ratio_agreement` reaches 0 (compared
    directly, without its logarithms: this runs for every profile in every lead)."""
    if ratio is None or listed is None or not 0.0 < ratio < math.inf:
        return False
    low, high = listed
    return ratio * RATIO_FALLOFF <= low or ratio >= high * RATIO_FALLOFF


def standing(profile: Profile, cues: Cues | None) -> bool:
    """True when no form cue rules the class out or speaks against it (:func:`ruled_out`, :func:`contradicted`: a
    handle surely seen on a class without one) as the cues were said nor however the unsettled ones turn out
    (:func:`cue_outcomes`); True without ``cues``."""
    return cues is None or not any(
        ruled_out(profile, c) or contradicted(profile, c) for c in (cues, *cue_outcomes(cues))
    )


def counts_as_rival(other: Profile, standing_match: bool, cues: Cues | None) -> bool:
    """True when a profile outside the class being weighed still competes with it: always, unless the class is
    ``standing_match`` (:func:`standing`: no form cue can rule it out) and a form cue rules ``other`` out (a closed
    can, whatever its colour, is no rival of a mug surely seen open; of a mug seen closed though not surely, it is,
    as the mug itself might be ruled out)."""
    return not (standing_match and ruled_out(other, cues))


def lead(match: Match, matches: Sequence[Match], cues: Cues | None = None) -> float:
    """How far ``match`` scores above the best rival: a profile not related to it by subsumption that still
    competes with it under the form ``cues`` the matches were scored on (:func:`counts_as_rival`); its own score
    when there is none; negative when a rival scores higher."""
    keep = standing(match.profile, cues)
    rivals = [
        m.score for m in matches if not m.profile.related(match.profile) and counts_as_rival(m.profile, keep, cues)
    ]
    return match.score - max(rivals, default=0.0)


def members(name: str, matches: Sequence[Match]) -> list[Match]:
    """The matches of ``name`` (lower case) and of its subclasses."""
    return [m for m in matches if name in m.profile.ancestors]


def above(match: Match, name: str, inside: Sequence[Match]) -> bool:
    """True when ``match``'s class is a proper superclass of ``name`` (lower case), whose matches (of it and its
    subclasses) are ``inside``: every one of them has it as an ancestor, and it is not below ``name``."""
    own = match.profile.class_name.lower()
    return own != name and name not in match.profile.ancestors and all(own in m.profile.ancestors for m in inside)


def class_evidence(name: str, matches: Sequence[Match], cues: Cues | None = None) -> tuple[float, float, bool]:
    """The evidence for class ``name`` (lower case, with or without a profile of its own) as a whole: the best score
    of its own and its subclasses' profiles, how far that lies above the best profile outside it (neither below
    nor above it, and competing under the form ``cues``: :func:`counts_as_rival`), and whether its own profile
    names it by printed text that was not read."""
    return _evidence_of(name, matches, lambda profile: name in profile.ancestors, cues)


def answering_evidence(wanted: str, matches: Sequence[Match], cues: Cues | None = None) -> tuple[float, float, bool]:
    """The evidence that the object answers a query for class ``wanted`` (lower case), taken as a whole: as
    :func:`class_evidence`, over the profiles that answer to it (:meth:`Profile.answers`: it, its subclasses, classes
    packaged in it), against those that do not, are not above all of them and still compete."""
    return _evidence_of(wanted, matches, lambda profile: profile.answers(wanted), cues)


def _evidence_of(
    name: str, matches: Sequence[Match], belongs: Callable[[Profile], bool], cues: Cues | None
) -> tuple[float, float, bool]:
    """(best score, lead, unread) of the matches whose profile ``belongs`` to ``name``, against the others that are
    not above all of them and still compete under the form ``cues`` (:func:`counts_as_rival`)."""
    inside = [m for m in matches if belongs(m.profile)]
    top = max((m.score for m in inside), default=0.0)
    keep = any(standing(m.profile, cues) for m in inside if m.score >= top)
    rivals = [
        m.score
        for m in matches
        if not belongs(m.profile) and not above(m, name, inside) and counts_as_rival(m.profile, keep, cues)
    ]
    unread = any(m.unread for m in inside if m.profile.class_name.lower() == name)
    return top, top - max(rivals, default=0.0), unread


def more_general_fit(
    best: Match,
    matches: Sequence[Match],
    min_score: float,
    calibration: Calibration,
    assert_probability: float,
    cues: Cues | None = None,
) -> tuple[str, float, float, float] | None:
    """The most specific class above ``best`` (one of its ancestors, not the root class, with or without a profile of
    its own) that, taken as a whole (:func:`class_evidence`), fits and is right with at least
    ``assert_probability``: (its name, score, lead, probability); None when there is none. When the cues cannot tell
    a white ceramic bowl from a plastic one it is still surely a bowl; when they cannot tell a cup from a glass it is
    still a container; when a carton's printed text was not read it is still food or drink."""
    names = [a for a in best.profile.lineage[1:] if a.lower() != UNKNOWN_CLASS.lower()]
    names.sort(key=lambda a: len(members(a.lower(), matches)))  # stable: the lineage order breaks ties
    for name in names:
        top, name_lead, unread = class_evidence(name.lower(), matches, cues)
        if top < min_score or unread:
            continue
        p = calibration.probability(top, name_lead, unread)
        if p >= assert_probability:
            return name, top, name_lead, p
    return None


def choose_expected(matches: Sequence[Match], expected: str, min_score: float, margin: float) -> Match | None:
    """The query's class breaking a tie: the best match of the expected class (a subclass, or a class packaged in
    it: :meth:`Profile.answers`) among the fitting matches within ``margin`` of the best fitting score; None
    otherwise, and always for the root class (a query for any object prefers none). A match fits when it scores at
    least ``min_score``. A class named by printed text that went unread (a mustard whose label was not read) is
    only a guess: it must tie with every fitting match, those of other unread classes included, while a match
    whose texts were read (or that names none) need only tie with those (an unread class scores without the
    cue that would tell it apart, so it does not raise their bar); its calibrated probability stays low."""
    wanted = expected.lower()
    fitting = [m for m in matches if m.score >= min_score]
    if not fitting or wanted == UNKNOWN_CLASS.lower():
        return None
    top = max(m.score for m in fitting)
    top_read = max((m.score for m in fitting if not m.unread), default=top)
    candidates = [
        m for m in fitting if (top if m.unread else top_read) - m.score <= margin and m.profile.answers(wanted)
    ]
    return max(candidates, key=lambda m: (not m.unread, m.score, -len(m.profile.ancestors)), default=None)


def cue_outcomes(cues: Cues) -> list[Cues]:
    """The ways the unsettled form cues (said with confidence below 1) could turn out. A handle is what a view hides
    or shows by chance: as the form expert said it, with full confidence, and the other way with the confidence it
    left (1 - its confidence). An open top is seen from the same view either way: as said, with full confidence.
    None for settled or missing cues."""
    outcomes = []
    if cues.handle is not None and cues.handle[1] < 1.0:
        seen, confidence = bool(cues.handle[0]), max(float(cues.handle[1]), 0.0)
        outcomes += [replace(cues, handle=(seen, 1.0)), replace(cues, handle=(not seen, 1.0 - confidence))]
    if cues.open_top is not None and cues.open_top[1] < 1.0:
        outcomes.append(replace(cues, open_top=(bool(cues.open_top[0]), 1.0)))
    return outcomes


def contradicted(profile: Profile, cues: Cues) -> bool:
    """True when a settled form cue (said with confidence 1) says what the profile rules out: an open top seen on a
    closed class or the other way, a handle seen on a class without one (a handle not seen may be behind)."""
    handle, open_top = cues.handle, cues.open_top
    if handle is not None and handle[1] >= 1.0 and handle[0] and profile.handle is False:
        return True
    return (
        open_top is not None and open_top[1] >= 1.0 and profile.open_top is not None and profile.open_top != open_top[0]
    )


def holds_up(pick: Match, matches: Sequence[Match], cues: Cues | None, min_score: float, margin: float) -> bool:
    """True when the query may decide for ``pick``: however the unsettled form cues turn out (:func:`cue_outcomes`,
    the same profiles as ``matches`` scored again), and as the settled ones are, no form cue rules its class out
    (:func:`contradicted`; nor a height over width or elongation where the class agrees not at all,
    :func:`ruled_out`: a cup on its saucer, four times as wide as high, is no jug for 'find a bottle') and it stays
    within ``margin`` of every fitting class not related to it; always without ``cues``."""
    if cues is None:
        return True
    if contradicted(pick.profile, cues) or ruled_out(pick.profile, cues):
        return False
    for outcome in cue_outcomes(cues):
        if contradicted(pick.profile, outcome):
            return False
        own = score(pick.profile, outcome).score
        rivals = [
            m.score
            for m in (score(match.profile, outcome) for match in matches)
            if m.score >= min_score and not m.unread and not m.profile.related(pick.profile)
        ]
        if rivals and max(rivals) > own + margin:
            return False
    return True


def kind_settled(
    pick: Match,
    matches: Sequence[Match],
    wanted: str,
    cues: Cues | None,
    min_score: float,
    calibration: Calibration,
    assert_probability: float,
) -> bool:
    """True unless ``pick`` is a proper subclass of the query's class ``wanted`` (lower case) that the cues do not
    tell from another of its kinds: a fitting match below ``wanted``, unrelated to ``pick`` and not contradicted by a
    settled form cue (:func:`contradicted`), scores so close that ``pick`` is right with less than
    ``assert_probability``. The query says which class, not which kind of it: a mug whose handle is not seen ties
    a cup without a handle, and for "find a cup" it is a cup, not a cup without a handle; a handle seen contradicts
    every kind without one, so a mug seen with its handle is a mug."""
    if wanted not in pick.profile.ancestors or pick.profile.class_name.lower() == wanted:
        return True
    kinds = [
        m.score
        for m in matches
        if wanted in m.profile.ancestors
        and m.profile.class_name.lower() != wanted
        and not m.profile.related(pick.profile)
        and m.score >= min_score
        and not (cues is not None and contradicted(m.profile, cues))
    ]
    if not kinds:
        return True
    return calibration.probability(pick.score, pick.score - max(kinds), pick.unread) >= assert_probability


@dataclass(frozen=True)
class Decision:
    """What the classifier says about one hypothesis and why.

    ``class_name`` is the asserted class, or :data:`UNKNOWN_CLASS` when no profile fits clearly; ``confidence``
    is the calibrated probability that the statement is right (for the unknown class: that the best candidate
    would have been wrong). ``best`` and ``margin`` are the evidence, ``probability`` the calibrated probability
    that ``best`` is right, ``reason`` says in words why the class was or was not asserted. ``answering`` is set
    when the query's class decided for a class other than itself (a subclass, or a class packaged in it): the
    calibrated probability that the object answers to the query's class, taken as a whole
    (:func:`answering_evidence`), when it exceeds ``confidence`` (a mustard whose label went unread and that ties
    with a lemon soda is surely no mustard, but as likely a bottle as the tie allows).
    """

    class_name: str
    confidence: float
    best: Match
    margin: float
    probability: float
    reason: str
    answering: float | None = None


def decide(
    matches: Sequence[Match],
    *,
    min_score: float = MIN_SCORE,
    margin: float = TIE_MARGIN,
    expected: str | None = None,
    calibration: Calibration = FITTED,
    assert_probability: float = ASSERT_PROBABILITY,
    cues: Cues | None = None,
) -> Decision:
    """The class of one hypothesis from its matches (see the module docstring); ValueError without matches.
    With the ``cues`` the matches were scored on, classes the form cues rule out are no rivals in the leads
    (:func:`ruled_out`), and the query's class decides only when it holds up against them (:func:`holds_up`)."""
    if not matches:
        raise ValueError("no profile matches to decide from")
    best = best_match(matches)
    best_lead = lead(best, matches, cues)
    p = calibration.probability(best.score, best_lead, best.unread)
    name = best.profile.class_name
    if best.score >= min_score and p >= assert_probability:
        return Decision(name, p, best, best_lead, p, f"fits {name} (score {best.score:.2f}, lead {best_lead:.2f})")
    pick = choose_expected(matches, expected, min_score, margin) if expected else None
    if pick is not None and holds_up(pick, matches, cues, min_score, margin):
        wanted = expected.lower() if expected else ""
        own = [m for m in matches if m.profile.class_name.lower() == wanted and m.score >= min_score]
        if own and not kind_settled(pick, matches, wanted, cues, min_score, calibration, assert_probability):
            answers = calibration.probability(*answering_evidence(wanted, matches, cues))
            return Decision(
                own[0].profile.class_name,
                answers,
                best,
                best_lead,
                p,
                f"{pick.profile.class_name} fits (score {pick.score:.2f}) as well as any other class, but the cues do "
                f"not tell it from other kinds of {expected}: the query's class decides for {expected}",
            )
        pick_lead = lead(pick, matches, cues)
        pick_p = calibration.probability(pick.score, pick_lead, pick.unread)
        answering = None
        if expected and pick.profile.class_name.lower() != expected.lower():
            answering = calibration.probability(*answering_evidence(expected.lower(), matches, cues))
        return Decision(
            pick.profile.class_name,
            pick_p,
            best,
            best_lead,
            p,
            f"{pick.profile.class_name} fits (score {pick.score:.2f}) as well as any other class; "
            f"the query's class decides",
            answering if answering is not None and answering > pick_p else None,
        )
    general = more_general_fit(best, matches, min_score, calibration, assert_probability, cues)
    if general is not None:
        general_name, general_score, general_lead, general_p = general
        return Decision(
            general_name,
            general_p,
            best,
            best_lead,
            p,
            f"fits {name} but leads only by {best_lead:.2f}; fits {general_name}, a class above it "
            f"(score {general_score:.2f}, lead {general_lead:.2f})",
        )
    if pick is not None:
        return Decision(
            UNKNOWN_CLASS,
            1.0 - p,
            best,
            best_lead,
            p,
            f"{pick.profile.class_name} fits (score {pick.score:.2f}) as well as any other class, but a form cue "
            f"speaks against it or, unsettled, could make another class fit better: the query's class does not "
            f"decide",
        )
    why = (
        f"no class fits: the closest, {name}, scores {best.score:.2f}"
        if best.score < min_score
        else f"{name} fits (score {best.score:.2f}) but leads only by {best_lead:.2f}: right with probability {p:.2f}"
    )
    return Decision(UNKNOWN_CLASS, 1.0 - p, best, best_lead, p, why)


def printed_cue(colors: Sequence[SemanticColor]) -> tuple[bool, float] | None:
    """(True, 1.0) when an object shows several colours, as a printed label does: a second colour reported, or a
    dominant one covering less than :data:`PLAIN_SHARE`; None otherwise. One colour says nothing: a label may be
    mostly one colour (a soup can's white half, a white tin with small flowers), as a handle may be hidden."""
    if colors and (len(colors) > 1 or max(a.ratio for a in colors) < PLAIN_SHARE):
        return True, 1.0
    return None


def elongation(dimensions: Sequence[float]) -> float | None:
    """The longest extent over the second longest (dimensions sorted largest first, as the size expert gives them);
    None when there are not two positive extents."""
    if len(dimensions) < 2 or not dimensions[1] > 0.0 or not np.isfinite(dimensions[0]):
        return None
    return float(dimensions[0] / dimensions[1])


def body_extent(form: FormFeatures | None) -> float | None:
    """The largest extent (metres) of the body standing on a thin wide base (a cup on its saucer), which the form
    expert measured above the base: the class is the body's, the size expert's extents are the base's; None
    without a base."""
    if form is None or form.body_width is None:
        return None
    return max(form.body_width, form.height_to_width * form.body_width)


class KnowledgeClassifier(Annotator):
    """Names each hypothesis' class from its colour, shape, size, form and text, compared with candidate profiles."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis, SemanticColor, Shape, Size, FormFeatures)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (Text,)
    outputs: ClassVar[tuple[type[CasType], ...]] = (Classification, AnswersTo)
    capability: ClassVar[Capability] = Capability(
        label="knowledge classifier",
        classes=(UNKNOWN_CLASS,),
        cost_ms=0.5,
        reliability=0.7,
    )

    def __init__(
        self,
        profiles: Sequence[Mapping[str, object]] = (),
        name: str | None = None,
        min_score: float = MIN_SCORE,
        margin: float = TIE_MARGIN,
        expected: str | None = None,
    ) -> None:
        """``expected`` is the class the query asks for; it only decides between near-equal fitting candidates."""
        super().__init__(name=name)
        self.profiles = tuple(Profile.from_mapping(p) for p in profiles)
        self.min_score = min_score
        self.margin = margin
        self.expected = expected

    def cues(self, hypothesis: ObjectHypothesis) -> Cues:
        """The most confident colour, shape, size and the text read on the hypothesis."""
        colors = self.attached(hypothesis, SemanticColor)
        color = max(colors, key=lambda a: a.confidence, default=None)
        shape = max(self.attached(hypothesis, Shape), key=lambda a: a.confidence, default=None)
        size = max(self.attached(hypothesis, Size), key=lambda a: a.confidence, default=None)
        texts = [t.text for t in self.attached(hypothesis, Text) if t.text.strip()]
        form = max(self.attached(hypothesis, FormFeatures), key=lambda a: a.confidence, default=None)
        return Cues(
            color=(color.color, color.confidence) if color is not None else None,
            shape=(shape.shape, shape.confidence) if shape is not None else None,
            size=(size.size_class, size.confidence) if size is not None else None,
            text=" ".join(texts) or None,
            handle=(form.has_handle, form.handle_confidence) if form is not None else None,
            open_top=(form.open_top, form.open_confidence) if form is not None else None,
            height_to_width=form.height_to_width if form is not None else None,
            extent=body_extent(form) or (max(size.dimensions) if size is not None and size.dimensions else None),
            printed=printed_cue(colors),
            elongation=elongation(size.dimensions) if size is not None else None,
            waist=(form.waisted, form.waist_confidence) if form is not None else None,
        )

    def decide(self, cues: Cues) -> Decision:
        """The decision for one hypothesis' cues with this classifier's profiles and parameters."""
        matches = [score(profile, cues) for profile in self.profiles]
        return decide(matches, min_score=self.min_score, margin=self.margin, expected=self.expected, cues=cues)

    def analyse(self) -> None:
        """Attach a Classification to every hypothesis that carries cues: its class when one fits clearly, else
        :data:`UNKNOWN_CLASS` (so the answer can say "unknown object"); when the query's class decided for a class
        below or packaged in it, also an AnswersTo of the query's class with the probability that the object
        answers to it (:attr:`Decision.answering`: the answer then shows that figure for "find all bottles", while
        the object's belief keeps only what the object was classified as)."""
        if not self.profiles:
            self.fail("no candidate class profiles to compare the hypotheses with")
        hypotheses = self.annotations(ObjectHypothesis)
        if not hypotheses:
            self.fail("no object hypotheses to classify")
        classified = 0
        for hypothesis in hypotheses:
            cues = self.cues(hypothesis)
            if cues == Cues():
                continue
            decision = self.decide(cues)
            self.attach(hypothesis, Classification(class_name=decision.class_name, confidence=decision.confidence))
            if decision.answering is not None and self.expected:  # what the query asked for, as a whole
                self.attach(hypothesis, AnswersTo(class_name=self.expected, confidence=decision.answering))
            classified += 1
        if classified == 0:
            self.fail("no object hypothesis carries a colour, shape, size or text to classify by")
