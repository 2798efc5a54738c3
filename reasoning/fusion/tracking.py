"""Object beliefs and their life cycle across frames: match, update, create, lose confidence, mark gone.

A :class:`BeliefTracker` takes the known beliefs near the camera and one frame's
:class:`~reasoning.fusion.frame.FrameObject` list, associates them (:mod:`reasoning.fusion.association`) and returns
the changed beliefs. It is pure: loading and saving beliefs is the belief store's job.

Per matched belief: the position is filtered (scalar Kalman gain, measurement noise shrinking with the
observation's confidence, process noise growing with the time since the last sighting); size and appearance
are blended; attribute evidence is accumulated with :mod:`reasoning.fusion.rule`; existence log-odds rise. A
sighting that repeats the belief's last view (:mod:`reasoning.fusion.views`) is dependent evidence: its statements
take the stronger of held and stated support, and existence is raised to at least one sighting's ``hit_log_odds``
(the object is still there) without accumulating.
A belief that projects into the image in front of the measured surface but was not matched loses existence
log-odds; once it has been missed and ``gone_after`` seconds have passed since it was last seen, it is gone.
Beliefs of another world (another recording seen without a camera pose) are never matched nor missed. An
observation whose geometry is in doubt (:func:`reasoning.fusion.frame.geometry_doubt`) may confirm a belief but
creates none. A belief's class is the fused class only when evidence supports it (positive log-odds): a class
stated without evidence (e.g. only the query's guess) is kept among the alternatives but names nothing.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import overload

import numpy as np

from reasoning.fusion.association import (
    Association,
    AssociationConfig,
    CameraModel,
    assign_pairs,
    gated_costs,
    same_world,
    visible_from,
)
from reasoning.fusion.frame import WORLD_FRAME, FrameObject
from reasoning.fusion.rule import (
    CLASS_ATTRIBUTE,
    MAX_LOG_ODDS,
    AttributeBelief,
    ClassTest,
    FusedAttribute,
    accumulate,
    accumulate_into,
    logit,
    sigmoid,
)
from reasoning.fusion.views import repeats_view
from robokudo.core.regions import RegionBox, region_of
from robokudo.core.types import Location, SemanticColor

PRESENT = "present"
GONE = "gone"


@dataclass(slots=True)
class ObjectBelief:
    """What is believed about one object; ``existence`` is log-odds, positions are in ``frame``."""

    id: int
    frame: str
    position: np.ndarray
    orientation: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 0.0, 1.0]))
    dimensions: np.ndarray | None = None
    appearance: np.ndarray | None = None
    attributes: dict[str, AttributeBelief] = field(default_factory=dict)
    position_variance: float = 0.0004
    existence: float = 0.0
    status: str = PRESENT
    first_seen: float = 0.0
    last_seen: float = 0.0
    misses: int = 0
    region: str = ""
    region_class: str = ""
    roi: tuple[int, int, int, int] | None = None
    sources: set[str] = field(default_factory=set)
    observations: int = 0
    class_name: str | None = None
    recording: str = ""
    """The recording the belief was first seen in (what its position is relative to without a fixed frame)."""

    @property
    def confidence(self) -> float:
        """Probability that the object exists as believed."""
        return sigmoid(self.existence)

    def fused(self, class_test: ClassTest | None = None) -> dict[str, FusedAttribute]:
        """Every attribute's fused value (subsumption applies to ``class``)."""
        result: dict[str, FusedAttribute] = {}
        for name, belief in self.attributes.items():
            fused = belief.fuse(class_test if name == CLASS_ATTRIBUTE else None)
            if fused is not None:
                result[name] = fused
        return result

    def value(self, attribute: str, class_test: ClassTest | None = None) -> str | None:
        """The fused value of one attribute, or None."""
        belief = self.attributes.get(attribute)
        if belief is not None and len(belief.values) == 1:  # the common case: the only value said is the fused one
            return next(iter(belief.values))
        fused = belief.fuse(class_test if attribute == CLASS_ATTRIBUTE else None) if belief else None
        return fused.value if fused else None


