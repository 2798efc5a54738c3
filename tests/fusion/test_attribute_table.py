"""The annotation types' attribute table (robokudo.core.types) drives fusion, answers and belief filters."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from queries import Block, Field, Query, String, Symbol
from reasoning.beliefs.answer import designator
from reasoning.beliefs.filters import FILTERED_TYPES, belief_filter
from reasoning.beliefs.store import BeliefFilter, BeliefStore
from reasoning.fusion.frame import FUSED_TYPES, FrameContext, frame_objects, hypothesis_evidence
from reasoning.knowledge.knowledge_base import KnowledgeBase
from robokudo.core import types
from robokudo.core.types import (
    ANNOTATION_TYPES,
    ATTRIBUTE_TYPES,
    VIEW_TYPES,
    Annotation,
    Classification,
    Location,
    ObjectHypothesis,
    Pose,
    SemanticColor,
    Shape,
    Size,
    Text,
    View,
    attribute_type,
)
from trees.answer_step import AnswerStep

STATED: dict[type[Annotation], tuple[Annotation, str]] = {
    SemanticColor: (SemanticColor(color=" Red ", source="Color"), "red"),
    Shape: (Shape(shape="Box", source="Shape"), "box"),
    Size: (Size(dimensions=(0.2, 0.1, 0.1), size_class="Medium", source="Size"), "medium"),
    Classification: (Classification(class_name="Milk", source="Classifier"), "Milk"),
    Text: (Text(text="MILK\n lactose  free", source="Reader"), "MILK lactose free"),
    Location: (Location(region="Fridge", source="Locator"), "fridge"),
}
"""One annotation of every attribute type and the value fusion reads from it."""


@pytest.fixture(scope="module")
def kb() -> KnowledgeBase:
    return KnowledgeBase.load(Path("/nonexistent/user.ttl"))


def hypothesis(*annotations: Annotation) -> ObjectHypothesis:
    found = ObjectHypothesis(point_indices=np.arange(4), mask=np.ones((2, 2), bool), roi=(0, 0, 2, 2))
    pose = Pose(position=np.array([1.3, 0.85, 1.0]), orientation=np.array([0.0, 0.0, 0.0, 1.0]), frame="world")
    found.annotations += [pose, *annotations]
    return found


def test_the_registries_are_the_class_hierarchy() -> None:
    declared = [c for c in vars(types).values() if isinstance(c, type) and c.__module__ == types.__name__]
    assert set(VIEW_TYPES) == {c for c in declared if issubclass(c, View) and c is not View}
    assert set(ANNOTATION_TYPES) == {c for c in declared if issubclass(c, Annotation) and c is not Annotation}
    assert tuple(STATED) == ATTRIBUTE_TYPES  # declaration order is the order of fused evidence
    assert all(attribute_type(t.attribute) is t for t in ATTRIBUTE_TYPES)
    assert set(AnswerStep.optional_inputs) >= set(FUSED_TYPES) >= set(ATTRIBUTE_TYPES)


def test_every_attribute_type_answers_the_ontology_query_key_of_its_attribute_name(kb: KnowledgeBase) -> None:
    for annotation_type in ATTRIBUTE_TYPES:
        assert kb.annotation_type_for_key(annotation_type.attribute) == annotation_type.type_name()


@pytest.mark.parametrize("annotation_type", ATTRIBUTE_TYPES, ids=lambda t: t.__name__)
def test_the_table_drives_fusion_and_the_answer_json(annotation_type: type[Annotation], tmp_path: Path) -> None:
    annotation, value = STATED[annotation_type]
    (evidence,) = hypothesis_evidence(hypothesis(annotation))
    assert (evidence.attribute, evidence.value, evidence.source) == (
        annotation_type.attribute,
        value,
        annotation.source,
    )
    with BeliefStore(tmp_path / "beliefs.sqlite") as store:
        store.integrate(frame_objects([hypothesis(annotation)], FrameContext()), 1.0)
        (belief,) = store.query(BeliefFilter())
        shown = designator(belief).to_dict()
    assert shown["attributes"][annotation_type.attribute]["value"] == value
    if annotation_type is Classification:
        assert shown["class"]["iri"].endswith("#Milk")
    if annotation_type is Size:
        assert shown["size"]["class"] == value
    if annotation_type is Location:
        assert shown["region"] == value


def query_with(key: str, value: str) -> Query:
    """A detect query whose body holds one ``key: value`` field (a word value)."""
    return Query(kind="detect", body=Block((Field(key, Symbol(value) if " " not in value else String(value)),)))


@pytest.mark.parametrize("annotation_type", FILTERED_TYPES, ids=lambda t: t.__name__)
def test_the_table_drives_the_belief_filter(annotation_type: type[Annotation], kb: KnowledgeBase) -> None:
    _, value = STATED[annotation_type]
    without_kb = belief_filter(query_with(annotation_type.attribute, value))
    assert without_kb.attributes == {annotation_type.attribute: value}
    kind = kb.value_kind(annotation_type.type_name())
    expected = value if kind is None else kb.resolve(value, (kind,)).name
    for key, answered_by in kb.query_keys().items():
        if answered_by == annotation_type.type_name() and " " not in key:
            assert belief_filter(query_with(key, value), kb).attributes == {annotation_type.attribute: expected}
