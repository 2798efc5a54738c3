"""Random capability ontologies for planner property tests and benchmarks, loaded by the real KnowledgeBase.

Types ``S0..`` are sensor views (what the reader supplies), ``T0..`` annotation types; they are written as Turtle
(the CAS-type vocabulary). Each annotator is a generated Annotator class, as a real expert would be: a few required
inputs, sometimes an optional input, one or two outputs, a cost and a reliability; the knowledge base gets the
classes as ``annotators=`` and turns their declarations into its annotator individuals.
"""

from __future__ import annotations

import random
from dataclasses import dataclass, field
from pathlib import Path

from ontology import shipped_files
from reasoning.knowledge.knowledge_base import KnowledgeBase
from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import Annotation, CasType, View

PREFIXES = (
    "@prefix rk: <http://robokudo.org/ontology#> .\n"
    "@prefix owl: <http://www.w3.org/2002/07/owl#> .\n"
    "@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\n\n"
)


@dataclass(frozen=True)
class RandomAnnotator:
    """One generated annotator."""

    name: str
    inputs: tuple[str, ...]
    optional_inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    cost_ms: float
    reliability: float


@dataclass(frozen=True)
class CapabilityOntology:
    """Generated sensor types, annotation types and annotators."""

    sensors: tuple[str, ...]
    types: tuple[str, ...]
    annotators: tuple[RandomAnnotator, ...]
    _cas_types: dict[str, type[CasType]] = field(default_factory=dict, compare=False, repr=False)

    def turtle(self) -> str:
        """The generated CAS types as Turtle (sensor types as views, the others as annotation types)."""
        lines = [PREFIXES]
        for sensor in self.sensors:
            lines.append(f'rk:{sensor} a owl:Class ; rdfs:subClassOf rk:View ; rdfs:label "{sensor.lower()}" .\n')
        for type_name in self.types:
            lines.append(
                f'rk:{type_name} a owl:Class ; rdfs:subClassOf rk:Annotation ; rdfs:label "{type_name.lower()}" .\n'
            )
        return "".join(lines)

    def cas_type(self, name: str) -> type[CasType]:
        """The runtime class of a generated type (made once per ontology)."""
        if name not in self._cas_types:
            base = View if name in self.sensors else Annotation
            self._cas_types[name] = type(name, (base,), {"__module__": __name__})
        return self._cas_types[name]

    def annotator_classes(self) -> list[type[Annotator]]:
        """One Annotator class per generated annotator, declaring its ports and capability."""
        return [
            type(
                spec.name,
                (Annotator,),
                {
                    "__module__": __name__,
                    "__doc__": f"Generated annotator {spec.name}.",
                    "inputs": tuple(map(self.cas_type, spec.inputs)),
                    "optional_inputs": tuple(map(self.cas_type, spec.optional_inputs)),
                    "outputs": tuple(map(self.cas_type, spec.outputs)),
                    "capability": Capability(cost_ms=spec.cost_ms, reliability=spec.reliability),
                },
            )
            for spec in self.annotators
        ]

    def producible(self) -> set[str]:
        """Reference semantics: every type some chain of annotators can produce from the sensors."""
        known = set(self.sensors)
        changed = True
        while changed:
            changed = False
            for spec in self.annotators:
                if set(spec.inputs) <= known and not set(spec.outputs) <= known:
                    known |= set(spec.outputs)
                    changed = True
        return known

    def load(self, folder: Path) -> KnowledgeBase:
        """Write the types into ``folder`` and load them with the generated annotator classes."""
        path = folder / "generated.ttl"
        path.write_text(self.turtle(), encoding="utf-8")
        return KnowledgeBase.load(
            folder / "user.ttl", files=[*shipped_files(), path], annotators=self.annotator_classes()
        )


def random_ontology(
    rng: random.Random, sensors: int = 2, types: int = 8, annotators: int = 10, max_inputs: int = 3
) -> CapabilityOntology:
    """A random capability ontology (cycles and unsatisfiable types included)."""
    sensor_names = tuple(f"S{i}" for i in range(sensors))
    type_names = tuple(f"T{i}" for i in range(types))
    everything = sensor_names + type_names
    specs = []
    for index in range(annotators):
        inputs = tuple(sorted(rng.sample(everything, rng.randint(1, max_inputs))))
        optional = tuple(sorted(set(rng.sample(type_names, rng.randint(0, 1))) - set(inputs)))
        outputs = tuple(sorted(rng.sample(type_names, rng.randint(1, 2))))
        cost = float(rng.randint(1, 50))
        reliability = rng.choice((0.5, 0.7, 0.9, 1.0))
        specs.append(RandomAnnotator(f"A{index}", inputs, optional, outputs, cost, reliability))
    return CapabilityOntology(sensor_names, type_names, tuple(specs))
