"""Plan synthesis: from required annotation types to a staged, minimal set of experts.

The algorithm, polynomial in annotators x types:

1. *Candidates*: the knowledge base ranks the providers of a type - annotators whose outputs include it,
   whose value domain covers the requested value under class subsumption and whose preconditions hold.
   An annotator that reads and writes a type (a crop filter) refines it rather than providing it.
2. *Feasibility* by a forward fixpoint from the sensor types (what some chain of providers can produce).
   A provider is a valid choice for a type when its inputs can be produced without that type, so choices
   never depend on themselves. A type with no valid provider is an error naming what was missing and why.
3. *Assignment*, breadth first from the requirements back to the sensors: each needed type gets one unit
   - its single valid provider, or all of them as Alternatives (a Fallback, in rank order) - and each
   annotator belongs to at most one unit. A type that an already planned unit guarantees needs no unit.
   When some types need each other (a cycle among the providers' rules, as on large ontologies) the greedy choice
   of all alternatives can paint itself into a cycle: there every type takes only the providers whose inputs are
   derived in the earliest fixpoint round (always acyclic, fewer alternatives), as it does when the greedy choice
   fails. An input that lost its unit while units were re-chosen is planned again (or its alternative dropped).
4. *Pruning and cycle breaking*: units nothing needs are dropped; an alternative whose inputs would close a
   dependency cycle is dropped from its Fallback.
5. *Refinements* of planned types run after the type's unit and before its readers: every refiner whose
   preconditions hold and that has some (a region filter when a region is named), plus the cheapest
   general-purpose one (a crop).
6. *Grouping*: inputs that only one alternative needs move into that alternative's branch, so a failing
   branch hands over to the next; units are staged by dependency depth (a stage's units are independent).
"""

from __future__ import annotations

from bisect import insort
from collections import deque
from collections.abc import Iterable, Mapping, Sequence
from collections.abc import Set as AbstractSet
from dataclasses import dataclass

from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.model import AnnotatorSpec, Conditions, Kind
from reasoning.planning.plan import Alternatives, Plan, Step, Task, Unit

NEEDED_BY = "needed by "  # a reason naming the provider that reads a type


class PlanningError(Exception):
    """No tree can satisfy the query; the message says which requirement failed and why."""


class _OrderingError(PlanningError):
    """The chosen alternatives cannot be ordered without a cycle (the planner then chooses more strictly)."""


@dataclass(frozen=True)
class Requirement:
    """A type the answer needs, the value asked for and why."""

    annotation_type: str
    value: str | None = None
    reason: str = ""


@dataclass(frozen=True)
class SensorSource:
    """The reader that starts every plan, the types it supplies and whether its frames carry the camera pose.

    Regions of the semantic map can be applied only with the camera pose (to place the points in the map frame).
    """

    step: Step
    camera_pose: bool = True

    @property
    def types(self) -> frozenset[str]:
        """The types the reader writes."""
        return frozenset(self.step.outputs)


def plan_requirements(
    task: Task,
    requirements: Sequence[Requirement],
    index: KnowledgeBase,
    source: SensorSource,
    conditions: Conditions | None = None,
    parameters: Mapping[str, Mapping[str, object]] | None = None,
    catalogs: dict[tuple[object, ...], object] | None = None,
) -> Plan:
    """Synthesize the staged plan that produces every requirement from the sensor source.

    ``conditions`` say whether depth and a region are available; ``parameters`` are constructor arguments
    per annotator name (e.g. the region box for a region filter). ``catalogs`` is a cache of the
    requirement-independent work (providers, fixpoints) that callers planning many queries against one
    ontology keep; it is keyed by object class, conditions and sensor types.
    """
    conditions = conditions or Conditions()
    key = (task.object_class, conditions, source.types)
    catalog = catalogs.get(key) if catalogs is not None else None
    if not isinstance(catalog, _Catalog):
        catalog = _Catalog(index, source.types, task.object_class, conditions)
        if catalogs is not None:
            catalogs[key] = catalog
    # providers whose inputs are derived in earlier fixpoint rounds are always acyclic (fewer alternatives): the
    # strict choice, made at once when some types need each other (there the greedy choice of all alternatives can
    # paint itself into a cycle, and on large ontologies it nearly always does)
    strict = catalog.cyclic()
    try:
        assignment = _Assignment(catalog, requirements, by_rounds=strict)
    except _OrderingError:
        if strict:
            raise
        assignment = _Assignment(catalog, requirements, by_rounds=True)
    layout = _Layout(catalog, assignment, source, dict(parameters or {}))
    return Plan(task=task, stages=layout.stages(), sensor_types=source.types)


