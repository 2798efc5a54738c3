"""Digests of the plans for a fixed set of random queries over the shipped ontology, to show plans unchanged.

``plans_shipped.json`` beside this file holds the queries and the digest of each one's plan (or planning error),
for two sensor sources: the default one and the kitchen reader without depth and camera pose. It was written by the
planner before it was made fast; write it again only when a change of the plans is intended:

    PYTHONPATH=. python tests/planning/plan_digests.py --write
"""

from __future__ import annotations

import hashlib
import json
import random
import sys
import tempfile
from pathlib import Path

from queries import parse_query
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.plan import Step
from reasoning.planning.planner import PlanningError, SensorSource
from reasoning.planning.query_planner import QueryPlan, plan_query

GOLDEN = Path(__file__).with_name("plans_shipped.json")
DEPTH_TYPES = ("DepthImage", "PointCloud")


def random_queries(kb: KnowledgeBase, count: int, seed: int = 11) -> list[str]:
    """``count`` queries over the ontology's classes, colours, shapes and regions (some unsatisfiable)."""
    rng = random.Random(seed)
    classes = kb.names_of_kind("class")
    colors = [kb.label(c) for c in kb.names_of_kind("color")]
    shapes = [kb.label(c) for c in kb.names_of_kind("shape")]
    regions = kb.names_of_kind("region")
    texts = []
    for _ in range(count):
        fields = [f"type: {rng.choice(classes)}"] if rng.random() < 0.85 else []
        if rng.random() < 0.5 or not fields:
            fields.append(f"color: {rng.choice(colors)}")
        if rng.random() < 0.3:
            fields.append(f"shape: {rng.choice(shapes)}")
        if rng.random() < 0.3:
            fields.append(f"location: {{ in: {rng.choice(regions)} }}")
        if rng.random() < 0.2:
            fields.append("transparent: true")
        if rng.random() < 0.2:
            fields.append('text: "milk"')
        texts.append(f"{rng.choice(['detect', 'inspect', 'track'])} {{ obj: {{ {', '.join(fields)} }} }}")
    return texts


def sources(kb: KnowledgeBase) -> dict[str, SensorSource]:
    """The kitchen reader as it is, and without depth and camera pose."""
    reader = kb.annotator("KitchenSceneReader")
    full = SensorSource(Step(reader.name, reader.implemented_by, (), reader.outputs, (), "reads"))
    flat = tuple(t for t in reader.outputs if t not in DEPTH_TYPES)
    bare = SensorSource(Step(reader.name, reader.implemented_by, (), flat, (), "reads"), camera_pose=False)
    return {"kitchen": full, "no depth, no pose": bare}


def canonical(result: QueryPlan) -> str:
    """The plan and its interpretation as text that does not depend on set order (hash seeds)."""
    plan = result.plan
    interpretation = result.interpretation
    parts = [
        repr(plan.task),
        repr(plan.stages),
        repr(sorted(plan.sensor_types)),
        repr(interpretation.requirements),
        repr(interpretation.region_box.name if interpretation.region_box else None),
        repr(interpretation.transparent),
    ]
    return "\n".join(parts)


def digest(kb: KnowledgeBase, text: str, source: SensorSource) -> str:
    """sha256 of the canonical plan of ``text``, or the planning error's message."""
    try:
        outcome = canonical(plan_query(parse_query(text), kb, source))
    except PlanningError as error:
        outcome = f"PlanningError: {error}"
    return hashlib.sha256(outcome.encode()).hexdigest()


def write(count: int = 150) -> None:
    """Write the golden file with the current planner."""
    from robokudo.application.knowledge import load_knowledge_base

    kb = load_knowledge_base(Path(tempfile.mkdtemp()) / "user.ttl")
    entries = {
        name: {text: digest(kb, text, source) for text in random_queries(kb, count)}
        for name, source in sources(kb).items()
    }
    GOLDEN.write_text(json.dumps(entries, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    print(f"wrote {sum(map(len, entries.values()))} digests to {GOLDEN}")


if __name__ == "__main__":
    if sys.argv[1:] != ["--write"]:
        sys.exit(__doc__)
    write()
