"""Classification by knowledge: each hypothesis is compared with the typical properties of candidate classes.

The planner passes one profile per candidate class as plain data::

    {"class": "Milk", "colors": ("white",), "shape": "box", "size": "medium", "texts": ("milk",),
     "ancestors": ("Milk", "Drink", "FoodOrDrink", "PhysicalObject")}

(colour, shape and size are the ontology's lower-case labels; any key but ``class`` may be missing or None).

Scoring. For every cue the hypothesis carries (its most confident SemanticColor, Shape, Size and, when read,
Text) a profile gets an agreement in [0, 1]:

* colour / shape: 1 when the profile lists the observed value, 0 when it lists others, 0.5 when it says nothing;
* size class: 1 when equal, 0.25 when one class apart, 0 when two apart, 0.5 when the profile says nothing;
* text: the share of the profile's texts found in the read text (case and punctuation ignored), ``TEXT_NONE``
  when the profile has no texts.

Colour, shape and size agreements are pulled toward 0.5 by the expert's confidence (``0.5 + (a - 0.5) * c``), so
uncertain evidence counts less. The score is the weighted mean over the observed cues with :data:`WEIGHTS`
(text is strong evidence). A hypothesis is classified as the best profile when its score is at least
``min_score`` and beats every profile not related to it by subsumption by ``margin``. When none is clear and
the query asked for a class (``expected``), a match of that class within ``margin`` of the best wins: the query
is a prior, deciding only between near-equal candidates, and such a guess is stated with confidence
:data:`GUESS_CONFIDENCE` (no evidence for the class over its rivals), so the answer may offer the object while
its belief takes no class from the query. Among related profiles
with the same score, the most specific one with the most matched texts wins when text was read and matched
(lactose-free milk over milk), else the most general one (no evidence for a variant).
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType
from typing import ClassVar

from annotators.cloud.size import SIZE_CLASSES
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CasType, Classification, ObjectHypothesis, SemanticColor, Shape, Size, Text

WEIGHTS: Mapping[str, float] = MappingProxyType({"color": 1.0, "shape": 1.0, "size": 0.5, "text": 3.0})
"""How much each cue counts in the score."""

GUESS_CONFIDENCE = 0.5
"""Confidence of a class chosen by the query's prior among near-equal candidates: log-odds 0, no evidence."""

TEXT_NONE = 0.4
"""Text agreement of a profile without texts when the object has readable text."""

_NOT_ALPHANUMERIC = re.compile(r"[^0-9a-z]+")


def compact(text: str) -> str:
    """Lower-case letters and digits only: how texts are compared (OCR splits and joins words freely)."""
    return _NOT_ALPHANUMERIC.sub("", text.lower())


def _names(value: object) -> tuple[str, ...]:
    if value is None:
        return ()
    if isinstance(value, str):
        return (value.lower(),) if value else ()
    return tuple(str(v).lower() for v in value if v)  # type: ignore[attr-defined]


@dataclass(frozen=True)
class Profile:
    """The typical properties of one candidate class (see the module docstring)."""

    class_name: str
    colors: tuple[str, ...] = ()
    shape: str | None = None
    size: str | None = None
    texts: tuple[str, ...] = ()
    ancestors: frozenset[str] = frozenset()

    @classmethod
    def from_mapping(cls, data: Mapping[str, object]) -> Profile:
        """A profile from the planner's plain data; ValueError when it names no class."""
        if not isinstance(data, Mapping):
            raise ValueError(f"a profile must be a mapping, got {type(data).__name__}")
        name = data.get("class")
        if not isinstance(name, str) or not name:
            raise ValueError(f"a profile needs a non-empty 'class', got {data!r}")
        shapes, sizes = _names(data.get("shape")), _names(data.get("size"))
        return cls(
            class_name=name,
            colors=_names(data.get("colors")),
            shape=shapes[0] if shapes else None,
            size=sizes[0] if sizes else None,
            texts=tuple(t for t in (compact(t) for t in _names(data.get("texts"))) if t),
            ancestors=frozenset(_names(data.get("ancestors"))) | {name.lower()},
        )

    def related(self, other: Profile) -> bool:
        """True when one of the two classes subsumes the other."""
        return self.class_name.lower() in other.ancestors or other.class_name.lower() in self.ancestors


@dataclass(frozen=True)
class Cues:
    """The cues the experts gave about one hypothesis (None: not given): the most confident colour, shape and
    size class with their confidences, and the text read on it."""

    color: tuple[str, float] | None = None
    shape: tuple[str, float] | None = None
    size: tuple[str, float] | None = None
    text: str | None = None


@dataclass(frozen=True)
class Match:
    """A profile's score for one hypothesis and how many of its texts were found."""

    profile: Profile
    score: float
    texts_found: int


def _toward_neutral(agreement: float, confidence: float) -> float:
    return 0.5 + (agreement - 0.5) * min(max(confidence, 0.0), 1.0)


def _value_agreement(observed: str, listed: Sequence[str]) -> float:
    return 0.5 if not listed else (1.0 if observed.lower() in listed else 0.0)