class _Catalog:
    """Candidate providers (memoised per type and value) and what can be produced from the sensors.

    Type sets of the fixpoints are bit masks over the ontology's CAS types (``OntologyIndex.type_bits``): each
    usable provider is one rule, its inputs -> the types it provides; a fixpoint makes a type known once a rule
    providing it has all its inputs known. Nothing here is kept between plans: a catalog is built per plan (unless
    the caller keeps catalogs), from the index's per-annotator masks and one pass over the annotators.
    """

    def __init__(
        self, index: KnowledgeBase, sensors: frozenset[str], object_class: str | None, conditions: Conditions
    ) -> None:
        self.index = index
        self.ontology = index.index
        self._supertypes: dict[str, frozenset[str]] = {}
        self._written: dict[str, frozenset[str]] = {}
        # a type is present when it or a subtype of it is: track each written type together with its supertypes
        self.sensors = self.with_supertypes(sensors)
        self.object_class = object_class
        self.conditions = conditions
        self._providers: dict[tuple[str, str | None], tuple[AnnotatorSpec, ...]] = {}
        self._refiners: dict[str, list[AnnotatorSpec]] = {}
        self._without: dict[int, int] = {}
        self._input_rounds: dict[str, int] = {}
        self._grouped: dict[
            tuple[str, str | None], tuple[int, int, tuple[AnnotatorSpec, ...], tuple[AnnotatorSpec, ...]] | None
        ] = {}
        self._known_by_round: list[int] = []
        self._fired_round: dict[int, int] = {}  # inputs mask of a rule -> the fixpoint round in which it fires
        self._excluded, self._own_types_only = index.provider_exclusions(object_class, conditions)
        excluded, own_types_only = self._excluded, self._own_types_only
        rules: dict[int, int] = {}  # the usable providers' rules, merged per inputs: inputs -> what they provide
        # annotators without inputs (sensor readers) are not in ``rule_ports``, whose masks of what a provider makes
        # leave out what it reads (a refiner)
        for name, inputs, outputs, provided in self.ontology.rule_ports:
            if name in excluded:
                continue
            if name in own_types_only:
                provided = outputs
            if provided:
                rules[inputs] = rules.get(inputs, 0) | provided
        self._sensor_mask = self.ontology.mask(self.sensors)
        self.rounds, self._rules = self._rounds(rules)
        self.producible = frozenset(self.rounds)
        # forbidding a sensor type or one nothing produces changes no fixpoint: such types are left out of the key
        self._forbiddable = self._known_by_round[-1] & ~self._sensor_mask  # the producible types by bit

    def _rounds(self, rules: dict[int, int]) -> tuple[dict[str, int], list[tuple[int, int]]]:
        """The fixpoint round in which each producible type first becomes producible (sensors: 0), and the
        ``rules`` (merged per inputs) that can fire at all, in the order they fire (later fixpoints, which forbid
        types, fire a subset of them)."""
        rounds = dict.fromkeys(self.sensors, 0)
        known = self._sensor_mask
        pending = list(rules.items())
        fired: list[tuple[int, int]] = []
        names = self.ontology.bit_types
        self._known_by_round = [known]  # what is producible after each round
        self._fired_before = [0]  # per round: how many rules fired in earlier rounds (their place in ``fired``)
        fired_round = self._fired_round
        current = 0
        while True:
            current += 1
            self._fired_before.append(len(fired))
            new = 0
            waiting = []
            for rule in pending:
                inputs = rule[0]
                if inputs & known == inputs:
                    new |= rule[1]
                    fired.append(rule)
                    fired_round[inputs] = current
                else:
                    waiting.append(rule)
            new &= ~known
            if not new:
                return rounds, fired
            while new:
                bit = new & -new
                rounds[names[bit.bit_length() - 1]] = current
                known |= bit
                new ^= bit
            self._known_by_round.append(known)
            pending = waiting

    def with_supertypes(self, types: Iterable[str]) -> frozenset[str]:
        """The types and all their supertypes."""
        found: set[str] = set()
        for type_name in types:
            known = self._supertypes.get(type_name)
            if known is None:
                # the index holds each class with its superclasses; anything else is resolved (or rejected) by name
                known = self.ontology.up.get(type_name) or frozenset({type_name, *self.index.superclasses(type_name)})
                self._supertypes[type_name] = known
            found |= known
        return frozenset(found)

    def input_round(self, spec: AnnotatorSpec) -> int:
        """The latest fixpoint round among the inputs of ``spec`` (0 without inputs)."""
        found = self._input_rounds.get(spec.name)
        if found is None:
            # a rule fires in the round after its latest input became producible
            fired = self._fired_round.get(self.ontology.port_masks[spec.name][0]) if spec.inputs else None
            if fired is None:
                rounds = self.rounds
                found = max((rounds.get(t, 0) for t in spec.inputs), default=0)
            else:
                found = fired - 1
            self._input_rounds[spec.name] = found
        return found

    def written(self, spec: AnnotatorSpec) -> frozenset[str]:
        """What an annotator makes present for others: its outputs and their supertypes, minus what it reads."""
        found = self.ontology.written_types.get(spec.name) or self._written.get(spec.name)
        if found is None:
            found = self._written[spec.name] = self.with_supertypes(spec.outputs) - self.with_supertypes(spec.inputs)
        return found

    def _admitted(self, type_name: str) -> list[AnnotatorSpec]:
        """``index.providers(type_name)`` for this catalog's object class and conditions (no value asked)."""
        if type_name not in self.ontology.cas_types:
            return self.index.providers(type_name, None, self.object_class, self.conditions)  # says what is wrong
        excluded, own_types_only = self._excluded, self._own_types_only
        return [
            s
            for s in self.ontology.providers[type_name]
            if s.name not in excluded and (s.name not in own_types_only or type_name in s.outputs)
        ]

    def providers(self, type_name: str, value: str | None = None) -> tuple[AnnotatorSpec, ...]:
        """Ranked providers of ``type_name`` for ``value`` (refiners of the type excluded)."""
        key = (type_name, value)
        found = self._providers.get(key)
        if found is None:
            makers = self.ontology.makers.get(type_name)
            if value is None and makers is not None:
                excluded, own_types_only = self._excluded, self._own_types_only
                found = tuple(
                    s
                    for s in makers
                    if s.name not in excluded and (s.name not in own_types_only or type_name in s.outputs)
                )
            else:
                # ``index.providers(type_name, value, ...)`` for this catalog's object class and conditions
                admitted = self._admitted(type_name)
                if value is not None:
                    admitted = self.index.serving_value(type_name, value, admitted)
                # annotators without inputs are sensor readers: the plan's source is chosen by its input, not here
                found = tuple(s for s in admitted if s.inputs and type_name not in s.inputs)
            self._providers[key] = found
        return found

    def refiners(self, type_name: str) -> list[AnnotatorSpec]:
        """Annotators that read and write ``type_name`` and whose preconditions hold, cheapest first."""
        found = self._refiners.get(type_name)
        if found is None:
            candidates = self.ontology.refiners.get(type_name)
            if candidates is None or type_name not in self.ontology.cas_types:
                found = sorted(
                    (s for s in self._admitted(type_name) if type_name in s.inputs), key=lambda s: (s.cost_ms, s.name)
                )
            else:
                excluded, own_types_only = self._excluded, self._own_types_only
                found = [
                    s
                    for s in candidates
                    if s.name not in excluded and (s.name not in own_types_only or type_name in s.outputs)
                ]
            self._refiners[type_name] = found
        return found

    def _start_round(self, forbidden: int) -> int:
        """The last fixpoint round before the first in which a ``forbidden`` type is made: what was made by then
        is producible without the forbidden types."""
        start = 0
        for made in self._known_by_round[1:]:
            if made & forbidden:
                break
            start += 1
        return start

    def _fixpoint(self, forbidden: int) -> int:
        """Make the types a rule provides known (unless forbidden) once all its inputs are, until none becomes so.

        It starts from every type made in a round before the first forbidden type is: each of them was first made
        from types of earlier rounds, none of them forbidden.
        """
        start = self._start_round(forbidden)
        known = self._known_by_round[start]
        # a rule that fired by round ``start`` provides only types already known
        allowed = ~forbidden
        missing = allowed & ~known
        pending = [rule for rule in self._rules[self._fired_before[start + 1] :] if rule[1] & missing]
        while True:
            before = known
            waiting = []
            for rule in pending:
                if rule[0] & known == rule[0]:
                    known |= rule[1] & allowed
                else:
                    waiting.append(rule)
            if known == before:  # the waiting rules wait for types that nothing made in this pass
                return known
            pending = waiting

    def cyclic(self) -> bool:
        """Whether some producible types need each other (a provider of one reads the other, transitively).

        Types are peeled off once every rule providing them reads only sensor types and types already peeled off;
        what is left when nothing more can be peeled lies on or behind a cycle.
        """
        done = self._sensor_mask
        pending = self._rules
        while True:
            blocked = ready = 0
            left = ~done
            rest = []  # the rules that still provide types not peeled off, with only those
            for inputs, provided in pending:
                provided &= left
                if not provided:
                    continue
                rest.append((inputs, provided))
                if inputs & done == inputs:
                    ready |= provided
                else:
                    blocked |= provided
            if not rest:
                return False
            ready &= ~blocked
            if not ready:
                return True
            done |= ready
            pending = rest

    def producible_without(self, forbidden: AbstractSet[str]) -> int:
        """What can be produced when the ``forbidden`` types may not be used, as a mask of types."""
        key = self.ontology.mask(forbidden) & self._forbiddable
        found = self._without.get(key)
        if found is None:
            found = self._without[key] = self._fixpoint(key)
        return found

    def valid(
        self, type_name: str, value: str | None, above: AbstractSet[str] = frozenset(), by_rounds: bool = False
    ) -> list[AnnotatorSpec]:
        """Providers of ``type_name`` whose inputs can be produced without it and without the types ``above`` it
        (those that need it), so that choosing them cannot create a cycle; ``by_rounds`` keeps only those whose
        inputs are derived earliest."""
        providers = self.providers(type_name, value)
        if not providers:
            return []
        masks = self.ontology.port_masks
        # what was made before the first round making a forbidden type is producible without them: providers
        # reading only that are usable without the fixpoint, which is needed only when others could be chosen too
        forbidden = self.ontology.mask(above) | self.ontology.type_bits.get(type_name, 0)
        start = self._start_round(forbidden & self._forbiddable)
        grouped = self._input_rounds_of(type_name, value, providers)
        if grouped is not None:
            # every provider's rule fires: it reads only what was made by ``start`` when it fires by ``start + 1``
            earliest, latest, first, candidates = grouped
            if by_rounds and earliest <= start:
                return list(first)
            if not by_rounds and latest <= start:
                return list(candidates)
        surely = self._known_by_round[start]
        sure: list[AnnotatorSpec] = []
        others: list[AnnotatorSpec] = []
        for spec in providers:
            inputs = masks[spec.name][0]
            (sure if inputs & surely == inputs else others).append(spec)
        if by_rounds and sure:
            rounds = [self.input_round(s) for s in sure]
            limit = min(rounds)
            # the others fire after that round (when their rule fires at all): the strict choice drops them whether
            # usable or not
            fired = self._fired_round
            if all(masks[s.name][0] in fired or self.input_round(s) > limit for s in others):
                return [s for s, r in zip(sure, rounds, strict=True) if r == limit]
        elif not others:
            return sure
        usable = self.producible_without(above | {type_name})
        found = [s for s in providers if masks[s.name][0] & usable == masks[s.name][0]]
        if by_rounds and found:
            rounds = [self.input_round(s) for s in found]
            limit = min(rounds)
            found = [s for s, r in zip(found, rounds, strict=True) if r <= limit]
        return found

    def has_valid(self, type_name: str, value: str | None) -> bool:
        """Whether :meth:`valid` finds some provider of ``type_name`` for ``value`` (nothing forbidden above it)."""
        providers = self.providers(type_name, value)
        if not providers:
            return False
        grouped = self._input_rounds_of(type_name, value, providers)
        start = self._start_round(self.ontology.type_bits.get(type_name, 0) & self._forbiddable)
        # a provider whose rule fires by ``start + 1`` reads only what was made without the type
        return (grouped is not None and grouped[0] <= start) or bool(self.valid(type_name, value))

    def _input_rounds_of(
        self, type_name: str, value: str | None, providers: tuple[AnnotatorSpec, ...]
    ) -> tuple[int, int, tuple[AnnotatorSpec, ...], tuple[AnnotatorSpec, ...]] | None:
        """Of the ``providers`` of ``type_name`` for ``value`` that read only producible types (no others are ever
        valid): the earliest and latest input round, those with the earliest and all of them (memoised); None when
        there are none or the rule of one of them never fires."""
        key = (type_name, value)
        if key in self._grouped:
            return self._grouped[key]
        masks, fired = self.ontology.port_masks, self._fired_round
        producible = self._known_by_round[-1]
        found: tuple[int, int, tuple[AnnotatorSpec, ...], tuple[AnnotatorSpec, ...]] | None = None
        chosen: list[AnnotatorSpec] = []
        first: list[AnnotatorSpec] = []  # those whose rule fires earliest
        # a provider's input round is the one before its rule fires (:meth:`input_round`)
        earliest = latest = 0
        for spec in providers:
            inputs = masks[spec.name][0]
            fires = fired.get(inputs)
            if fires is not None:
                if not chosen or fires < earliest:
                    earliest, first = fires, [spec]
                elif fires == earliest:
                    first.append(spec)
                if fires > latest:
                    latest = fires
                chosen.append(spec)
            elif inputs & producible == inputs:  # reads only producible types, yet its rule never fires
                chosen = []
                break
        if chosen:
            found = (earliest - 1, latest - 1, tuple(first), tuple(chosen))
        self._grouped[key] = found
        return found

    def why_not(self, type_name: str, value: str | None) -> str:
        """Why no provider of ``type_name`` is usable, naming each excluded annotator."""
        asked = f"{type_name} with value {value!r}" if value else type_name
        usable = {s.name for s in self.providers(type_name, value)}
        details = [
            f"{s.name} {_exclusion(s, self.index.value_kind(type_name), value, self.object_class, self.conditions)}"
            for s in self.index.providers(type_name)
            if s.name not in usable and type_name not in s.inputs
        ]
        producible = self.producible_without(frozenset({type_name}))
        for spec in self.providers(type_name, value):
            bits = self.ontology.type_bits
            missing = sorted(t for t in set(spec.inputs) if not bits[t] & producible)
            details.append(f"{spec.name} needs {', '.join(missing)}, which cannot be produced")
        if not details:
            return f"no annotator in the ontology provides {asked}"
        return f"no usable annotator provides {asked} ({'; '.join(details)})"


