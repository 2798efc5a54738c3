"""The planner's result: what the query asks (Task) and which experts run in which order (Plan).

A Plan is pure data (no behaviour-tree nodes, no vision code); ``trees.synthesis`` turns it into a
Perception Pipeline Tree.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

from queries.selection import SelectionRequest


@dataclass(frozen=True)
class Constraint:
    """A requested value: ``key`` of the query, the annotation type answering it and the value asked for."""

    key: str
    annotation_type: str
    value: str | None


@dataclass(frozen=True)
class Task:
    """The query interpreted against the knowledge base."""

    kind: str
    object_class: str | None = None
    region: str | None = None
    constraints: tuple[Constraint, ...] = ()
    inferences: tuple[str, ...] = ()
    max_results: int | None = None
    object_id: int | None = None
    min_confidence: float = 0.0
    pointing: str | None = None
    """What a pointing query asks for (``object`` or ``region``), None for other queries."""
    footprint: tuple[float, float] | None = None
    """Width and depth (metres) of what a free-space scan looks for room for; None when it looks for none."""
    selection: SelectionRequest | None = None
    """How the answer picks among the objects found (``the top box``); None when it answers every one."""

    def constraint(self, key: str) -> Constraint | None:
        """The constraint on ``key``, or None."""
        return next((c for c in self.constraints if c.key == key), None)


@dataclass(frozen=True)
class Step:
    """One annotator in the plan: its ontology name, implementing class, ports, parameters and why it is there.

    ``provides`` is the type it was chosen to provide ("" for the reader, refinements and steps inside a branch).
    """

    annotator: str
    implemented_by: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    parameters: tuple[tuple[str, Any], ...] = ()
    reason: str = ""
    provides: str = ""

    def __init__(
        self,
        annotator: str,
        implemented_by: str,
        inputs: tuple[str, ...],
        outputs: tuple[str, ...],
        parameters: tuple[tuple[str, Any], ...] = (),
        reason: str = "",
        provides: str = "",
    ) -> None:
        # the fields set in one update (a plan builds dozens of steps; the frozen dataclass's own __init__ sets each
        # field through object.__setattr__, twice as slow)
        self.__dict__.update(
            annotator=annotator,
            implemented_by=implemented_by,
            inputs=inputs,
            outputs=outputs,
            parameters=parameters,
            reason=reason,
            provides=provides,
        )


@dataclass(frozen=True)
class Alternatives:
    """Several ways to produce one type, tried in rank order (a Fallback). Each branch ends with its provider."""

    provides: str
    branches: tuple[tuple[Step, ...], ...]
    reason: str = ""

    @property
    def providers(self) -> tuple[Step, ...]:
        """The last step of each branch: the annotator that provides the type."""
        return tuple(branch[-1] for branch in self.branches)


Unit = Step | Alternatives


@dataclass(frozen=True)
class Plan:
    """Stages run one after another; the units of a stage are independent and may run side by side."""

    task: Task
    stages: tuple[tuple[Unit, ...], ...]
    sensor_types: frozenset[str] = field(default_factory=frozenset)

    def units(self) -> Iterator[Unit]:
        """Every unit, stage by stage."""
        for stage in self.stages:
            yield from stage

    def steps(self) -> Iterator[Step]:
        """Every step, including those inside alternatives."""
        for unit in self.units():
            if isinstance(unit, Step):
                yield unit
            else:
                for branch in unit.branches:
                    yield from branch

    def annotator_names(self) -> list[str]:
        """Names of every annotator in the plan, in order."""
        return [step.annotator for step in self.steps()]
