"""Random capability ontologies for planner property tests and benchmarks, written as Turtle and loaded by the
real KnowledgeBase.

Types ``S0..`` are sensor views (what the reader supplies), ``T0..`` annotation types; each annotator has a
few required inputs, sometimes an optional input, and one or two outputs.
"""

from __future__ import annotations

import random
from dataclasses import dataclass
from pathlib import Path

from ontology import shipped_files
from reasoning.knowledge.knowledge_base import KnowledgeBase

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

    def turtle(self) -> str:
        """The ontology as Turtle (types as CAS classes, annotators as individuals)."""
        lines = [PREFIXES]
        for sensor in self.sensors:
            lines.append(f'rk:{sensor} a owl:Class ; rdfs:subClassOf rk:View ; rdfs:label "{sensor.lower()}" .\n')
        for type_name in self.types:
            lines.append(
                f'rk:{type_name} a owl:Class ; rdfs:subClassOf rk:Annotation ; rdfs:label "{type_name.lower()}" .\n'
            )
        for spec in self.annotators:
            lines.append(f"rk:{spec.name} a owl:NamedIndividual , rk:Annotator ;\n")
            lines.append(f'    rk:implementedBy "annotators.generated.{spec.name}" ;\n')
            if spec.inputs:
                lines.append(f"    rk:requiresInput {' , '.join('rk:' + t for t in spec.inputs)} ;\n")
            if spec.optional_inputs:
                lines.append(f"    rk:optionalInput {' , '.join('rk:' + t for t in spec.optional_inputs)} ;\n")
            lines.append(f"    rk:providesOutput {' , '.join('rk:' + t for t in spec.outputs)} ;\n")
            lines.append(f"    rk:expectedCostMs {spec.cost_ms:.1f} ;\n    rk:reliability {spec.reliability:.2f} .\n")
        return "".join(lines)

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
        """Write the ontology into ``folder`` and load it with the real KnowledgeBase."""
        path = folder / "generated.ttl"
        path.write_text(self.turtle(), encoding="utf-8")
        return KnowledgeBase.load(folder / "user.ttl", files=[*shipped_files(), path])


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