class _UnitChoice:
    """The providers chosen for one needed type (one unit of the plan)."""

    def __init__(self, type_name: str, providers: list[AnnotatorSpec], value: str | None, catalog: _Catalog) -> None:
        self.type_name = type_name
        self.value = value
        self._written = catalog.written
        self._written_types = catalog.ontology.written_types
        self._input_round = catalog.input_round
        self.choose(providers)

    def choose(self, providers: list[AnnotatorSpec]) -> None:
        """Make ``providers`` (best first) the unit's alternatives."""
        self.providers = providers
        known = self._written_types
        if len(providers) == 1:
            self._guaranteed = known.get(providers[0].name) or self._written(providers[0])
        else:
            self._guaranteed = frozenset.intersection(*[known.get(s.name) or self._written(s) for s in providers])
        # the types some alternative reads
        self.read: frozenset[str] | tuple[str, ...] = (
            frozenset().union(*[s.inputs for s in providers]) if len(providers) > 1 else providers[0].inputs
        )
        self._latest_round: int | None = None

    @property
    def latest_round(self) -> int:
        """The latest fixpoint round among the inputs of any provider."""
        if self._latest_round is None:
            self._latest_round = max(map(self._input_round, self.providers))
        return self._latest_round

    def guaranteed(self) -> frozenset[str]:
        """Types the unit produces for others: outputs every provider writes without having read them."""
        return self._guaranteed