def _size_agreement(observed: str, listed: str | None) -> float:
    if listed is None or listed not in SIZE_CLASSES or observed not in SIZE_CLASSES:
        return 0.5
    return (1.0, 0.25, 0.0)[abs(SIZE_CLASSES.index(observed) - SIZE_CLASSES.index(listed))]


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
        total += WEIGHTS["size"] * _toward_neutral(_size_agreement(cues.size[0], profile.size), cues.size[1])
        weight += WEIGHTS["size"]
    if cues.text:
        read = compact(cues.text)
        found = sum(1 for text in profile.texts if text in read)
        agreement = found / len(profile.texts) if profile.texts else TEXT_NONE
        total += WEIGHTS["text"] * agreement
        weight += WEIGHTS["text"]
    return Match(profile, total / weight if weight else 0.0, found)


def choose(matches: Sequence[Match], min_score: float, margin: float) -> Match | None:
    """The clear winner among the matches of one hypothesis, or None (see the module docstring)."""
    if not matches:
        return None
    top = max(m.score for m in matches)
    tied = [m for m in matches if m.score >= top - 1e-9]
    if any(m.texts_found for m in tied):
        best = max(tied, key=lambda m: (m.texts_found, len(m.profile.ancestors)))
    else:
        best = min(tied, key=lambda m: len(m.profile.ancestors))
    if best.score < min_score:
        return None
    rivals = [m.score for m in matches if not m.profile.related(best.profile)]
    if rivals and best.score - max(rivals) < margin:
        return None
    return best


def choose_expected(matches: Sequence[Match], expected: str, min_score: float, margin: float) -> Match | None:
    """When no match is clear: the best match of the expected class (or a subclass of it) if it scores at least
    ``min_score`` and lies within ``margin`` of the best score - the query's class acts as a prior."""
    if not matches:
        return None
    top = max(m.score for m in matches)
    wanted = expected.lower()
    candidates = [m for m in matches if wanted in m.profile.ancestors and m.score >= min_score]
    candidates = [m for m in candidates if top - m.score < margin]
    return max(candidates, key=lambda m: (m.score, -len(m.profile.ancestors)), default=None)


class KnowledgeClassifier(Annotator):
    """Names each hypothesis' class from its colour, shape, size and text, compared with candidate profiles."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis, SemanticColor, Shape, Size)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (Text,)
    outputs: ClassVar[tuple[type[CasType], ...]] = (Classification,)
    capability: ClassVar[Capability] = Capability(
        label="knowledge classifier",
        classes=("PhysicalObject",),
        cost_ms=0.5,
        reliability=0.7,
    )

    def __init__(
        self,
        profiles: Sequence[Mapping[str, object]] = (),
        name: str | None = None,
        min_score: float = 0.6,
        margin: float = 0.1,
        expected: str | None = None,
    ) -> None:
        """``expected`` is the class the query asks for; it decides between near-equal candidates."""
        super().__init__(name=name)
        self.profiles = tuple(Profile.from_mapping(p) for p in profiles)
        self.min_score = min_score
        self.margin = margin
        self.expected = expected

    def cues(self, hypothesis: ObjectHypothesis) -> Cues:
        """The most confident colour, shape, size and the text read on the hypothesis."""
        color = max(self.attached(hypothesis, SemanticColor), key=lambda a: a.confidence, default=None)
        shape = max(self.attached(hypothesis, Shape), key=lambda a: a.confidence, default=None)
        size = max(self.attached(hypothesis, Size), key=lambda a: a.confidence, default=None)
        texts = [t.text for t in self.attached(hypothesis, Text) if t.text.strip()]
        return Cues(
            color=(color.color, color.confidence) if color is not None else None,
            shape=(shape.shape, shape.confidence) if shape is not None else None,
            size=(size.size_class, size.confidence) if size is not None else None,
            text=" ".join(texts) or None,
        )

    def analyse(self) -> None:
        """Attach a Classification to every hypothesis with a clear best profile (unclear ones stay unclassified)."""
        if not self.profiles:
            self.fail("no candidate class profiles to compare the hypotheses with")
        hypotheses = self.annotations(ObjectHypothesis)
        if not hypotheses:
            self.fail("no object hypotheses to classify")
        best_seen: Match | None = None
        classified = 0
        for hypothesis in hypotheses:
            cues = self.cues(hypothesis)
            if cues == Cues():
                continue
            matches = [score(profile, cues) for profile in self.profiles]
            top = max(matches, key=lambda m: m.score)
            if best_seen is None or top.score > best_seen.score:
                best_seen = top
            winner = choose(matches, self.min_score, self.margin)
            confidence = winner.score if winner is not None else GUESS_CONFIDENCE
            if winner is None and self.expected:
                winner = choose_expected(matches, self.expected, self.min_score, self.margin)
            if winner is not None:
                self.attach(hypothesis, Classification(class_name=winner.profile.class_name, confidence=confidence))
                classified += 1
        if classified == 0 and best_seen is None:
            self.fail("no object hypothesis carries a colour, shape, size or text to classify by")
        # hypotheses that match no profile clearly stay unclassified: "none of these is a known class" is an
        # answer, so the tree goes on and the query is answered with the objects that did match (maybe none)
