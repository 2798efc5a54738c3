"""Property tests of plan synthesis over random capability ontologies loaded by the real KnowledgeBase."""

from __future__ import annotations

import random
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from reasoning.planning.plan import Alternatives, Plan, Step, Task
from reasoning.planning.planner import PlanningError, Requirement, SensorSource, plan_requirements
from robokudo.core.annotator import Annotator
from robokudo.core.dataflow import validate_data_flow
from robokudo.core.render import unicode_tree
from robokudo.core.types import Annotation, CasType, View
from tests.planning.capability_ontology import CapabilityOntology, random_ontology
from trees.synthesis import build_tree


class PortTypes:
    """CAS classes made on the fly for the generated type names (views for sensors, annotations otherwise)."""

    def __init__(self, sensors: tuple[str, ...]) -> None:
        self.sensors = set(sensors)
        self.classes: dict[str, type[CasType]] = {}

    def __call__(self, name: str) -> type[CasType]:
        if name not in self.classes:
            self.classes[name] = type(name, (View if name in self.sensors else Annotation,), {})
        return self.classes[name]

    def node(self, step: Step) -> Annotator:
        cls = type(
            step.annotator,
            (Annotator,),
            {"inputs": tuple(map(self, step.inputs)), "outputs": tuple(map(self, step.outputs))},
        )
        return cls()


def reader_for(ontology: CapabilityOntology) -> SensorSource:
    step = Step("Reader", "annotators.generated.Reader", (), ontology.sensors, reason="reads the sensors")
    return SensorSource(step)


def plan_for(ontology: CapabilityOntology, kb, wanted: list[str]) -> Plan:
    requirements = [Requirement(t, None, f"test requires {t}") for t in wanted]
    return plan_requirements(Task(kind="detect"), requirements, kb, reader_for(ontology))


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 10_000), annotators=st.integers(3, 14), types=st.integers(3, 9))
@example(seed=1818, annotators=12, types=7)  # a branch's absorbed unit also wrote a type another unit makes
def test_random_capability_ontologies(seed: int, annotators: int, types: int) -> None:
    rng = random.Random(seed)
    ontology = random_ontology(rng, sensors=2, types=types, annotators=annotators)
    producible = ontology.producible()
    with tempfile.TemporaryDirectory() as folder:
        kb = ontology.load(Path(folder))
        for _ in range(4):
            wanted = sorted(rng.sample(ontology.types, rng.randint(1, 3)))
            satisfiable = set(wanted) <= producible
            if not satisfiable:
                with pytest.raises(PlanningError, match="cannot satisfy"):
                    plan_for(ontology, kb, wanted)
                continue
            plan = plan_for(ontology, kb, wanted)
            ports = PortTypes(ontology.sensors)
            tree = build_tree(plan, make=ports.node)  # build_tree runs the data-flow validator
            validate_data_flow(tree)
            check_each_annotator_once(plan)
            check_minimal(plan, wanted)
            check_alternatives_in_fallbacks(plan)
            again = plan_for(ontology, kb, wanted)
            assert again == plan  # deterministic
            assert unicode_tree(build_tree(again, make=PortTypes(ontology.sensors).node)) == unicode_tree(tree)


def check_each_annotator_once(plan: Plan) -> None:
    """Each annotator runs at most once on any path: it appears once in the plan, or (a unit that only the
    alternatives of one Fallback need) once in each of several branches of one Alternatives."""
    outside = [unit.annotator for unit in plan.units() if isinstance(unit, Step)]
    inside: dict[str, int] = {}
    for unit in plan.units():
        if isinstance(unit, Alternatives):
            for branch in unit.branches:
                names = [step.annotator for step in branch]
                assert len(names) == len(set(names)), names
            for name in {step.annotator for branch in unit.branches for step in branch}:
                inside[name] = inside.get(name, 0) + 1
    assert len(outside) == len(set(outside)), outside
    assert all(count == 1 for count in inside.values()), inside  # never in two Fallbacks
    assert not set(outside) & set(inside), set(outside) & set(inside)


def check_minimal(plan: Plan, wanted: list[str]) -> None:
    """Every annotator's outputs are needed: required, or read by another annotator of the plan."""
    steps = list(plan.steps())
    for step in steps[1:]:  # the reader is the plan's source
        readers = {t for other in steps if other is not step for t in other.inputs}
        useful = set(step.outputs) & (set(wanted) | readers)
        assert useful, f"{step.annotator} produces {step.outputs}, which nothing needs"


def check_alternatives_in_fallbacks(plan: Plan) -> None:
    """Each type is provided by one unit; several providers of it sit together in one Fallback."""
    provided = []
    for unit in plan.units():
        if isinstance(unit, Alternatives):
            assert len(unit.branches) >= 2
            assert all(branch[-1].provides == unit.provides for branch in unit.branches)
            provided.append(unit.provides)
        elif unit.provides:
            provided.append(unit.provides)
    assert len(provided) == len(set(provided)), provided


def test_unsatisfiable_requirement_is_an_error_naming_it() -> None:
    ontology = random_ontology(random.Random(3), sensors=1, types=3, annotators=0)
    with tempfile.TemporaryDirectory() as folder:
        kb = ontology.load(Path(folder))
        with pytest.raises(PlanningError, match=r"test requires T0.*no annotator in the ontology provides T0"):
            plan_for(ontology, kb, ["T0"])