class _Assignment:
    """Which unit provides each needed type, with each annotator in at most one unit and no cycles.

    Units are keyed by the type they were made for. ``above[T]`` holds the types whose units (transitively)
    need unit T; a provider for T may not need any of them, which keeps the unit graph acyclic.
    """

    def __init__(self, catalog: _Catalog, requirements: Sequence[Requirement], by_rounds: bool) -> None:
        self.catalog = catalog
        self.by_rounds = by_rounds
        self.requirements = requirements
        self.values = {r.annotation_type: r.value for r in requirements}
        self.reasons: dict[str, list[str]] = {}  # type -> why it is needed, other than by a provider
        self.consumers: dict[str, list[str]] = {}  # type -> the chosen providers that read it, in planning order
        for requirement in requirements:
            self._note(requirement.annotation_type, requirement.reason)
        self.units: dict[str, _UnitChoice] = {}
        self.above: dict[str, set[str]] = {}
        self._guaranteed: dict[str, str] | None = None
        self._by_order: dict[str, str] | None = None  # the type -> unit mapping by unit order alone, when current
        self._last_guaranteed: dict[str, str] | None = None
        self._owner: dict[str, str] | None = None
        self._owners: dict[str, str] = {}  # annotator name -> its unit, kept as the units change
        self._version = 0  # counts changes of the units
        self._clean_below: dict[str, set[str]] = {}  # unit -> the units below it, while they are unchanged
        self._inputs_for: dict[str, str] | None = None
        self._input_units_of: dict[str, tuple[str, ...]] = {}
        self.pinned: dict[str, str] = {}  # type -> unit chosen for it when several units write it
        self._order: list[tuple[int, str]] = []  # (fixpoint round, type) of each unit, sorted
        self._check_feasible()
        self._assign(deque((r.annotation_type, None) for r in self.requirements))
        self._complete()
        self._prune()

    def _note(self, type_name: str, reason: str) -> None:
        if reason.startswith(NEEDED_BY):
            self._note_consumer(type_name, reason.removeprefix(NEEDED_BY))
            return
        reasons = self.reasons.setdefault(type_name, [])
        if reason and reason not in reasons:
            reasons.append(reason)

    def _note_consumer(self, type_name: str, annotator: str) -> None:
        noted = self.consumers.get(type_name)
        if noted is None:
            self.consumers[type_name] = [annotator]
        elif annotator not in noted:
            noted.append(annotator)

    def _check_feasible(self) -> None:
        for requirement in self.requirements:
            type_name, value = requirement.annotation_type, requirement.value
            if type_name in self.catalog.sensors:
                continue
            if type_name not in self.catalog.producible or not self.catalog.has_valid(type_name, value):
                raise PlanningError(
                    f"cannot satisfy '{requirement.reason or type_name}': {self.catalog.why_not(type_name, value)}"
                )

    def owner(self) -> dict[str, str]:
        """Annotator name -> the type of the unit it belongs to, as the units are now (read only; a later change of the
        units leaves it as it was)."""
        if self._owner is None:
            self._owner = dict(self._owners)
        return self._owner

    def _invalidate(self) -> None:
        self._version += 1
        self._by_order = None
        self._clean_below = {}
        self._guaranteed = None
        self._owner = None

    def _set_providers(self, key: str, providers: list[AnnotatorSpec]) -> None:
        owners = self._owners
        for spec in self.units[key].providers:
            del owners[spec.name]
        self.units[key].choose(providers)
        owners.update(dict.fromkeys((spec.name for spec in providers), key))
        self._invalidate()

    def guaranteed_by(self) -> dict[str, str]:
        """Type -> the unit (by its type) that guarantees it (cached until the units change)."""
        if self._guaranteed is None:
            found = self._compute_guaranteed()
            previous = self._last_guaranteed
            # the same mapping as before (most changes of providers keep it) is the same object, so that what was
            # derived from it stays valid
            same = previous is not None and found == previous  # read by key or sorted: the order is no matter
            self._guaranteed = self._last_guaranteed = previous if same else found
        return self._guaranteed

    def _compute_guaranteed(self) -> dict[str, str]:
        found: dict[str, str] = {}
        rounds = self.catalog.rounds
        # by-products come from the unit derived earliest, the one least likely to depend on their readers
        by_rounds = self.by_rounds
        units = self.units
        for _, key in self._order:
            unit = units[key]
            latest = unit.latest_round if by_rounds else 0
            for type_name in unit.guaranteed():  # (each type on its own: the order is no matter)
                if type_name in found:
                    continue
                if by_rounds and latest >= rounds.get(type_name, 0):
                    continue  # a by-product made from later types could close a cycle in the strict mode
                found[type_name] = key
        self._by_order = found
        return self._overridden(found)

    def _add_guaranteed(self, key: str) -> None:
        """Update the type -> unit mapping for the new unit ``key`` (when the mapping by unit order is known): the
        types it guarantees that no unit earlier in the order does are now its."""
        by_order = self._by_order
        previous = self._guaranteed  # the mapping from ``by_order`` (while that is known)
        self._invalidate()
        if by_order is None or previous is None:
            return
        rounds = self.catalog.rounds
        unit = self.units[key]
        by_rounds = self.by_rounds
        latest = unit.latest_round if by_rounds else 0
        place = (rounds.get(key, 0), key)
        taken = []  # the types that map to the new unit by unit order now
        for type_name in unit.guaranteed():  # (each type on its own: the order is no matter)
            if by_rounds and latest >= rounds.get(type_name, 0):
                continue
            present = by_order.get(type_name)
            if present is None or (rounds.get(present, 0), present) > place:
                by_order[type_name] = key
                taken.append(type_name)
        self._by_order = by_order
        # the new unit's own type maps to it now (it did not before): the mapping changed
        self._guaranteed = self._last_guaranteed = self._with_unit(previous, key, taken)

    def _with_unit(self, previous: dict[str, str], key: str, taken: list[str]) -> dict[str, str]:
        """:meth:`_overridden` of the mapping by unit order after the new unit ``key`` took the types ``taken``, from
        ``previous`` (that of the mapping before): pinned types and units' own types keep their units."""
        found = dict(previous)
        units, pinned = self.units, self.pinned
        for type_name in taken:
            if type_name in units:
                continue  # a unit's own type (the new unit's: below)
            pin = pinned.get(type_name)
            if pin is not None and pin != key and pin in units and type_name in units[pin].guaranteed():
                continue
            found[type_name] = key
        guaranteed = units[key].guaranteed()
        for type_name, pin in pinned.items():
            if pin == key and type_name in guaranteed:
                found[type_name] = key
        found[key] = key
        return found

    def _overridden(self, by_order: dict[str, str]) -> dict[str, str]:
        """The mapping by unit order with the pinned types and each unit's own type put to their units."""
        found = dict(by_order)
        for type_name, key in self.pinned.items():
            if key in self.units and type_name in self.units[key].guaranteed():
                found[type_name] = key
        for key in self.units:  # a unit always guarantees its own type
            found[key] = key
        return found

    def _input_units(self, spec: AnnotatorSpec, guaranteed: dict[str, str]) -> tuple[str, ...]:
        """The units (sorted) that guarantee the required inputs of ``spec`` by ``guaranteed`` (a result of
        :meth:`guaranteed_by`; memoised while it is the current one)."""
        if guaranteed is not self._inputs_for:
            if guaranteed is not self._guaranteed:
                return _units_of(spec.inputs, guaranteed)
            self._inputs_for = guaranteed
            self._input_units_of = {}
        found = self._input_units_of.get(spec.name)
        if found is None:
            found = self._input_units_of[spec.name] = _units_of(spec.inputs, guaranteed)
        return found

    def _below(self, key: str) -> set[str]:
        """The unit and every unit it (transitively) needs (through its providers' required inputs)."""
        guaranteed = self.guaranteed_by()
        table = self._input_units_of if guaranteed is self._inputs_for else {}
        seen = {key}
        frontier = [key]
        while frontier:
            node = frontier.pop()
            for spec in self.units[node].providers:
                deps = table.get(spec.name)
                if deps is None:
                    deps = self._input_units(spec, guaranteed)
                for dep in deps:
                    if dep not in seen:
                        seen.add(dep)
                        frontier.append(dep)
        return seen

    def _reuse(self, key: str, above: set[str], below: set[str] | None = None) -> bool:
        """Let the types ``above`` use unit ``key`` when that makes no cycle (``below``: :meth:`_below` of ``key``,
        when known)."""
        below = self._below(key) if below is None else below
        if not below.isdisjoint(above):
            return False
        if above:
            known = self.above
            for unit in below:
                present = known.get(unit)
                if present is None:
                    known[unit] = set(above)
                elif not above <= present:
                    present |= above
        return True

    def _cut_and_reuse(self, key: str, above: set[str]) -> bool:
        """:meth:`_cut`, then :meth:`_reuse` when the cut kept some alternatives.

        A cut that changed nothing has visited exactly the units below ``key``: they are not searched again.
        """
        below = self._clean_below.get(key)
        if below is not None and below.isdisjoint(above):
            # the units are as when a cut from ``key`` found no cycle and changed nothing: none of them is above,
            # so this cut too would visit exactly them and change nothing
            return self._reuse(key, above, below)
        memo: dict[str, bool] = {}
        version = self._version
        if not self._cut_below(key, above, frozenset(), memo):
            return False
        if self._version != version:
            return self._reuse(key, above)
        self._clean_below[key] = below = set(memo)
        return self._reuse(key, above, below)

    def _cut(self, key: str, above: set[str]) -> bool:
        """Drop the alternatives below unit ``key`` that need a type in ``above``; False when none can remain."""
        return self._cut_below(key, above, frozenset(), {})

    def _cut_below(self, key: str, above: set[str], path: frozenset[str], memo: dict[str, bool]) -> bool:
        if key in above or key in path:
            return False
        known = memo.get(key)
        if known is not None:
            return known
        unit = self.units[key]
        guaranteed = self.guaranteed_by()  # as it is now: cuts further down do not change what this level reads
        # the memo of _input_units for this mapping (a cut further down may start another one: this one stays right)
        table = self._input_units_of if guaranteed is self._inputs_for else {}
        inner: frozenset[str] | None = None
        keep = []
        for spec in unit.providers:
            deps = table.get(spec.name)
            if deps is None:
                deps = self._input_units(spec, guaranteed)
            for dep in deps:
                if dep == key:
                    continue
                if dep in above or dep in path:  # what the call for ``dep`` would answer first
                    break
                done = memo.get(dep)
                if done is None:
                    inner = path | {key} if inner is None else inner
                    done = self._cut_below(dep, above, inner, memo)
                if not done:
                    break
            else:
                keep.append(spec)
        memo[key] = bool(keep)
        if keep and len(keep) < len(unit.providers):
            self._set_providers(key, keep)
        return bool(keep)

    def _drop_needing(self, key: str, type_name: str) -> bool:
        """Drop the alternatives of unit ``key`` that need ``type_name``, if others remain."""
        unit = self.units[key]
        keep = [spec for spec in unit.providers if type_name not in spec.inputs]
        if not keep or len(keep) == len(unit.providers):
            return False
        self._set_providers(key, keep)
        return True

    def _take_over(self, type_name: str, valid: list[AnnotatorSpec], consumer: str | None, above: set[str]) -> bool:
        """Every valid provider runs as an alternative elsewhere: commit that unit to one of them, or drop the
        consumer's alternatives that needed the type."""
        owner = self.owner()
        for spec in valid:
            key = owner[spec.name]
            if consumer is not None and (key == consumer or key in above):
                if self._drop_needing(consumer, type_name):
                    return True
                continue
            previous = list(self.units[key].providers)
            self._set_providers(key, [spec])
            if self._cut_and_reuse(key, above):
                self._note(type_name, f"{spec.name} also provides it")
                self.pinned[type_name] = key
                self._invalidate()
                return True
            self._set_providers(key, previous)
        return False

    def _unplanned_inputs(self) -> list[tuple[str, str]]:
        """(type, unit) for each required input of a chosen provider that no unit guarantees and no sensor gives."""
        guaranteed = self.guaranteed_by()
        sensors = self.catalog.sensors
        return [
            (needed, key)
            for key, unit in self.units.items()
            for spec in unit.providers
            for needed in spec.inputs
            if needed not in guaranteed and needed not in sensors
        ]

    def _complete(self) -> None:
        """Plan the inputs that lost their unit while units were re-chosen (a type pinned to a unit that was then
        committed to another provider); an alternative whose input still has no unit is dropped."""
        for _ in range(len(self.units) + 1):
            missing = self._unplanned_inputs()
            if not missing:
                return
            self._assign(deque(missing))
        while missing := self._unplanned_inputs():
            needed, key = missing[0]
            if not self._drop_needing(key, needed):
                raise _OrderingError(f"cannot produce {needed} for {key} without a cycle")

    def _assign(self, queue: deque[tuple[str, str | None]]) -> None:
        """Give each (type, consumer unit) of ``queue`` a unit, and so on for the inputs of its providers."""
        sensors, units = self.catalog.sensors, self.units
        while queue:
            type_name, consumer = queue.popleft()
            if type_name in sensors:
                continue
            if consumer is None:
                above: set[str] = set()
            else:
                unit = units.get(consumer)
                if unit is None or type_name not in unit.read:
                    continue  # the consumer's alternatives that needed it were dropped
                known = self.above.get(consumer)
                above = {consumer} if known is None else known | {consumer}
            existing = (self._guaranteed or self.guaranteed_by()).get(type_name)
            if existing is not None and self._cut_and_reuse(existing, above):
                continue
            if existing is not None and consumer is not None and self._drop_needing(consumer, type_name):
                continue
            value = self.values.get(type_name)
            if existing == type_name:
                # the type's own unit leads back to this consumer: choose its providers again under all constraints
                combined = above | self.above.get(type_name, set())
                owner = self._owners  # read here only, before the units change
                again = [
                    s
                    for s in self.catalog.valid(type_name, value, frozenset(combined), self.by_rounds)
                    if owner.get(s.name) in (None, type_name)
                ]
                if not again:
                    raise _OrderingError(f"cannot order the annotators for {type_name}: its providers need {consumer}")
                self._set_providers(type_name, again)
                self.above[type_name] = combined
                queue.extend((needed, type_name) for spec in again for needed in spec.inputs)
                continue
            valid = self.catalog.valid(type_name, value, above, self.by_rounds)
            owners = self._owners  # annotator -> its unit
            free = [s for s in valid if s.name not in owners]
            if not free:
                if not self._take_over(type_name, valid, consumer, above):
                    raise _OrderingError(f"cannot produce {type_name}: {self.catalog.why_not(type_name, value)}")
                continue
            self.units[type_name] = _UnitChoice(type_name, free, value, self.catalog)
            for spec in free:
                owners[spec.name] = type_name
            insort(self._order, (self.catalog.rounds.get(type_name, 0), type_name))
            self._add_guaranteed(type_name)
            self.above[type_name] = above  # (a set of this round's own)
            consumers = self.consumers  # (:meth:`_note_consumer` inline: many inputs per plan)
            for spec in free:
                name = spec.name
                for needed in spec.inputs:
                    noted = consumers.get(needed)
                    if noted is None:
                        consumers[needed] = [name]
                    elif name not in noted:
                        noted.append(name)
                    if needed not in sensors:  # (a sensor type needs no unit: it would be skipped)
                        queue.append((needed, type_name))

    def _prune(self) -> None:
        """Drop units that no requirement needs any more (after a unit was committed to one provider)."""
        while True:
            guaranteed = self.guaranteed_by()
            needed: set[str] = set()
            frontier = [r.annotation_type for r in self.requirements]
            while frontier:
                type_name = frontier.pop()
                key = guaranteed.get(type_name)
                if key is None or key in needed:
                    continue
                needed.add(key)
                for spec in self.units[key].providers:
                    frontier += spec.inputs
            unneeded = set(self.units) - needed
            if not unneeded:
                return
            for key in unneeded:
                for spec in self.units.pop(key).providers:
                    del self._owners[spec.name]
            self._order = [entry for entry in self._order if entry[1] in self.units]
            self._invalidate()


