"""CAS type filtering, sharing by reference, phi (CAS lookup), declared-port enforcement and failure handling."""

from __future__ import annotations

import numpy as np
import py_trees
import pytest
from py_trees.common import Status

from robokudo import CAS, Engine, Pipeline, PortError, StructureError
from robokudo.core.types import (
    Annotation,
    ColorImage,
    ObjectHypothesis,
    Plane,
    SemanticColor,
    Shape,
    type_by_name,
)
from tests.support import annotator_class, make_instance


def test_filtering_by_type_honours_subclasses() -> None:
    cas = CAS()
    plane, hypothesis = make_instance(Plane), make_instance(ObjectHypothesis)
    cas.add(plane)
    cas.add(hypothesis)
    assert cas.annotations(Plane) == [plane]
    assert cas.annotations(Annotation) == [plane, hypothesis]


def test_views_are_shared_by_reference() -> None:
    image = np.zeros((4, 4, 3), np.uint8)
    cas = CAS()
    cas.set_view(ColorImage(image))
    assert cas.view(ColorImage).image is image


def test_types_are_tied_to_ontology_iris_by_name() -> None:
    assert SemanticColor.iri().endswith("#SemanticColor")
    assert type_by_name("ObjectHypothesis") is ObjectHypothesis
    with pytest.raises(KeyError, match="known"):
        type_by_name("Nonsense")


def test_annotators_in_nested_pipelines_use_their_own_cas_and_reach_others_by_name() -> None:
    outer_writer = annotator_class("OuterWriter", outputs=[Plane])()
    inner_writer = annotator_class("InnerWriter", outputs=[ObjectHypothesis])()
    seen = {}

    def look(self) -> None:
        seen["own"] = self.cas
        seen["outer"] = self.cas_of("outer")

    looker = annotator_class("Looker", work=look)()
    inner = Pipeline("inner", [inner_writer, looker])
    outer = Pipeline("outer", [outer_writer, inner])
    outer.tick_once()
    assert outer.status is Status.SUCCESS
    assert len(outer.cas.annotations(Plane)) == 1 and not outer.cas.annotations(ObjectHypothesis)
    assert len(inner.cas.annotations(ObjectHypothesis)) == 1 and not inner.cas.annotations(Plane)
    assert seen["own"] is inner.cas and seen["outer"] is outer.cas


def test_an_annotator_moved_to_another_pipeline_writes_to_that_pipelines_cas() -> None:
    writer = annotator_class("Writer", outputs=[Plane])()
    group = py_trees.composites.Sequence("group", memory=True, children=[writer])
    first, second = Pipeline("first", [group]), Pipeline("second", [])
    first.tick_once()
    assert len(first.cas.annotations(Plane)) == 1
    first.remove_child(group)
    second.add_child(group)
    second.tick_once()
    assert len(second.cas.annotations(Plane)) == 1
    group.remove_child(writer)
    first.add_child(writer)
    first.tick_once()
    assert len(first.cas.annotations(Plane)) == 1 and writer.cas is first.cas


def test_cross_pipeline_lookup_of_unknown_name_lists_the_pipelines() -> None:
    def look(self) -> None:
        self.cas_of("nowhere")

    with pytest.raises(StructureError, match=r"'L': no Pipeline named 'nowhere'.*pipelines: p"):
        Pipeline("p", [annotator_class("L", work=look)()]).tick_once()


def test_annotator_outside_any_pipeline_is_reported_when_the_tree_is_built() -> None:
    orphan = annotator_class("Orphan", outputs=[Plane])()
    root = py_trees.composites.Sequence("root", memory=True, children=[Pipeline("p", []), orphan])
    with pytest.raises(StructureError, match=r"'Orphan' .* is not inside any Pipeline"):
        Engine(root)


def test_duplicate_pipeline_names_are_rejected() -> None:
    root = py_trees.composites.Sequence("root", memory=True, children=[Pipeline("p"), Pipeline("p")])
    with pytest.raises(StructureError, match="repeated: p"):
        Engine(root)


def test_reading_an_undeclared_input_raises_naming_annotator_and_type() -> None:
    def read_plane(self) -> None:
        self.annotations(Plane)

    sneaky = annotator_class("Sneaky", inputs=[ObjectHypothesis], work=read_plane)()
    with pytest.raises(PortError, match=r"'Sneaky'.*read Plane.*declared inputs \(ObjectHypothesis\)"):
        Pipeline("p", [sneaky]).tick_once()


def test_writing_an_undeclared_output_raises_naming_annotator_and_type() -> None:
    def write_shape(self) -> None:
        self.write(Shape(shape="box"))

    liar = annotator_class("Liar", outputs=[SemanticColor], work=write_shape)()
    with pytest.raises(PortError, match=r"'Liar'.*wrote Shape.*declared outputs \(SemanticColor\)"):
        Pipeline("p", [liar]).tick_once()


def test_failing_annotator_reports_reason_and_commits_nothing() -> None:
    def half_then_fail(self) -> None:
        self.write(make_instance(Plane))
        self.fail("depth image is all zero")

    broken = annotator_class("Broken", outputs=[Plane], work=half_then_fail)()
    after = annotator_class("After", outputs=[ObjectHypothesis])()
    fallback = py_trees.composites.Selector("either", memory=False, children=[broken, after])
    pipeline = Pipeline("p", [fallback])
    pipeline.tick_once()
    assert broken.status is Status.FAILURE
    assert broken.feedback_message == "depth image is all zero"
    assert pipeline.cas.annotations(Plane) == []  # nothing half-written
    assert pipeline.status is Status.SUCCESS  # the tree went on


def test_a_crashing_annotator_fails_with_the_exception_as_reason() -> None:
    def crash(self) -> None:
        raise ValueError("bad shape (0, 3)")

    crasher = annotator_class("Crasher", outputs=[Plane], work=crash)()
    Pipeline("p", [crasher]).tick_once()
    assert crasher.status is Status.FAILURE
    assert crasher.feedback_message == "ValueError: bad shape (0, 3)"


def test_missing_view_fails_with_reason() -> None:
    def need_image(self) -> None:
        self.view(ColorImage)

    needy = annotator_class("Needy", inputs=[ColorImage], work=need_image)()
    Pipeline("p", [needy]).tick_once()
    assert needy.status is Status.FAILURE and "no ColorImage in the CAS" in needy.feedback_message


def test_pipeline_starts_each_run_on_a_fresh_cas() -> None:
    pipeline = Pipeline("p", [annotator_class("W", outputs=[Plane])()])
    pipeline.tick_once()
    first = pipeline.cas
    pipeline.tick_once()
    assert pipeline.cas is not first and len(pipeline.cas.annotations(Plane)) == 1
