"""Property tests of tree semantics: the threshold Parallel over random children and thresholds, and the
data-flow validator against execution of random Sequence/Fallback trees."""

from __future__ import annotations

import py_trees
from hypothesis import given, settings
from hypothesis import strategies as st
from py_trees.common import Status

from robokudo import Pipeline, ThresholdParallel, data_flow_violations
from tests.support import Scripted, annotator_class, marker_type

S, F, R = Status.SUCCESS, Status.FAILURE, Status.RUNNING

scripts = st.lists(st.tuples(st.integers(0, 3), st.sampled_from([S, F])), min_size=1, max_size=6)


@settings(max_examples=200, deadline=None)
@given(children=scripts, data=st.data())
def test_threshold_parallel_follows_its_rule_tick_by_tick(children: list[tuple[int, Status]], data) -> None:
    n = len(children)
    n_success = data.draw(st.integers(0, n))
    n_failure = data.draw(st.integers(0, n))
    nodes = [Scripted(f"c{i}", [R] * running + [final]) for i, (running, final) in enumerate(children)]
    parallel = ThresholdParallel("p", nodes, n_success=n_success, n_failure=n_failure)
    for _ in range(10):
        parallel.tick_once()
        finished = [
            (running, final) for (running, final), node in zip(children, nodes, strict=True) if node.updates > running
        ]
        succeeded = sum(final is S for _, final in finished)
        failed = sum(final is F for _, final in finished)
        if failed > n_failure:
            expected = F
        elif succeeded > n_success:
            expected = S
        elif len(finished) == n:
            expected = F  # every child finished without crossing a threshold
        else:
            expected = R
        assert parallel.status is expected
        for (running, _), node in zip(children, nodes, strict=True):
            assert node.updates <= running + 1  # a finished child is never ticked again within the run
        if expected is not R:
            assert all(node.status is not R for node in nodes)  # nothing dangles
            break


Types = [marker_type(f"T{i}") for i in range(4)]
leaf_ports = st.tuples(st.sets(st.integers(0, 3), max_size=2), st.sets(st.integers(0, 3), max_size=2))


def trees(depth: int) -> st.SearchStrategy:
    leaf = leaf_ports.map(lambda ports: ("leaf", ports))
    if depth == 0:
        return leaf
    branch = st.tuples(st.sampled_from(["seq", "fallback"]), st.lists(trees(depth - 1), min_size=1, max_size=3))
    return st.one_of(leaf, branch)


def build(spec, counter: list[int]) -> py_trees.behaviour.Behaviour:
    kind, body = spec
    if kind == "leaf":
        counter[0] += 1
        inputs, outputs = body
        cls = annotator_class(f"A{counter[0]}", [Types[i] for i in sorted(inputs)], [Types[i] for i in sorted(outputs)])
        return cls()
    children = [build(child, counter) for child in body]
    if kind == "seq":
        return py_trees.composites.Sequence(f"s{counter[0]}", memory=True, children=children)
    return py_trees.composites.Selector(f"f{counter[0]}", memory=True, children=children)


def outcomes(spec, available: frozenset[int]) -> list[tuple[bool, frozenset[int], bool]]:
    """Every execution: (succeeded, types present afterwards, some leaf read a type not present)."""
    kind, body = spec
    if kind == "leaf":
        inputs, outputs = body
        bad = not inputs <= available
        return [(True, available | frozenset(outputs), bad), (False, available, bad)]
    results = [(True, available, False)]
    if kind == "seq":
        for child in body:
            extended = []
            for ok, present, bad in results:
                if not ok:
                    extended.append((ok, present, bad))
                    continue
                for child_ok, child_present, child_bad in outcomes(child, present):
                    extended.append((child_ok, child_present, bad or child_bad))
            results = extended
        return results
    results = [(False, available, False)]
    for child in body:
        extended = []
        for ok, present, bad in results:
            if ok:
                extended.append((ok, present, bad))
                continue
            for child_ok, child_present, child_bad in outcomes(child, present):
                extended.append((child_ok, child_present, bad or child_bad))
        results = extended
    return results


@settings(max_examples=200, deadline=None)
@given(spec=trees(3))
def test_validator_accepts_exactly_the_trees_where_every_path_reads_what_was_written(spec) -> None:
    tree = Pipeline("p", [build(spec, [0])])
    unsafe = any(bad for _, _, bad in outcomes(spec, frozenset()))
    assert bool(data_flow_violations(tree)) == unsafe