def _units_of(types: tuple[str, ...], guaranteed: Mapping[str, str]) -> tuple[str, ...]:
    """The units (sorted, each once) that guarantee ``types`` by ``guaranteed``."""
    if len(types) == 1:
        key = guaranteed.get(types[0])
        return () if key is None else (key,)
    return tuple(sorted({guaranteed[t] for t in types if t in guaranteed}))


def _depths(graph: Mapping[str, set[str]]) -> dict[str, int] | None:
    """Each node's depth (0 without dependencies, else one more than its deepest dependency), or None when the
    graph has a cycle."""
    depth: dict[str, int] = {}

    def level(node: str) -> int | None:
        found = depth.get(node)
        if found is not None:
            return None if found < 0 else found  # -1: still being visited, a cycle
        depth[node] = -1
        deepest = -1
        for dep in graph.get(node, ()):
            below = depth.get(dep)
            if below is None:
                below = level(dep)
                if below is None:
                    return None
            elif below < 0:
                return None
            if below > deepest:
                deepest = below
        depth[node] = deepest + 1
        return deepest + 1

    for node in graph:
        if node not in depth and level(node) is None:
            return None
    return depth


def _find_cycle(graph: Mapping[str, set[str]]) -> list[str] | None:
    """A cycle of the graph (each node followed by a node it depends on), or None."""
    state: dict[str, int] = {}
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for dep in sorted(graph.get(node, ())):
            if state.get(dep) == 1:
                return path[path.index(dep) :]
            if dep not in state:
                found = visit(dep)
                if found:
                    return found
        state[node] = 2
        path.pop()
        return None

    for node in sorted(graph):
        if node not in state:
            found = visit(node)
            if found:
                return found
    return None