@dataclass(frozen=True, slots=True)
class TrackerConfig:
    """Association gates and life-cycle parameters (seconds, metres, log-odds)."""

    association: AssociationConfig = field(default_factory=AssociationConfig)
    gone_after: float = 10.0
    hit_log_odds: float = logit(0.8)
    miss_log_odds: float = logit(0.75)
    measurement_sigma: float = 0.02
    motion_sigma: float = 0.01
    blend_rate: float = 0.3


class ChangedBeliefs(Sequence[ObjectBelief]):
    """The beliefs a frame changed, in order, each one made when first read: an item is a belief or a function
    making it (a store that updates beliefs on their stored rows makes the objects only for a caller that looks).
    Compares equal to any sequence of the same beliefs (a tuple included)."""

    __slots__ = ("_items",)

    def __init__(self, items: Iterable[ObjectBelief | Callable[[], ObjectBelief]]) -> None:
        self._items = list(items)

    def __len__(self) -> int:
        return len(self._items)

    @overload
    def __getitem__(self, index: int) -> ObjectBelief: ...

    @overload
    def __getitem__(self, index: slice) -> tuple[ObjectBelief, ...]: ...

    def __getitem__(self, index: int | slice) -> ObjectBelief | tuple[ObjectBelief, ...]:
        if isinstance(index, slice):
            return tuple(self[i] for i in range(*index.indices(len(self._items))))
        item = self._items[index]
        if not isinstance(item, ObjectBelief):
            item = self._items[index] = item()
        return item

    def __iter__(self) -> Iterator[ObjectBelief]:
        return (self[i] for i in range(len(self._items)))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Sequence) or isinstance(other, str) or len(other) != len(self):
            return False
        return all(a == b for a, b in zip(self, other, strict=True))

    __hash__ = None  # type: ignore[assignment]  # beliefs are mutable, as in a tuple of them

    def __repr__(self) -> str:
        return f"ChangedBeliefs({list(self)!r})"


@dataclass(frozen=True, slots=True)
class TrackStep:
    """The outcome of one frame: ``assigned[i]`` is the belief id of observation ``i`` (0 when a doubted
    observation matched no belief and was dropped). ``changed`` is a tuple, or :class:`ChangedBeliefs` (made on
    first read) when a store updated beliefs on their rows."""

    changed: Sequence[ObjectBelief]
    assigned: tuple[int, ...]
    created: tuple[int, ...]
    missed: tuple[int, ...]
    gone: tuple[int, ...]
    association: Association


def _same_class(a: str, b: str) -> bool:
    return a == b


def _stated_colors_and_classes(observation: FrameObject) -> tuple[set[str], set[str]]:
    """The colours and the classes stated for an observation (``values`` of both, in one pass)."""
    colors: set[str] = set()
    classes: set[str] = set()
    for e in observation.evidence:
        if e.attribute == SemanticColor.attribute:
            colors.add(e.value)
        elif e.attribute == CLASS_ATTRIBUTE:
            classes.add(e.value)
    return colors, classes


