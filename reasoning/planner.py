"""Plan synthesis: from required annotation types to a staged, minimal set of experts.

The algorithm, polynomial in annotators x types:

1. *Requirements*: each required type carries an optional requested value and a reason.
2. *Provider choice* (memoised per type): the knowledge base ranks the annotators whose outputs include
   the type, whose value domain covers the requested value under class subsumption and whose
   preconditions hold. Annotators that refine a type (read and write it, like a crop filter) are not
   providers of it. A provider is feasible when all its inputs are feasible; infeasible ones are dropped,
   and a type with no feasible provider is an error naming what was missing and why.
3. *Backward chaining* from the providers' inputs to the sensor types the reader supplies. Each annotator
   appears once. Refinements of a type whose preconditions hold run after the type's providers and
   before its consumers.
4. *Grouping*: a type with several feasible providers becomes an Alternatives unit (a Fallback, in rank
   order); inputs only one alternative needs move into that alternative's branch so that a failing
   branch hands over to the next. Units are staged by dependency depth; a stage's units are independent.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Protocol

from reasoning.model import AnnotatorSpec, Conditions
from reasoning.plan import Alternatives, Plan, Step, Task, Unit


class PlanningError(Exception):
    """No tree can satisfy the query; the message says which requirement failed and why."""


class ProviderIndex(Protocol):
    """Ranked providers of a type, honouring value domains, subsumption and preconditions (the KnowledgeBase)."""

    def providers(
        self,
        annotation_type: str,
        value: str | None = None,
        object_class: str | None = None,
        conditions: Conditions | None = None,
    ) -> Sequence[AnnotatorSpec]:
        """Annotators providing ``annotation_type`` that can report ``value`` for ``object_class``, best first."""
        ...


@dataclass(frozen=True)
class Requirement:
    """A type the answer needs, the value asked for and why."""

    annotation_type: str
    value: str | None = None
    reason: str = ""


@dataclass(frozen=True)
class SensorSource:
    """The reader that starts every plan and the types it supplies."""

    step: Step

    @property
    def types(self) -> frozenset[str]:
        """The types the reader writes."""
        return frozenset(self.step.outputs)


@dataclass
class _Search:
    """State of one planning run (memo tables); discarded afterwards."""

    index: ProviderIndex
    sensors: frozenset[str]
    object_class: str | None
    conditions: Conditions
    values: dict[str, str | None] = field(default_factory=dict)
    chosen: dict[str, list[AnnotatorSpec]] = field(default_factory=dict)
    failures: dict[str, str] = field(default_factory=dict)
    visiting: set[str] = field(default_factory=set)
    reasons: dict[str, list[str]] = field(default_factory=dict)

    def feasible(self, type_name: str, value: str | None, reason: str) -> bool:
        """Choose providers for ``type_name`` (memoised); False with a recorded reason when impossible."""
        self.reasons.setdefault(type_name, [])
        if reason and reason not in self.reasons[type_name]:
            self.reasons[type_name].append(reason)
        if type_name in self.sensors:
            return True
        if type_name in self.chosen:
            return True
        if type_name in self.failures or type_name in self.visiting:
            return False
        self.visiting.add(type_name)
        candidates = [
            spec
            for spec in self.index.providers(type_name, value, self.object_class, self.conditions)
            if type_name not in spec.inputs
        ]
        feasible = []
        blocked: list[str] = []
        for spec in candidates:
            missing = [needed for needed in spec.inputs if not self.feasible(needed, None, f"needed by {spec.name}")]
            if missing:
                blocked.append(f"{spec.name} needs {', '.join(missing)}, which cannot be produced")
            else:
                feasible.append(spec)
        self.visiting.discard(type_name)
        if not feasible:
            self.failures[type_name] = self._why_none(type_name, value, blocked)
            return False
        self.chosen[type_name] = feasible
        self.values[type_name] = value
        return True

    def _why_none(self, type_name: str, value: str | None, blocked: list[str]) -> str:
        asked = f"{type_name} with value {value!r}" if value else type_name
        usable = {spec.name for spec in self.index.providers(type_name, value, self.object_class, self.conditions)}
        details = [
            f"{spec.name} {_exclusion(spec, type_name, value, self.object_class, self.conditions)}"
            for spec in self.index.providers(type_name)
            if spec.name not in usable and type_name not in spec.inputs
        ] + blocked
        if not details:
            return f"no annotator in the ontology provides {asked}"
        return f"no usable annotator provides {asked} ({'; '.join(details)})"


def plan_requirements(
    task: Task,
    requirements: Sequence[Requirement],
    index: ProviderIndex,
    source: SensorSource,
    conditions: Conditions | None = None,
    parameters: Mapping[str, Mapping[str, object]] | None = None,
) -> Plan:
    """Synthesize the staged plan that produces every requirement from the sensor source.

    ``conditions`` say whether depth and a region are available; ``parameters`` are constructor arguments
    per annotator name (e.g. the region box for a region filter).
    """
    search = _Search(index, source.types, task.object_class, conditions or Conditions())
    for requirement in requirements:
        if not search.feasible(requirement.annotation_type, requirement.value, requirement.reason):
            raise PlanningError(
                f"cannot satisfy '{requirement.reason or requirement.annotation_type}': "
                f"{search.failures[requirement.annotation_type]}"
            )
    refinements = _refinements(index, search, source.types)
    graph = _UnitGraph(search, refinements, source, dict(parameters or {}))
    return Plan(task=task, stages=graph.stages(), sensor_types=source.types)


def _refinements(index: ProviderIndex, search: _Search, sensors: frozenset[str]) -> dict[str, list[AnnotatorSpec]]:
    """Annotators that read and write a planned type and whose preconditions and other inputs hold."""
    planned = set(search.chosen) | set(sensors)
    found: dict[str, list[AnnotatorSpec]] = {}
    for type_name in sorted(planned):
        applicable = [
            spec
            for spec in index.providers(type_name, None, search.object_class, search.conditions)
            if type_name in spec.inputs
            and all(
                needed == type_name or search.feasible(needed, None, f"needed by {spec.name}") for needed in spec.inputs
            )
        ]
        if applicable:
            found[type_name] = sorted(applicable, key=lambda s: (s.cost_ms, s.name))
    return found


class _UnitGraph:
    """Units (the reader, one per provided type, one per refinement) with their dependencies, staged by depth.

    Unit keys: ``reader``, ``type:<T>`` (the providers of T: a Step or Alternatives) and ``refine:<name>``.
    """

    def __init__(
        self,
        search: _Search,
        refinements: dict[str, list[AnnotatorSpec]],
        source: SensorSource,
        parameters: dict[str, Mapping[str, object]],
    ) -> None:
        self.search = search
        self.refinements = refinements
        self.source = source
        self.parameters = parameters
        self.branches = self._branches()
        absorbed = {t for owned in self.branches.values() for types in owned.values() for t in types}
        self.final: dict[str, str] = dict.fromkeys(source.types, "reader")
        self.dependencies: dict[str, set[str]] = {"reader": set()}
        provided = [t for t in sorted(search.chosen) if t not in absorbed]
        for type_name in provided:
            self.final[type_name] = f"type:{type_name}"
        for type_name in absorbed:
            owner = next(f"type:{t}" for t, owned in self.branches.items() for ts in owned.values() if type_name in ts)
            self.final[type_name] = owner
        unrefined = dict(self.final)
        for type_name, specs in sorted(refinements.items()):
            for spec in specs:
                self.final[type_name] = f"refine:{spec.name}"
        self.refines_output_of: dict[str, str] = {}
        for type_name, specs in sorted(refinements.items()):
            previous = unrefined.get(type_name)
            for spec in specs:
                key = f"refine:{spec.name}"
                if previous:
                    self.refines_output_of[spec.name] = previous
                self.dependencies[key] = ({previous} if previous else set()) | self._producers(
                    [t for t in spec.inputs if t != type_name], spec.optional_inputs
                )
                previous = key
        for type_name in provided:
            key = f"type:{type_name}"
            deps: set[str] = set()
            for spec in search.chosen[type_name]:
                members = self._members(type_name, spec)
                inside = set(self.branches.get(type_name, {}).get(spec.name, []))
                inputs = [t for m in members for t in m.inputs if t not in inside]
                optional = [t for m in members for t in m.optional_inputs if t not in inside]
                deps |= self._producers(inputs, optional)
            deps.discard(key)
            self.dependencies[key] = deps
        self._drop_cycles()

    def _producers(self, inputs: Iterable[str], optional: Iterable[str] = ()) -> set[str]:
        keys = {self.final[t] for t in inputs if t in self.final}
        keys |= {self.final[t] for t in optional if t in self.final}
        return keys

    def _members(self, type_name: str, spec: AnnotatorSpec) -> list[AnnotatorSpec]:
        """The annotators of one branch: absorbed providers in dependency order, then the alternative."""
        owned = self.branches.get(type_name, {}).get(spec.name, [])
        return [self.search.chosen[t][0] for t in _topological(owned, self.search.chosen)] + [spec]

    def _branches(self) -> dict[str, dict[str, list[str]]]:
        """For each type with alternatives: the types only one alternative needs, moved into its branch.

        A type moves when it has a single provider, is not refined, and is consumed only inside that branch.
        """
        consumers: dict[str, set[str]] = {}
        planned = [s for specs in self.search.chosen.values() for s in specs]
        planned += [s for specs in self.refinements.values() for s in specs]
        for spec in planned:
            for needed in (*spec.inputs, *spec.optional_inputs):
                consumers.setdefault(needed, set()).add(spec.name)
        branches: dict[str, dict[str, list[str]]] = {}
        for type_name in sorted(self.search.chosen):
            specs = self.search.chosen[type_name]
            if len(specs) < 2:
                continue
            branches[type_name] = {}
            for spec in specs:
                owned: list[str] = []
                members = {spec.name}
                frontier = list(spec.inputs)
                while frontier:
                    needed = frontier.pop(0)
                    providers = self.search.chosen.get(needed, [])
                    if (
                        needed in owned
                        or len(providers) != 1
                        or needed in self.refinements
                        or not consumers.get(needed, set()) <= members
                    ):
                        continue
                    owned.append(needed)
                    members.add(providers[0].name)
                    frontier.extend(providers[0].inputs)
                branches[type_name][spec.name] = owned
        return branches

    def _drop_cycles(self) -> None:
        """Optional inputs may point backwards; such ordering edges are dropped (required ones never cycle)."""
        state: dict[str, int] = {}

        def visit(key: str) -> None:
            state[key] = 1
            for dep in sorted(self.dependencies.get(key, set())):
                if state.get(dep) == 1:
                    self.dependencies[key].discard(dep)
                elif dep not in state:
                    visit(dep)
            state[key] = 2

        for key in sorted(self.dependencies):
            if key not in state:
                visit(key)

    def stages(self) -> tuple[tuple[Unit, ...], ...]:
        """Units grouped by dependency depth, in a deterministic order."""
        depth: dict[str, int] = {}

        def level(key: str) -> int:
            if key not in depth:
                depth[key] = 1 + max((level(d) for d in self.dependencies.get(key, set())), default=-1)
            return depth[key]

        by_level: dict[int, list[str]] = {}
        for key in sorted(self.dependencies):
            by_level.setdefault(level(key), []).append(key)
        return tuple(tuple(self._unit(key) for key in sorted(keys)) for _, keys in sorted(by_level.items()))

    def _label(self, key: str) -> str:
        if key == "reader":
            return self.source.step.annotator
        if key.startswith("refine:"):
            return key.split(":", 1)[1]
        return " / ".join(s.name for s in self.search.chosen[key.split(":", 1)[1]])

    def _step(self, spec: AnnotatorSpec, why: str, inside: Iterable[str] = ()) -> Step:
        inside = set(inside)
        feeds = []
        for needed in spec.inputs:
            if needed in inside:
                feeds.append(f"{needed} from {self.search.chosen[needed][0].name}")
            elif needed in self.final:
                producer = self.final[needed]
                if needed in spec.outputs and spec.name in self.refines_output_of:
                    producer = self.refines_output_of[spec.name]
                feeds.append(f"{needed} from {self._label(producer)}")
        reason = f"{spec.name}: {why}"
        if feeds:
            reason += f"; needs {', '.join(feeds)}"
        return Step(
            annotator=spec.name,
            implemented_by=spec.implemented_by,
            inputs=tuple(spec.inputs),
            outputs=tuple(spec.outputs),
            parameters=tuple(sorted(self.parameters.get(spec.name, {}).items())),
            reason=reason,
        )

    def _why(self, type_name: str) -> str:
        reasons = self.search.reasons.get(type_name, [])
        return "; ".join(reasons) if reasons else f"provides {type_name}"

    def _unit(self, key: str) -> Unit:
        if key == "reader":
            return self.source.step
        kind, name = key.split(":", 1)
        if kind == "refine":
            spec = next(s for specs in self.refinements.values() for s in specs if s.name == name)
            refined = next(t for t in spec.outputs if t in spec.inputs)
            return self._step(spec, f"refines {refined} before it is used ({_precondition_note(spec)})")
        specs = self.search.chosen[name]
        if len(specs) == 1:
            return self._step(specs[0], self._why(name))
        branches = []
        for spec in specs:
            members = self._members(name, spec)
            owned = self.branches[name][spec.name]
            inner = tuple(self._step(m, f"needed only by {spec.name}", owned) for m in members[:-1])
            branches.append((*inner, self._step(spec, self._why(name), owned)))
        ranking = ", ".join(f"{s.name} (reliability {s.reliability:g}, {s.cost_ms:g} ms)" for s in specs)
        return Alternatives(
            provides=name,
            branches=tuple(branches),
            reason=f"{len(specs)} annotators can provide {name}; tried in rank order: {ranking}",
        )


def _topological(types: list[str], chosen: Mapping[str, list[AnnotatorSpec]]) -> list[str]:
    """Order types so that each comes after the types its provider needs."""
    ordered: list[str] = []
    remaining = list(types)
    while remaining:
        for type_name in sorted(remaining):
            needs = set(chosen[type_name][0].inputs) & set(remaining)
            if not needs:
                ordered.append(type_name)
                remaining.remove(type_name)
                break
        else:  # a cycle cannot occur in a feasible plan; keep order stable anyway
            ordered.extend(sorted(remaining))
            break
    return ordered


def _precondition_note(spec: AnnotatorSpec) -> str:
    preconditions = getattr(spec, "preconditions", ())
    return "its preconditions hold: " + ", ".join(preconditions) if preconditions else "applies to every plan"


def _exclusion(
    spec: AnnotatorSpec, type_name: str, value: str | None, object_class: str | None, conditions: Conditions
) -> str:
    """Why the knowledge base excluded ``spec`` as a provider, in words."""
    domain_field = _VALUE_DOMAIN_FIELDS.get(type_name)
    domain: frozenset[str] = getattr(spec, domain_field) if domain_field else frozenset()
    if value is not None and domain:
        return f"can report only {', '.join(sorted(domain))}, not {value!r}"
    if spec.preconditions:
        facts = f"depth available: {conditions.depth}, region given: {conditions.region}"
        target = f" for {object_class}" if object_class else ""
        return f"has preconditions {', '.join(spec.preconditions)} that do not hold{target} ({facts})"
    if object_class is not None and spec.classes:
        return f"recognises only {', '.join(sorted(spec.classes))}, not {object_class}"
    return "was excluded by the knowledge base"


_VALUE_DOMAIN_FIELDS = {"SemanticColor": "colors", "Shape": "shapes", "Size": "sizes", "Classification": "classes"}