class _Layout:
    """Units (the reader, provider units, refinements) with their dependencies, staged by depth.

    Unit keys: ``reader``, ``type:<T>`` and ``refine:<annotator>``.
    """

    def __init__(
        self,
        catalog: _Catalog,
        assignment: _Assignment,
        source: SensorSource,
        parameters: dict[str, Mapping[str, object]],
    ) -> None:
        self.catalog = catalog
        self.assignment = assignment
        self.units = assignment.units
        self.source = source
        self.parameters = parameters
        self._labels: dict[str, str] = {}
        self._branch_members: dict[tuple[str, str], list[AnnotatorSpec]] = {}  # (type, alternative) -> _members
        self.branches = self._branches()
        absorbed = {t for owned in self.branches.values() for types in owned.values() for t in types}
        # type -> the key of its final producer (read by type only: the order is no matter)
        self.final: dict[str, str] = dict.fromkeys(catalog.sensors, "reader")
        keys = {key: f"type:{key}" for key in self.units}
        for type_name, key in assignment.guaranteed_by().items():
            if key not in absorbed:
                self.final[type_name] = keys[key]
        for owner_type, owned in self.branches.items():
            for types in owned.values():
                for type_name in types:
                    self.final[type_name] = f"type:{owner_type}"
        self.unrefined = dict(self.final)
        self.refinements = self._refinements()
        self._unit_inputs = self._branch_inputs(absorbed)
        self._settle()
        # a type whose unit moved into a Fallback's branch exists only when that branch ran: a refiner outside
        # reading it is left out
        if any(not absorbed.isdisjoint(s.inputs) for specs in self.refinements.values() for s in specs):
            kept = {t: [s for s in specs if absorbed.isdisjoint(s.inputs)] for t, specs in self.refinements.items()}
            self.refinements = {t: specs for t, specs in kept.items() if specs}
            self._settle()

    def _settle(self) -> None:
        """Connect the units; leave out refinements that close a cycle until none does."""
        while True:
            self._connect()
            cycle = self._required_cycle()
            if cycle is None:
                break
            # refinements that would close a cycle are left out (refinements are improvements, never required)
            dropped = {key.split(":", 1)[1] for key in cycle if key.startswith("refine:")}
            if not dropped:
                raise PlanningError(f"the annotators for {' -> '.join(cycle)} depend on each other in a cycle")
            self.refinements = {t: [s for s in specs if s.name not in dropped] for t, specs in self.refinements.items()}
            self.refinements = {t: specs for t, specs in self.refinements.items() if specs}

    def _connect(self) -> None:
        """Compute the final producer of each type and every unit's dependencies for the current refinements."""
        self.final = dict(self.unrefined)
        for type_name, specs in self.refinements.items():
            self.final[type_name] = f"refine:{specs[-1].name}"
        self.dependencies: dict[str, set[str]] = {"reader": set()}
        self._depth: dict[str, int] | None = None
        self.optional_edges: set[tuple[str, str]] = set()
        self.refines_output_of: dict[str, str] = {}
        final = self.final
        edges, dependencies = self.optional_edges, self.dependencies
        for type_name, specs in self.refinements.items():  # (by type, sorted)
            previous = self.unrefined[type_name]
            for spec in specs:
                key = f"refine:{spec.name}"
                self.refines_output_of[spec.name] = previous
                deps = {previous}
                for t in spec.inputs:
                    if t != type_name and t in final:
                        deps.add(final[t])
                if spec.optional_inputs:
                    optional = {final[t] for t in spec.optional_inputs if t in final} - deps
                    if optional:
                        edges.update((key, dep) for dep in optional)
                        deps |= optional
                deps.discard(key)
                dependencies[key] = deps
                previous = key
        for key, (required_types, optional_types) in self._unit_inputs.items():
            deps = {final[t] for t in required_types if t in final}
            if optional_types:
                optional = {final[t] for t in optional_types if t in final} - deps
                if optional:
                    edges.update((key, dep) for dep in optional)
                    deps |= optional
            deps.discard(key)
            dependencies[key] = deps

    def _branch_inputs(self, absorbed: set[str]) -> dict[str, tuple[tuple[str, ...], tuple[str, ...]]]:
        """Per provider unit not ``absorbed`` into a branch, by its key: the required and the optional input types
        its branches read from outside themselves (they do not change with the refinements; read as sets)."""
        found: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {}
        for type_name, unit in self.units.items():  # (read by key: the order is no matter)
            if type_name in absorbed:
                continue
            branches = self.branches.get(type_name)
            if len(unit.providers) == 1 and not (branches and branches.get(unit.providers[0].name)):
                found[f"type:{type_name}"] = (unit.providers[0].inputs, unit.providers[0].optional_inputs)
                continue
            required: set[str] = set()
            optional: set[str] = set()
            for spec in unit.providers:
                if not branches or not branches.get(spec.name):  # the alternative alone in its branch
                    required.update(spec.inputs)
                    optional.update(spec.optional_inputs)
                    continue
                members = self._members(type_name, spec)
                inside = set(branches[spec.name])
                required.update(t for m in members for t in m.inputs if t not in inside)
                optional.update(t for m in members for t in m.optional_inputs if t not in inside)
            found[f"type:{type_name}"] = (tuple(required), tuple(optional))
        return found

    def _refinements(self) -> dict[str, list[AnnotatorSpec]]:
        """Refiners of planned types whose other inputs are planned too and that are not otherwise used."""
        used = set(self.assignment.owner())
        read = {r.annotation_type for r in self.assignment.requirements}
        for unit in self.units.values():
            read.update(unit.read)
        found: dict[str, list[AnnotatorSpec]] = {}
        final = self.final
        for type_name in sorted(final.keys() & read):
            candidates = self.catalog.refiners(type_name)
            if not candidates:
                continue
            usable = [
                s for s in candidates if s.name not in used and all(t == type_name or t in final for t in s.inputs)
            ]
            # refiners made for a situation (with preconditions, which hold) all apply; of the general-purpose
            # ones only the cheapest does, so two interchangeable crops are never chained
            specs = [s for s in usable if s.preconditions]  # (cheapest first, as the candidates)
            general = [s for s in usable if not s.preconditions]
            if general:
                insort(specs, min(general, key=_by_rank_among_crops), key=_by_cost)
            if specs:
                found[type_name] = specs
                used |= {s.name for s in specs}
        return found

    def _producers(self, types: Iterable[str]) -> set[str]:
        return {self.final[t] for t in types if t in self.final}

    def _members(self, type_name: str, spec: AnnotatorSpec) -> list[AnnotatorSpec]:
        """The annotators of one branch: absorbed providers in dependency order, then the alternative."""
        key = (type_name, spec.name)
        found = self._branch_members.get(key)
        if found is None:
            owned = self.branches.get(type_name, {}).get(spec.name, [])
            ordered = _topological(owned, self.units, self.assignment.guaranteed_by()) if owned else []
            found = self._branch_members[key] = [self.units[t].providers[0] for t in ordered] + [spec]
        return found

    def _branches(self) -> dict[str, dict[str, list[str]]]:
        """For each unit with alternatives: the units only one alternative needs, moved into its branch.

        A unit moves when it has a single provider, guarantees nothing else that is required elsewhere, and is
        needed only inside that branch or by other alternatives of the same type (then it goes into each of
        theirs); optional readers elsewhere do not hold it back.
        """
        # only required inputs bind a unit to the stage: an optional reader (size or shape using the plane when
        # there is one) runs after the Fallback that may have made it and does without when no branch did
        multiple = sorted(t for t, unit in self.units.items() if len(unit.providers) > 1)
        if not multiple:
            return {}
        specs = [s for unit in self.units.values() for s in unit.providers]
        for type_name in set(self.units) | self.catalog.sensors:  # (sets of readers: the order is no matter)
            specs += self.catalog.refiners(type_name)
        guaranteed = self.assignment.guaranteed_by()
        # per unit: who reads what it guarantees (units nobody reads are left out)
        readers: dict[str, set[str]] = {}
        for spec in specs:
            for needed in spec.inputs:
                key = guaranteed.get(needed)
                if key is not None:
                    found = readers.get(key)
                    if found is None:
                        readers[key] = {spec.name}
                    else:
                        found.add(spec.name)
        branches: dict[str, dict[str, list[str]]] = {}
        for type_name in multiple:
            unit = self.units[type_name]
            rivals = {s.name for s in unit.providers}
            # a unit only alternatives of this type need goes into each of their branches: a branch that fails
            # (its plane not found) then hands over to the next, which makes its own - unless some alternative
            # needing it would not own it, then units go into a branch only when that branch alone needs them
            shared = {spec.name: self._owned(spec, type_name, guaranteed, readers, rivals) for spec in unit.providers}
            if not all(
                consumer in members or (consumer in rivals and key in shared[consumer][0])
                for owned, members in shared.values()
                for key in owned
                for consumer in readers.get(key, ())
            ):
                shared = {
                    spec.name: self._owned(spec, type_name, guaranteed, readers, set()) for spec in unit.providers
                }
            branches[type_name] = {name: owned for name, (owned, _) in shared.items()}
        return branches

    def _owned(
        self,
        spec: AnnotatorSpec,
        type_name: str,
        guaranteed: dict[str, str],
        readers: dict[str, set[str]],
        rivals: set[str],
    ) -> tuple[list[str], set[str]]:
        """The units that move into the branch of alternative ``spec`` of ``type_name`` (and the branch's
        annotators): single-provider units whose outputs only the branch (or the ``rivals``) read (``readers``: who
        reads what each unit guarantees, read units only)."""
        members = {spec.name}
        allowed = members | rivals  # who may read what moves into the branch
        units = self.units
        for needed in spec.inputs:  # the branch owns nothing unless it can own a unit making one of its inputs
            key = guaranteed.get(needed)
            if (
                key is not None
                and key != type_name
                and len(units[key].providers) == 1
                and (key not in readers or readers[key] <= allowed)
            ):
                break
        else:
            return [], members
        owned: list[str] = []
        frontier = list(spec.inputs)
        while frontier:
            needed = frontier.pop(0)
            key = guaranteed.get(needed)
            if key is None or key in owned or key == type_name or len(self.units[key].providers) != 1:
                continue
            if key in readers and not readers[key] <= allowed:
                continue
            owned.append(key)
            inner = self.units[key].providers[0]
            members.add(inner.name)
            allowed.add(inner.name)
            frontier.extend(inner.inputs)
        return owned, members

    def _required_cycle(self) -> list[str] | None:
        """Drop optional ordering edges that close cycles; return a cycle of required edges, if any.

        Without a cycle the units' depths (their stages) are kept from the check (which finds no depths when there
        is one)."""
        self._depth = _depths(self.dependencies)
        while self._depth is None:
            cycle = _find_cycle(self.dependencies)
            if cycle is None:
                return None
            edges = list(zip(cycle, cycle[1:] + cycle[:1], strict=True))
            optional = [edge for edge in edges if edge in self.optional_edges]
            if not optional:
                return cycle
            consumer, producer = optional[0]
            self.dependencies[consumer].discard(producer)
            self._depth = _depths(self.dependencies)
        return None

    def stages(self) -> tuple[tuple[Unit, ...], ...]:
        """Units grouped by dependency depth, in a deterministic order."""
        self._refiner_of = {s.name: (t, s) for t, specs in self.refinements.items() for s in specs}
        self._made_by: dict[str, str] = {}  # type -> "<type> from <its final producer>" (for the steps' reasons)
        depth = self._depth if self._depth is not None else _depths(self.dependencies)
        assert depth is not None, "the dependencies were checked for cycles"
        by_level: dict[int, list[str]] = {}
        for key in sorted(self.dependencies):  # each level's keys sorted
            by_level.setdefault(depth[key], []).append(key)
        unit = self._unit
        return tuple(tuple([unit(key) for key in keys]) for _, keys in sorted(by_level.items()))

    def _label(self, key: str) -> str:
        found = self._labels.get(key)
        if found is None:
            found = self._labels[key] = self._make_label(key)
        return found

    def _make_label(self, key: str) -> str:
        if key == "reader":
            return self.source.step.annotator
        kind, name = key.split(":", 1)
        if kind == "refine":
            return name
        providers = self.units[name].providers
        return providers[0].name if len(providers) == 1 else " / ".join([s.name for s in providers])

    def _step(
        self, spec: AnnotatorSpec, why: str, provides: str = "", inside_types: frozenset[str] = frozenset()
    ) -> Step:
        """The step of ``spec``, its reason naming what feeds each input (``inside_types``: the types made by the
        units moved into its branch)."""
        final, made = self.final, self._made_by
        name = spec.name
        refined = self.refines_output_of.get(name)  # what a refiner's step reads of the type it refines
        feeds = []
        for needed in spec.inputs:
            # a type a unit inside the branch also makes as a by-product may be guaranteed by none (the reader
            # makes it): then it is fed as outside the branch
            guarantor = self.assignment.guaranteed_by().get(needed) if inside_types and needed in inside_types else None
            if guarantor is not None:
                maker = self.units[guarantor].providers[0].name
                feeds.append(f"{needed} from {maker}")
            elif refined is not None and needed in spec.outputs:
                feeds.append(f"{needed} from {self._label(refined)}")
            else:
                feed = made.get(needed)
                if feed is None and needed in final:
                    feed = made[needed] = f"{needed} from {self._label(final[needed])}"
                if feed is not None:
                    feeds.append(feed)
        parameters = self.parameters.get(name)
        # positional (many steps per plan): annotator, implemented_by, inputs, outputs, parameters, reason, provides
        return Step(
            name,
            spec.implemented_by,
            spec.inputs,
            spec.outputs,
            tuple(sorted(parameters.items())) if parameters else (),
            f"{name}: {why}; needs {', '.join(feeds)}" if feeds else f"{name}: {why}",
            provides,
        )

    def _why(self, type_name: str) -> str:
        others = self.assignment.reasons.get(type_name)
        consumers = self.assignment.consumers.get(type_name)
        if consumers:
            needed = f"{type_name} is needed by {', '.join(consumers)}"
            return "; ".join([*others, needed]) if others else needed
        return "; ".join(others) if others else f"provides {type_name}"

    def _unit(self, key: str) -> Unit:
        if key.startswith("type:"):
            name = key[5:]
        elif key == "reader":
            return self.source.step
        else:
            refined, spec = self._refiner_of[key.removeprefix("refine:")]
            return self._step(spec, f"refines {refined} before it is used ({_precondition_note(spec)})")
        unit = self.units[name]
        if len(unit.providers) == 1:
            return self._step(unit.providers[0], self._why(name), name)
        branches = []
        why = self._why(name)
        for spec in unit.providers:
            owned = self.branches[name][spec.name]
            if not owned:
                branches.append((self._step(spec, why, name),))
                continue
            inside = frozenset(t for key in owned for t in self.units[key].guaranteed())
            inner = tuple(
                self._step(m, f"needed only by {spec.name}", inside_types=inside)
                for m in self._members(name, spec)[:-1]
            )
            branches.append((*inner, self._step(spec, why, provides=name, inside_types=inside)))
        notes = self.catalog.ontology.rank_notes
        ranking = ", ".join([notes[s.name] for s in unit.providers])
        return Alternatives(
            provides=name,
            branches=tuple(branches),
            reason=f"{len(unit.providers)} annotators can provide {name}; tried in rank order: {ranking}",
        )


