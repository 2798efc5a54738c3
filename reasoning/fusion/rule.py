"""Attribute fusion: what several experts (and several frames) said about one attribute of one object.

Rule (log-odds accumulation over a categorical domain with an implicit "something else" value):

* every statement "attribute = v with confidence c" adds ``logit(c)`` to the own log-odds ``L(v)``
  (``c`` clipped to [0.01, 0.99], the sum clipped to ``±MAX_LOG_ODDS`` so repeated frames of one expert
  cannot make a belief certain);
* a statement from a view that repeats the belief's last one (:mod:`reasoning.fusion.views`) is dependent evidence:
  it moves ``L(v)`` only as far as it goes beyond what is held in its direction, ``max(L, l)`` for a positive
  ``l = logit(c)`` when ``L >= 0`` and ``min(L, l)`` for a negative one when ``L <= 0`` (N identical views say what
  one says; ``l`` sums the repeated view's own statements of ``v``, independent experts); a repeat that contradicts
  the held sign adds ``l`` as a new view does;
* the score of a value also collects the positive own log-odds of its subclasses (class subsumption:
  ``LactoseFreeMilk`` from one expert supports ``Milk`` from another): ``S(v) = L(v) + Σ_{u ⊏ v} max(L(u), 0)``;
* the probability of ``v`` is normalised against the values it conflicts with and "something else":
  ``p(v) = e^S(v) / (e^S(v) + 1 + Σ_w e^S(w))`` over the most general conflicting values ``w``.
  One statement with confidence ``c`` thus gives back exactly ``c``; agreement raises it, conflicts lower it;
* the fused value is the most probable one, refined to its most specific subclass that is itself more likely
  than not; every value is kept with its support (log-odds, count, experts), so conflicts are never dropped;
  it is ``supported`` when its score is positive (a value stated with confidence 0.5 only is no evidence).

The probability that an object answers a query for class ``C`` (:func:`answer_probability`) is the same rule applied
to ``C`` as a value stated by every value the query's class test accepts (``C``, its subclasses, classes packaged in
it): the most general of them (pairwise unrelated) state ``C`` as alternatives, their odds adding up
(``e^S(C) = Σ_m e^S(m)``; ``S(C)`` itself when ``C`` was stated), the ones below them support ``C`` as a subclass
does (``S(m) = L(m) + Σ_u max(L(u), 0)`` over all of them, bounded by ``±MAX_LOG_ODDS``), each value counted once
whatever its paths to ``C``; the rivals are the values that neither answer ``C`` nor are above ``C`` or one of its
answering values.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

from robokudo.core.types import Classification

ClassTest = Callable[[str, str], bool]
"""``class_test(a, b)`` is True when class ``a`` is ``b`` or a subclass of ``b``."""

CONFIDENCE_CLIP: tuple[float, float] = (0.01, 0.99)
"""Confidences are clipped to this range before taking log-odds."""

MAX_LOG_ODDS: float = 6.9
"""Bound of an accumulated log-odds value (about 0.999 probability)."""

CLASS_ATTRIBUTE = Classification.attribute
"""The attribute name of the object class (fused with subsumption)."""


def logit(confidence: float) -> float:
    """Log-odds of a confidence, clipped to :data:`CONFIDENCE_CLIP`."""
    low, high = CONFIDENCE_CLIP
    p = float(confidence)
    # min(max(p, low), high), written out (the same value, NaN included: it passes through both)
    p = low if p < low else p
    p = high if p > high else p
    return math.log(p / (1.0 - p))


def sigmoid(log_odds: float) -> float:
    """Probability of a log-odds value."""
    if log_odds >= 0:
        return 1.0 / (1.0 + math.exp(-log_odds))
    e = math.exp(log_odds)
    return e / (1.0 + e)


def _clamp(log_odds: float) -> float:
    return min(max(log_odds, -MAX_LOG_ODDS), MAX_LOG_ODDS)


@dataclass(frozen=True, slots=True)
class Evidence:
    """One statement of one expert: ``attribute = value`` with ``confidence`` at ``time``."""

    attribute: str
    value: str
    confidence: float
    source: str
    time: float = 0.0


@dataclass(slots=True)
class ValueSupport:
    """The accumulated support of one value of an attribute."""

    log_odds: float = 0.0
    count: int = 0
    sources: set[str] = field(default_factory=set)
    first_seen: float = 0.0
    last_seen: float = 0.0

    def add(self, log_odds: float, sources: Iterable[str], time: float, count: int = 1) -> None:
        """Accumulate ``log_odds`` (clipped) from ``sources``."""
        # min, max and _clamp written out (the hot path of every update; the same values, NaN included)
        if self.count == 0 or time < self.first_seen:
            self.first_seen = time
        total = self.log_odds + log_odds
        total = -MAX_LOG_ODDS if total < -MAX_LOG_ODDS else total
        self.log_odds = MAX_LOG_ODDS if total > MAX_LOG_ODDS else total
        self.count += count
        self.sources.update(sources)
        if self.last_seen < time:
            self.last_seen = time

    def repeat(self, log_odds: float, sources: Iterable[str], time: float, count: int = 1) -> None:
        """Take ``log_odds`` stated (by ``count`` statements) in a view that repeats the last one: dependent
        evidence (:func:`repeated_log_odds`)."""
        if self.count == 0 or time < self.first_seen:
            self.first_seen = time
        self.log_odds = repeated_log_odds(self.log_odds, log_odds)
        self.count += count
        self.sources.update(sources)
        if self.last_seen < time:
            self.last_seen = time


def repeated_log_odds(held: float, stated: float) -> float:
    """The log-odds of a value holding ``held`` after a repeated view states ``stated`` (dependent evidence: the
    stronger of the two in the held direction, the bounded sum when they disagree in sign)."""
    if stated >= 0.0 and held >= 0.0:
        return held if held > stated else stated
    if stated <= 0.0 and held <= 0.0:
        return held if held < stated else stated
    return _clamp(held + stated)


@dataclass(frozen=True, slots=True)
class SupportSummary:
    """One value of a fused attribute with its probability and who said it."""

    value: str
    confidence: float
    log_odds: float
    count: int
    sources: tuple[str, ...]


@dataclass(frozen=True, slots=True)
class FusedAttribute:
    """The fused value of an attribute, its confidence, its experts, and the support of every value seen.

    ``sources`` are the experts that agree with the fused value (they said it, a subclass or a superclass);
    ``conflict`` is True when a value incompatible with the fused one has support of its own; ``supported`` is
    False when nothing but zero-evidence statements (confidence 0.5 or less) back the fused value.
    """

    name: str
    value: str
    confidence: float
    sources: tuple[str, ...]
    support: tuple[SupportSummary, ...]
    conflict: bool
    supported: bool = True

    def confidence_of(self, value: str) -> float:
        """The probability of ``value`` (0 when nobody said it)."""
        for item in self.support:
            if item.value == value:
                return item.confidence
        return 0.0


@dataclass(slots=True)
class AttributeBelief:
    """All values ever stated for one attribute of one object, with their support."""

    name: str
    values: dict[str, ValueSupport] = field(default_factory=dict)

    def add(self, evidence: Evidence, time: float | None = None) -> None:
        """Accumulate one statement (at ``time`` when given, else at the statement's own time)."""
        support = self.values.get(evidence.value)
        if support is None:
            support = self.values[evidence.value] = ValueSupport()
        support.add(logit(evidence.confidence), (evidence.source,), evidence.time if time is None else time)

    def merge(self, other: AttributeBelief) -> None:
        """Accumulate everything ``other`` holds (e.g. one frame's statements into a stored belief)."""
        for value, theirs in other.values.items():
            mine = self.values.get(value)
            if mine is None:
                mine = self.values[value] = ValueSupport()
            mine.add(theirs.log_odds, theirs.sources, theirs.first_seen, theirs.count)
            mine.last_seen = max(mine.last_seen, theirs.last_seen)

    def supported_value(self, class_test: ClassTest | None = None) -> str | None:
        """The fused value when evidence supports it (``fuse(...).supported``), else None."""
        if len(self.values) == 1:  # the fast path of fuse_values, without building the summary
            ((only, support),) = self.values.items()
            return only if support.log_odds > 0 else None
        fused = self.fuse(class_test)
        return fused.value if fused is not None and fused.supported else None

    def fuse(self, class_test: ClassTest | None = None) -> FusedAttribute | None:
        """The fused value (see the module docstring); None when nothing was said."""
        if not self.values:
            return None
        return fuse_values(self.name, self.values, class_test)


def fuse_values(name: str, values: Mapping[str, ValueSupport], class_test: ClassTest | None = None) -> FusedAttribute:
    """Fuse the supports of the values of one attribute; ``class_test`` enables subsumption."""
    if len(values) == 1:  # the common case: everybody agreed so far
        ((only, support),) = values.items()
        p = sigmoid(support.log_odds)
        experts = tuple(sorted(support.sources))
        return FusedAttribute(
            name,
            only,
            p,
            experts,
            (SupportSummary(only, p, support.log_odds, support.count, experts),),
            False,
            support.log_odds > 0,
        )
    names = list(values)

    def below(a: str, b: str) -> bool:  # a is a strict subclass of b
        return class_test is not None and a != b and class_test(a, b)

    sub = {v: [u for u in names if below(u, v)] for v in names} if class_test else {v: [] for v in names}
    score = {v: _clamp(values[v].log_odds + sum(max(values[u].log_odds, 0.0) for u in sub[v])) for v in names}

    def compatible(a: str, b: str) -> bool:
        return a == b or below(a, b) or below(b, a)

    probability: dict[str, float] = {}
    for v in names:
        rivals = [w for w in names if not compatible(v, w)]
        general = [w for w in rivals if not any(below(w, x) for x in rivals)]
        top = max([score[v], 0.0, *(score[w] for w in general)])
        denominator = math.exp(score[v] - top) + math.exp(-top) + sum(math.exp(score[w] - top) for w in general)
        probability[v] = math.exp(score[v] - top) / denominator

    def specificity(v: str) -> int:
        return sum(1 for u in names if below(v, u))

    best = max(names, key=lambda v: (probability[v], specificity(v), values[v].count, v))
    refined = [u for u in sub[best] if probability[u] > 0.5]
    if refined:
        best = max(refined, key=lambda u: (specificity(u), probability[u], u))
    supporters = set(values[best].sources)
    for u in names:
        if u != best and compatible(u, best) and values[u].log_odds > 0:
            supporters.update(values[u].sources)
    conflict = any(not compatible(best, w) and values[w].log_odds > 0 for w in names)
    summary = tuple(
        sorted(
            (
                SupportSummary(v, probability[v], values[v].log_odds, values[v].count, tuple(sorted(values[v].sources)))
                for v in names
            ),
            key=lambda s: (-s.confidence, s.value),
        )
    )
    return FusedAttribute(name, best, probability[best], tuple(sorted(supporters)), summary, conflict, score[best] > 0)


def answer_probability(values: Mapping[str, ValueSupport], asked: str, class_test: ClassTest | None = None) -> float:
    """The fused probability that an object whose class attribute holds ``values`` answers a query for ``asked``:
    the mass of the class distribution on the values ``class_test(value, asked)`` accepts, each counted once (see
    the module docstring); without a test, values named ``asked`` (case ignored). 0 when none of them was stated;
    equal to ``fuse_values(...).confidence_of(asked)`` when ``asked`` was stated and the test is a taxonomy's."""
    accepts = class_test or (lambda a, b: a.lower() == b.lower())
    members = [v for v in values if v == asked or accepts(v, asked)]
    if not members:
        return 0.0

    def below(a: str, b: str) -> bool:  # a is a strict subclass of b
        return class_test is not None and a != b and class_test(a, b)

    general = [m for m in members if not any(below(m, n) for n in members)]
    support = sum(max(values[u].log_odds, 0.0) for u in members if u not in general)
    terms = [_clamp(values[m].log_odds + support) for m in general]  # bounded as a value's score is

    def related(w: str) -> bool:  # w answers, is above the asked class or above one of its answering values
        return w in members or below(asked, w) or any(below(m, w) for m in members)

    rivals = [w for w in values if not related(w)]
    rivals = [w for w in rivals if not any(below(w, x) for x in rivals)]
    rival_scores = [
        _clamp(values[w].log_odds + sum(max(values[u].log_odds, 0.0) for u in values if below(u, w))) for w in rivals
    ]
    top = max([*terms, 0.0, *rival_scores])
    mass = sum(math.exp(t - top) for t in terms)
    return mass / (mass + math.exp(-top) + sum(math.exp(s - top) for s in rival_scores))


def fuse_evidence(evidence: Iterable[Evidence], class_test: ClassTest | None = None) -> dict[str, FusedAttribute]:
    """Fuse statements about one object, attribute by attribute (subsumption applies to ``class``)."""
    beliefs = accumulate(evidence)
    fused: dict[str, FusedAttribute] = {}
    for name, belief in beliefs.items():
        result = belief.fuse(class_test if name == CLASS_ATTRIBUTE else None)
        if result is not None:
            fused[name] = result
    return fused


def accumulate(evidence: Iterable[Evidence], time: float | None = None) -> dict[str, AttributeBelief]:
    """Group statements by attribute and accumulate their support (stamped with ``time`` when given)."""
    beliefs: dict[str, AttributeBelief] = {}
    accumulate_into(beliefs, evidence, time)
    return beliefs


def accumulate_into(
    beliefs: dict[str, AttributeBelief],
    evidence: Iterable[Evidence],
    time: float | None = None,
    repeated: bool = False,
) -> None:
    """Accumulate statements into ``beliefs`` (by attribute, created when missing), stamped with ``time`` when given
    (e.g. one frame's statements straight into a stored belief's attributes); ``repeated`` when they come from a view
    that repeats the belief's last one (dependent evidence, :meth:`ValueSupport.repeat`)."""
    if repeated:
        said: dict[tuple[str, str], tuple[float, list[str], float]] = {}
        for item in evidence:  # the view's own statements add up (independent experts), as in any frame
            key = (item.attribute, item.value)
            held = said.get(key)
            stamp = item.time if time is None else time
            if held is None:
                said[key] = (logit(item.confidence), [item.source], stamp)
            else:
                held[1].append(item.source)
                said[key] = (held[0] + logit(item.confidence), held[1], max(held[2], stamp))
        for (name, value), (log_odds, sources, stamp) in said.items():
            belief = beliefs.get(name)
            if belief is None:
                belief = beliefs[name] = AttributeBelief(name)
            support = belief.values.get(value)
            if support is None:
                support = belief.values[value] = ValueSupport()
            support.repeat(_clamp(log_odds), sources, stamp, len(sources))
        return
    for item in evidence:  # AttributeBelief.add of each statement, written out (the hot path of every update)
        belief = beliefs.get(item.attribute)
        if belief is None:
            belief = beliefs[item.attribute] = AttributeBelief(item.attribute)
        values = belief.values
        support = values.get(item.value)
        if support is None:
            support = values[item.value] = ValueSupport()
        support.add(logit(item.confidence), (item.source,), item.time if time is None else time)
