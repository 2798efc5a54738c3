"""Adding an expert touches one place: a new Annotator class in a module of its own.

The class declares its ports and its Capability; loading the knowledge base with it makes the planner use it,
and a catalog with it builds and runs the tree. No Turtle file and no other file of the project is edited.
"""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest
from py_trees.common import Status

from annotators.catalog import AnnotatorCatalog
from queries import parse_query
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.query_planner import plan_query
from robokudo.application.sensor_sources import sensor_source
from robokudo.application.service import AnsweringService
from robokudo.core.annotator import Annotator
from robokudo.core.engine import Engine
from robokudo.core.types import ObjectHypothesis, SemanticColor
from trees.synthesis import SynthesisError, build_tree

QUERY = "detect { obj: { color: teal } }"  # no shipped expert can report teal (asked as blue or green)

EXPERT_MODULE = '''
"""A user's own expert, in a module of its own."""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from robokudo.core.annotator import Annotator
from robokudo.core.capability import Capability
from robokudo.core.types import CasType, ColorImage, ObjectHypothesis, SemanticColor


class TealSpotter(Annotator):
    """Says how teal each object hypothesis is: the share of its pixels with a blue-green colour."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (ObjectHypothesis, ColorImage)
    outputs: ClassVar[tuple[type[CasType], ...]] = (SemanticColor,)
    capability: ClassVar[Capability] = Capability(
        label="teal spotter", colors=("Teal",), cost_ms=1.0, reliability=0.9
    )

    def analyse(self) -> None:
        image = self.view(ColorImage).image.astype(np.int16)
        hypotheses = self.annotations(ObjectHypothesis)
        if not hypotheses:
            self.fail("no object hypotheses")
        for hypothesis in hypotheses:
            pixels = image[hypothesis.mask]
            red, green, blue = pixels[:, 0], pixels[:, 1], pixels[:, 2]
            teal = (green > red + 30) & (blue > red + 30)
            share = float(teal.mean()) if len(pixels) else 0.0
            self.attach(hypothesis, SemanticColor(color="teal", ratio=share, confidence=share))
'''


@pytest.fixture()
def teal_spotter(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> type:
    """The new expert class, imported from a module written for this test."""
    (tmp_path / "my_teal_expert.py").write_text(EXPERT_MODULE, encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    return importlib.import_module("my_teal_expert").TealSpotter


def test_a_new_expert_class_is_planned_built_and_run(tmp_path: Path, teal_spotter: type) -> None:
    query = parse_query(QUERY)
    shipped = KnowledgeBase.load(tmp_path / "user.ttl", annotators=AnnotatorCatalog.discover().values())
    asked_as_basic = plan_query(query, shipped, sensor_source(shipped, None)).plan
    assert "SemanticColorAnnotator" in asked_as_basic.annotator_names()  # no shipped expert says teal
    assert any("asked as blue or green" in note for note in asked_as_basic.task.inferences)

    kb = KnowledgeBase.load(tmp_path / "user.ttl", annotators=[*AnnotatorCatalog.discover().values(), teal_spotter])
    spec = kb.annotator("TealSpotter")
    assert spec.colors == {"Teal"} and spec.implemented_by == "my_teal_expert.TealSpotter"
    plan = plan_query(query, kb, sensor_source(kb, None)).plan
    assert "TealSpotter" in plan.annotator_names()
    assert not any("asked as" in note for note in plan.task.inferences)  # an expert says teal: asked as it is

    pipeline = build_tree(plan, query=query, catalog=AnnotatorCatalog.discover(extra=[teal_spotter]))
    (expert,) = [node for node in pipeline.iterate() if isinstance(node, teal_spotter)]
    status = Engine(pipeline, hz=200.0).run(ticks=4000, until=lambda s: s is not Status.RUNNING)

    assert status is Status.SUCCESS, [(n.name, n.feedback_message) for n in pipeline.iterate()]
    assert expert.status is Status.SUCCESS
    hypotheses = pipeline.cas.annotations(ObjectHypothesis)
    assert hypotheses
    for hypothesis in hypotheses:
        (colour,) = [c for c in hypothesis.find(SemanticColor) if c.source == "TealSpotter"]
        assert colour.color == "teal" and 0.0 <= colour.ratio <= 1.0


def test_a_plan_naming_a_class_missing_from_the_catalog_is_a_synthesis_error(
    tmp_path: Path, teal_spotter: type
) -> None:
    kb = KnowledgeBase.load(tmp_path / "user.ttl", annotators=[*AnnotatorCatalog.discover().values(), teal_spotter])
    plan = plan_query(parse_query(QUERY), kb, sensor_source(kb, None)).plan
    with pytest.raises(SynthesisError, match="no annotator class called 'TealSpotter' in the catalog"):
        build_tree(plan)  # the default catalog holds only the annotators package
    impostor = type("TealSpotter", (Annotator,), {"__module__": __name__, "outputs": (SemanticColor,)})
    with pytest.raises(SynthesisError, match=r"the plan was made for my_teal_expert\.TealSpotter"):
        build_tree(plan, catalog=AnnotatorCatalog.discover(extra=[impostor]))


def test_the_answering_service_answers_with_the_new_expert(
    tmp_path: Path, teal_spotter: type, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    catalog = AnnotatorCatalog.discover(extra=[teal_spotter])
    with AnsweringService.open(tmp_path / "beliefs.sqlite", catalog=catalog) as service:
        outcome = service.answer(QUERY)
    (expert,) = [node for node in outcome.tree.iterate() if isinstance(node, teal_spotter)]
    assert expert.status is Status.SUCCESS
    assert "TealSpotter" in outcome.plan.plan.annotator_names()