def _by_cost(spec: AnnotatorSpec) -> tuple[float, str]:
    """Cheapest first (the order of refiners)."""
    return spec.cost_ms, spec.name


def _by_rank_among_crops(spec: AnnotatorSpec) -> tuple[float, float, str]:
    """The general-purpose refiner that runs: the cheapest, then the most reliable."""
    return spec.cost_ms, -spec.reliability, spec.name


def _topological(keys: list[str], units: Mapping[str, _UnitChoice], guaranteed: Mapping[str, str]) -> list[str]:
    """Order units so that each comes after the units of the same list that make the types it needs.

    A type's maker is the unit that guarantees it in the plan (``guaranteed``), not any unit that also writes it:
    a unit writing a type another unit already makes must not be waited for by that type's readers (that could
    make a cycle, and the cycle's order would be arbitrary)."""
    ordered: list[str] = []
    remaining = list(keys)
    while remaining:
        for key in sorted(remaining):
            makers = {guaranteed.get(t) for t in units[key].providers[0].inputs}
            if not any(other in makers for other in remaining if other != key):
                ordered.append(key)
                remaining.remove(key)
                break
        else:
            ordered.extend(sorted(remaining))
            break
    return ordered


def _precondition_note(spec: AnnotatorSpec) -> str:
    if spec.preconditions:
        return "its preconditions hold: " + ", ".join(spec.preconditions)
    return "the cheapest general-purpose one"


def _exclusion(
    spec: AnnotatorSpec, value_kind: Kind | None, value: str | None, object_class: str | None, conditions: Conditions
) -> str:
    """Why the knowledge base excluded ``spec`` as a provider of a type whose values are of ``value_kind``."""
    domain = spec.domain(value_kind) if value_kind is not None else frozenset()
    if value is not None and domain:
        return f"can report only {', '.join(sorted(domain))}, not {value!r}"
    if spec.preconditions:
        facts = f"depth available: {conditions.depth}, region given: {conditions.region}"
        target = f" for {object_class}" if object_class else ""
        return f"has preconditions {', '.join(spec.preconditions)} that do not hold{target} ({facts})"
    if object_class is not None and spec.classes:
        return f"recognises only {', '.join(sorted(spec.classes))}, not {object_class}"
    return "was excluded by the knowledge base"
