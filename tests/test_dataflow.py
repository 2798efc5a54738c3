"""The static data-flow validator."""

from __future__ import annotations

import py_trees
import pytest

from robokudo import DataFlowError, Engine, Pipeline, ThresholdParallel, data_flow_violations, validate_data_flow
from tests.support import annotator_class, marker_type

Cloud, Hyp, Color = marker_type("Cloud"), marker_type("Hyp"), marker_type("Color")


def make(name, inputs=(), outputs=()):
    return annotator_class(name, inputs, outputs)()


def test_valid_chain_is_accepted() -> None:
    tree = Pipeline("p", [make("Gen", outputs=[Cloud]), make("Seg", [Cloud], [Hyp]), make("Col", [Hyp], [Color])])
    validate_data_flow(tree)
    Engine(tree)


def test_consumer_before_producer_is_rejected_in_words() -> None:
    tree = Pipeline("p", [make("Seg", [Cloud], [Hyp]), make("Gen", outputs=[Cloud])])
    with pytest.raises(DataFlowError, match="Seg reads Cloud, but its producer Gen does not run before it"):
        validate_data_flow(tree)
    with pytest.raises(DataFlowError):
        Engine(tree)


def test_producer_in_only_one_branch_of_a_fallback_is_rejected() -> None:
    fallback = py_trees.composites.Selector(
        "segmenters", memory=False, children=[make("SegA", outputs=[Hyp]), make("Other", outputs=[Cloud])]
    )
    tree = Pipeline("p", [fallback, make("Col", [Hyp], [Color])])
    with pytest.raises(DataFlowError, match="only in one branch of Fallback 'segmenters'"):
        validate_data_flow(tree)


def test_producer_in_every_branch_of_a_fallback_is_accepted() -> None:
    fallback = py_trees.composites.Selector(
        "segmenters", memory=False, children=[make("SegA", outputs=[Hyp]), make("SegB", outputs=[Hyp])]
    )
    validate_data_flow(Pipeline("p", [fallback, make("Col", [Hyp], [Color])]))


def test_siblings_in_a_parallel_cannot_feed_each_other() -> None:
    parallel = ThresholdParallel("both", [make("Seg", outputs=[Hyp]), make("Col", [Hyp], [Color])])
    assert data_flow_violations(Pipeline("p", [parallel]))


def test_parallel_guarantees_outputs_only_of_children_it_needs() -> None:
    # one success out of two is enough: neither child's output is guaranteed afterwards
    lenient = ThresholdParallel("any", [make("A", outputs=[Hyp]), make("B", outputs=[Cloud])], n_success=0, n_failure=1)
    assert data_flow_violations(Pipeline("p", [lenient, make("Use", [Hyp])]))
    strict = ThresholdParallel("all", [make("A", outputs=[Hyp]), make("B", outputs=[Cloud])])
    validate_data_flow(Pipeline("p", [strict, make("Use", [Hyp, Cloud])]))


def test_nested_pipeline_has_its_own_cas() -> None:
    inner = Pipeline("inner", [make("Col", [Hyp], [Color])])
    tree = Pipeline("outer", [make("Seg", outputs=[Hyp]), inner])
    with pytest.raises(DataFlowError, match="nothing in Pipeline 'inner' produces it"):
        validate_data_flow(tree)


def test_subtypes_satisfy_inputs() -> None:
    special = marker_type("SpecialHyp")
    special_hyp = type("SpecialHyp2", (Hyp,), {})
    tree = Pipeline("p", [make("Seg", outputs=[special_hyp]), make("Col", [Hyp], [Color])])
    validate_data_flow(tree)
    assert data_flow_violations(Pipeline("p", [make("Seg", outputs=[special]), make("Col", [Hyp])]))


def test_fallback_branches_writing_a_type_or_its_subtype_guarantee_the_type() -> None:
    special = type("SpecialHyp3", (Hyp,), {})
    fallback = py_trees.composites.Selector(
        "segmenters", memory=False, children=[make("SegA", outputs=[special]), make("SegB", outputs=[Hyp])]
    )
    validate_data_flow(Pipeline("p", [fallback, make("Col", [Hyp], [Color])]))
    # the subtype itself is written in one branch only
    fallback = py_trees.composites.Selector(
        "segmenters", memory=False, children=[make("SegA", outputs=[special]), make("SegB", outputs=[Hyp])]
    )
    with pytest.raises(DataFlowError, match="only in one branch of Fallback 'segmenters'"):
        validate_data_flow(Pipeline("p", [fallback, make("Use", [special])]))