class BeliefTracker:
    """Associates frames of objects with beliefs and updates them (see the module docstring).

    :meth:`step` is one frame. Its parts are public for stores that run the step on their own rows (the belief
    store does): :meth:`associate` pairs observations with beliefs, :meth:`update` applies a matched observation,
    :meth:`create` makes the belief of a new one and :meth:`unseen` applies a frame that did not see a belief."""

    def __init__(
        self,
        config: TrackerConfig | None = None,
        *,
        class_test: ClassTest | None = None,
        regions: Sequence[RegionBox] = (),
    ) -> None:
        self.config = config or TrackerConfig()
        self.class_test = class_test
        self.regions = tuple(regions)

    def step(
        self,
        beliefs: Sequence[ObjectBelief],
        observations: Sequence[FrameObject],
        time: float,
        new_id: Callable[[], int],
        camera: CameraModel | None = None,
    ) -> TrackStep:
        """Integrate one frame; ``beliefs`` are the present beliefs that could be involved (changed in place)."""
        beliefs = [b for b in beliefs if b.status == PRESENT]
        association = self.associate(observations, beliefs)
        changed: dict[int, ObjectBelief] = {}
        assigned = [0] * len(observations)
        for i, j, _ in association.matches:
            belief = beliefs[j]
            self.update(belief, observations[i], time)
            changed[belief.id] = belief
            assigned[i] = belief.id
        created = []
        for i in association.new:
            if observations[i].doubt:
                continue
            belief = self.create(observations[i], time, new_id())
            changed[belief.id] = belief
            assigned[i] = belief.id
            created.append(belief.id)
        missed, gone = [], []
        for j in association.unmatched:
            belief = beliefs[j]
            was_missed, is_gone = self.unseen(belief, time, camera)
            if was_missed:
                missed.append(belief.id)
                changed[belief.id] = belief
            if is_gone:
                gone.append(belief.id)
                changed[belief.id] = belief
        return TrackStep(
            tuple(changed.values()), tuple(assigned), tuple(created), tuple(missed), tuple(gone), association
        )

    def unseen(self, belief: ObjectBelief, time: float, camera: CameraModel | None) -> tuple[bool, bool]:
        """Apply a frame that did not match ``belief`` (changed in place): whether it was missed (in view of
        ``camera`` and of a class its detectors look for: existence lowered) and whether it is now gone (missed and
        not seen for ``gone_after``)."""
        missed = (
            camera is not None
            and (camera.looks_for is None or camera.looks_for(belief.class_name or ""))
            and same_world(belief, camera)
            and visible_from(belief.position, camera)
        )
        if missed:
            belief.existence = max(belief.existence - self.config.miss_log_odds, -MAX_LOG_ODDS)
            belief.misses += 1
        gone = belief.misses > 0 and time - belief.last_seen >= self.config.gone_after
        if gone:
            belief.status = GONE
        return missed, gone

    def associate(self, observations: Sequence[FrameObject], beliefs: Sequence[ObjectBelief]) -> Association:
        """The feasible pairs of the frame with their geometric costs (:func:`gated_costs`, found once), the colour
        and class penalties of :func:`pair_cost` added on them, then one optimal assignment (:func:`assign_pairs`)."""
        config = self.config.association
        pairs = gated_costs(observations, beliefs, config)
        if not pairs.rows.size:
            return assign_pairs(pairs)
        colors: dict[int, str | None] = {}
        stated: dict[int, tuple[set[str], set[str]]] = {}
        test = self.class_test or _same_class
        color_penalty, class_penalty = config.color_penalty, config.class_penalty
        color_added = [0.0] * pairs.rows.size
        class_added = [0.0] * pairs.rows.size
        rows, cols = pairs.rows.tolist(), pairs.cols.tolist()
        for k, (i, j, histograms_compared) in enumerate(zip(rows, cols, pairs.compared.tolist(), strict=True)):
            found = stated.get(i)
            if found is None:
                found = stated[i] = _stated_colors_and_classes(observations[i])
            observation_colors, observation_classes = found
            if observation_colors and not histograms_compared:
                if j in colors:
                    color = colors[j]
                else:
                    color = colors[j] = beliefs[j].value(SemanticColor.attribute)
                if color and color not in observation_colors:
                    color_added[k] = color_penalty
            belief_class = beliefs[j].class_name
            if observation_classes and belief_class:
                for c in observation_classes:
                    if test(c, belief_class) or test(belief_class, c):
                        break
                else:
                    class_added[k] = class_penalty
        # the colour penalty first, then the class penalty, as pair_cost adds them (adding 0.0 changes nothing)
        costs = pairs.costs
        if any(color_added):
            costs = costs + np.array(color_added)
        if any(class_added):
            costs = costs + np.array(class_added)
        return assign_pairs(pairs if costs is pairs.costs else pairs.with_costs(costs))

    def create(self, observation: FrameObject, time: float, belief_id: int) -> ObjectBelief:
        """The new belief ``belief_id`` of an observation no belief matched, first seen at ``time``."""
        belief = ObjectBelief(
            id=belief_id,
            frame=observation.frame,
            position=observation.position.copy(),
            orientation=observation.orientation.copy(),
            dimensions=None if observation.dimensions is None else observation.dimensions.copy(),
            appearance=None if observation.appearance is None else observation.appearance.copy(),
            attributes=accumulate(observation.evidence, time),
            position_variance=self._measurement_variance(observation),
            existence=min(logit(observation.confidence), self.config.hit_log_odds),
            first_seen=time,
            last_seen=time,
            roi=observation.roi,
            sources=set(observation.sources),
            observations=1,
            recording=observation.recording,
        )
        self._refresh(belief)
        return belief

    def update(self, belief: ObjectBelief, observation: FrameObject, time: float) -> None:
        """Apply the observation matched with ``belief`` at ``time`` (changed in place): Kalman step of the position,
        blended size and histogram, accumulated evidence, existence raised."""
        config = self.config
        elapsed = max(time - belief.last_seen, 0.0)
        predicted = belief.position_variance + config.motion_sigma**2 * elapsed
        measured = self._measurement_variance(observation)
        gain = predicted / (predicted + measured)
        belief.position = belief.position + gain * (observation.position - belief.position)
        belief.position_variance = (1.0 - gain) * predicted
        belief.orientation = observation.orientation.copy()
        rate = config.blend_rate
        if observation.dimensions is not None:
            if belief.dimensions is None or belief.dimensions.shape != observation.dimensions.shape:
                belief.dimensions = observation.dimensions.copy()
            else:
                belief.dimensions = (1.0 - rate) * belief.dimensions + rate * observation.dimensions
        if observation.appearance is not None:
            if belief.appearance is None or belief.appearance.shape != observation.appearance.shape:
                belief.appearance = observation.appearance.copy()
            else:
                blended = (1.0 - rate) * belief.appearance + rate * observation.appearance
                belief.appearance = blended / max(float(blended.sum()), 1e-12)
        repeated = repeats_view(
            belief.roi, belief.frame, belief.recording, observation.roi, observation.frame, observation.recording
        )
        accumulate_into(belief.attributes, observation.evidence, time, repeated)
        if repeated:  # still there, but no more certain than one sighting makes it (dependent evidence)
            belief.existence = max(belief.existence, config.hit_log_odds)
        else:
            belief.existence = min(belief.existence + config.hit_log_odds, MAX_LOG_ODDS)
        belief.misses = 0
        belief.status = PRESENT
        belief.last_seen = max(belief.last_seen, time)
        belief.roi = observation.roi
        belief.sources.update(observation.sources)
        belief.observations += 1
        self._refresh(belief)

    # ------------------------------------------------------------------ internals

    def _measurement_variance(self, observation: FrameObject) -> float:
        return self.config.measurement_sigma**2 / max(observation.confidence, 0.1)

    def _refresh(self, belief: ObjectBelief) -> None:
        """Recompute the cached class and the region after a change."""
        known = belief.attributes.get(CLASS_ATTRIBUTE)
        belief.class_name = known.supported_value(self.class_test) if known is not None else None
        region = region_of(belief.position, self.regions) if belief.frame == WORLD_FRAME and self.regions else None
        if region is not None:
            belief.region = region.name
            belief.region_class = str(getattr(region, "region_class", ""))
        else:
            belief.region = belief.value(Location.attribute) or ""
            belief.region_class = ""
