"""Single source of truth: the ontology's annotators and the annotator classes in code must agree."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

from ontology import ontology_dir
from reasoning.knowledge.capabilities import ImplementationError, check_implementations, load_implementation
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.model import AnnotatorSpec
from tests.reasoning.helpers import shipped_without, write_ttl


def test_shipped_ontology_and_annotator_code_agree(kb: KnowledgeBase) -> None:
    problems = check_implementations(kb)
    assert problems == [], "\n".join(problems)


def test_every_declared_annotator_names_an_annotators_module(kb: KnowledgeBase) -> None:
    assert kb.annotators()
    for spec in kb.annotators():
        assert spec.module.startswith("annotators."), spec


def test_ports_that_disagree_are_reported(tmp_path: Path) -> None:
    extra = write_ttl(
        tmp_path / "wrong.ttl",
        """rk:WrongRangeFilter a owl:NamedIndividual , rk:Annotator ;
    rk:implementedBy "annotators.cloud.filters.RangeFilter" ;
    rk:requiresInput rk:DepthImage ;
    rk:providesOutput rk:PointCloud , rk:Plane ;
    rk:expectedCostMs 1.0 ;
    rk:reliability 1.0 .
""",
    )
    kb = KnowledgeBase.load(tmp_path / "user.ttl", extra_files=[extra])
    problems = "\n".join(check_implementations(kb))
    assert re.search(r"annotators\.cloud\.filters\.RangeFilter: inputs disagree: code has \[PointCloud\]", problems)
    assert re.search(
        r"RangeFilter: outputs disagree: code has \[PointCloud\], ontology .* \[Plane, PointCloud\]", problems
    )


def test_declared_annotator_without_implementation_is_reported(tmp_path: Path) -> None:
    extra = write_ttl(
        tmp_path / "ghost.ttl",
        """rk:GhostFilter a owl:NamedIndividual , rk:Annotator ;
    rk:implementedBy "annotators.cloud.filters.GhostFilter" ;
    rk:requiresInput rk:PointCloud ;
    rk:providesOutput rk:PointCloud ;
    rk:expectedCostMs 1.0 ;
    rk:reliability 1.0 .
""",
    )
    kb = KnowledgeBase.load(tmp_path / "user.ttl", extra_files=[extra])
    assert any("GhostFilter" in p and "no class" in p for p in check_implementations(kb))


def test_annotator_class_missing_from_the_ontology_is_reported(tmp_path: Path) -> None:
    text = (ontology_dir() / "annotators.ttl").read_text(encoding="utf-8")
    block = re.search(r"\nrk:RangeFilter a owl:NamedIndividual.*?\.\n", text, flags=re.DOTALL)
    assert block is not None
    reduced = tmp_path / "annotators.ttl"
    reduced.write_text(text.replace(block.group(0), "\n"), encoding="utf-8")
    kb = KnowledgeBase.load(tmp_path / "user.ttl", files=[*shipped_without("annotators.ttl"), reduced])
    assert "RangeFilter" not in {s.name for s in kb.annotators()}
    problems = check_implementations(kb)
    assert any("annotators.cloud.filters.RangeFilter" in p and "does not declare" in p for p in problems)


def test_load_implementation_refuses_modules_outside_annotators() -> None:
    spec = AnnotatorSpec(
        name="Evil",
        implemented_by="evil_module_for_this_test.Evil",
        inputs=(),
        optional_inputs=(),
        outputs=("Text",),
        colors=frozenset(),
        shapes=frozenset(),
        sizes=frozenset(),
        materials=frozenset(),
        classes=frozenset(),
        preconditions=(),
        cost_ms=1.0,
        reliability=1.0,
    )
    with pytest.raises(ImplementationError, match="outside the 'annotators' package"):
        load_implementation(spec)
    assert "evil_module_for_this_test" not in sys.modules
