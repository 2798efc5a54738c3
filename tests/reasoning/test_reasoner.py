"""HermiT: classification on load, the Java-missing fallback, and questions that never reason or parse."""

from __future__ import annotations

import logging
import re
from pathlib import Path

import pytest

from reasoning.errors import InconsistentOntologyError
from reasoning.knowledge import hermit, knowledge_base, sources
from reasoning.knowledge.knowledge_base import KnowledgeBase
from robokudo.application.knowledge import load_knowledge_base
from tests.reasoning.helpers import write_ttl


@pytest.mark.slow
def test_reasoned_load_adds_inferred_subsumptions(tmp_path: Path) -> None:
    asserted = KnowledgeBase.load(tmp_path / "user.ttl")
    reasoned = KnowledgeBase.load(tmp_path / "user.ttl", reason=True)
    result = reasoned.reasoner_result
    assert result is not None and result.ok
    assert result.message.startswith("HermiT: consistent")
    # defined classes: "stored in some Fridge" and "transparent value true"
    assert reasoned.is_subclass("Milk", "RefrigeratedItem")
    assert reasoned.is_subclass("LactoseFreeMilk", "RefrigeratedItem")
    assert not asserted.is_subclass("Milk", "RefrigeratedItem")
    assert {"Glass", "WineGlass", "Jar", "GlassBottle"} <= set(reasoned.subclasses("TransparentObject"))
    assert asserted.subclasses("TransparentObject") == []
    # the asserted hierarchy is kept
    assert reasoned.is_subclass("WholeMilk", "Milk")
    assert reasoned.default_location("SkimMilk") == "Fridge"


@pytest.mark.slow
def test_reasoned_load_rejects_an_unsatisfiable_class(tmp_path: Path) -> None:
    extra = write_ttl(tmp_path / "bad.ttl", "rk:SpoonCup a owl:Class ; rdfs:subClassOf rk:Spoon , rk:Cup .\n")
    assert KnowledgeBase.load(tmp_path / "user.ttl", extra_files=[extra]).is_subclass("SpoonCup", "Cup")
    with pytest.raises(InconsistentOntologyError, match="SpoonCup can have no instances according to HermiT"):
        KnowledgeBase.load(tmp_path / "user.ttl", extra_files=[extra], reason=True)


@pytest.mark.slow
def test_no_class_has_a_handle_and_none_at_once(tmp_path: Path) -> None:
    """An object has a handle or has none: with rk:hasHandle functional, HermiT would find a class that inherits
    both values unsatisfiable. None does: not a mug or a pitcher (below a container that once declared "no
    handle"), nor a jug (the bottle with a handle, below a bottle that once declared none)."""
    extra = write_ttl(tmp_path / "functional.ttl", "rk:hasHandle a owl:FunctionalProperty .\n")
    reasoned = KnowledgeBase.load(tmp_path / "user.ttl", extra_files=[extra], reason=True)
    assert reasoned.is_subclass("Jug", "Bottle") and reasoned.is_subclass("Mug", "Cup")


@pytest.mark.slow
def test_a_class_given_a_handle_and_none_is_rejected(tmp_path: Path) -> None:
    """The check above can fail: a bottle with a handle below the glass bottle (which has none) is caught."""
    extra = write_ttl(
        tmp_path / "functional.ttl",
        "rk:hasHandle a owl:FunctionalProperty .\n"
        "rk:HandledGlassBottle a owl:Class ; rdfs:subClassOf rk:GlassBottle ,\n"
        "    [ a owl:Restriction ; owl:onProperty rk:hasHandle ; owl:hasValue true ] .\n",
    )
    with pytest.raises(InconsistentOntologyError) as rejected:
        KnowledgeBase.load(tmp_path / "user.ttl", extra_files=[extra], reason=True)
    assert set(re.findall(r"(\w+) can have no instances", str(rejected.value))) == {"HandledGlassBottle"}


def test_without_java_loading_says_so_and_keeps_the_asserted_hierarchy(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    monkeypatch.setattr(hermit, "find_java", lambda: None)
    with caplog.at_level(logging.WARNING):
        kb = KnowledgeBase.load(tmp_path / "user.ttl", reason=True)
    assert "Java was not found" in caplog.text
    result = kb.reasoner_result
    assert result is not None and not result.available
    assert "default-jre-headless" in result.message
    assert kb.is_subclass("WholeMilk", "Milk")
    assert not kb.is_subclass("Milk", "RefrigeratedItem")


def test_questions_never_parse_files_or_run_the_reasoner(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    kb = load_knowledge_base(tmp_path / "user.ttl")

    def forbidden(*_: object, **__: object) -> None:
        raise AssertionError("a question parsed a file or ran the reasoner")

    monkeypatch.setattr(knowledge_base, "parse_turtle", forbidden)
    monkeypatch.setattr(knowledge_base, "classify", forbidden)
    monkeypatch.setattr(sources, "parse_turtle", forbidden)
    monkeypatch.setattr(hermit, "classify", forbidden)
    assert kb.resolve("cereal boxes").name == "CerealBox"
    assert kb.is_subclass("SkimMilk", "Drink")
    assert kb.default_location("milk") == "Fridge"
    assert kb.object_profile("Glass").transparent is True
    assert kb.regions_of_class("Fridge")
    assert kb.providers("SemanticColor", value="red")
    assert kb.annotation_type_for_key("color") == "SemanticColor"
    assert kb.inputs_of("ClusterExtractor")
    assert kb.variants_differ_by_text("LactoseFreeMilk")
    assert kb.subclasses("Milk") and kb.superclasses("Milk")
    assert not kb.reload_if_changed()
