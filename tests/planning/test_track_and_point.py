"""Track and detect (the paper's Fig. 7): following a person while watching what she points at.

``track { human: {}, pointing: { target: region } }`` and the phrase "follow the person and watch where she
points" plan one tree: the planner chains the tracker and the pointing experts from their declarations, and the
synthesis runs the tracker branch and the pointing unit (``trees.pointing``) side by side in a Parallel. Run on
the kitchen camera while the figure walks and then points at the fridge, every run of the loop answers with the
track, and the answers name the fridge once she points.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from annotators.image.human_pose import PoseModelError, load_pose_model
from annotators.readers.streams import KitchenCameraStream
from annotators.simulation.kitchen_person import Motion, PersonScript
from queries import parse_query
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.planner import PlanningError
from reasoning.planning.query_planner import plan_query
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.sensor_sources import sensor_source
from robokudo.application.service import AnsweringService
from robokudo.core.composites import Sequence
from robokudo.core.dataflow import validate_data_flow
from robokudo.core.loop import Loop
from robokudo.core.parallel import ThresholdParallel
from trees.pointing import UNIT_NAME, WATCH_NAME, split_track_and_point, track_types
from trees.synthesis import build_task_tree

FORMS = {
    "nested": "track { human: {}, pointing: { target: region } }",
    "phrase": "follow the person and watch where she points",
    "json": '{"track": {"human": {}, "pointing": {"target": "region"}}}',
}


@pytest.fixture(scope="module")
def kb() -> KnowledgeBase:
    return load_knowledge_base()


def names(node: object) -> list[str]:
    return [n.name for n in node.iterate()]  # type: ignore[attr-defined]


@pytest.mark.parametrize("text", FORMS.values(), ids=FORMS.keys())
def test_the_plan_runs_the_tracker_and_the_pointing_unit_in_a_parallel(kb: KnowledgeBase, text: str) -> None:
    query = parse_query(text)
    assert query.kind == "track"
    plan = plan_query(query, kb, sensor_source(kb, None)).plan
    tree = build_task_tree(plan, query=query)
    assert isinstance(tree, Loop)
    validate_data_flow(tree.decorated)
    (watch,) = [n for n in tree.iterate() if n.name == WATCH_NAME]
    assert isinstance(watch, ThresholdParallel)
    follow, unit = watch.children
    assert isinstance(follow, Sequence) and isinstance(unit, Sequence) and unit.name == UNIT_NAME
    assert "HumanTracker" in names(follow) and not {"ActivityRecognizer", "PointingEstimator"} & set(names(follow))
    assert {"ActivityRecognizer", "PointingEstimator"} <= set(names(unit)) and "HumanTracker" not in names(unit)
    # what both need runs once, before the Parallel
    before = [c.name for c in tree.decorated.children[: tree.decorated.children.index(watch)]]
    assert "HumanPoseDetector" in before and "HumanPoseDetector" not in names(watch)
    # the Parallel answers when either branch does: a frame without pointing still gives the track
    assert watch.decide([follow.status.SUCCESS, unit.status.FAILURE]) is follow.status.SUCCESS


def test_the_split_keeps_every_step_once_and_in_plan_order(kb: KnowledgeBase) -> None:
    plan = plan_query(parse_query(FORMS["nested"]), kb, sensor_source(kb, None)).plan
    parts = split_track_and_point(plan, track_types())
    split = [name for part in parts for name in part.annotator_names()]
    assert sorted(split) == sorted(plan.annotator_names())
    order = plan.annotator_names()
    for part in parts:
        own = part.annotator_names()
        assert own == [n for n in order if n in own]


def test_pointing_is_watched_only_while_tracking_a_person(kb: KnowledgeBase) -> None:
    kitchen = sensor_source(kb, None)
    with pytest.raises(PlanningError, match="tracking a person"):
        plan_query(parse_query("track { obj: { type: Cup }, pointing: { target: region } }"), kb, kitchen)
    with pytest.raises(PlanningError, match="not asked by"):
        plan_query(parse_query("inspect { pointing: { target: region } }"), kb, kitchen)


@pytest.mark.slow
def test_following_a_person_who_walks_then_points_gives_the_track_every_run_and_the_region(tmp_path: Path) -> None:
    try:
        load_pose_model()
    except PoseModelError as error:
        pytest.skip(str(error))
    script = PersonScript(
        (
            Motion("walk", 2.0, ((-0.6, 0.9), (-0.2, 0.7))),
            Motion("point", 600.0, ((-0.2, 0.7),), "fridge"),
        )
    )
    stream = KitchenCameraStream(rate_hz=10.0, view="person", person=script)
    with AnsweringService.open(tmp_path / "beliefs.sqlite", stream=stream, lost_after=30.0) as service:
        handle = service.start(FORMS["phrase"])
        answers = []
        while sum(a.pointing is not None for a in answers) < 3 and len(answers) < 60:
            answer = handle.next_answer(timeout=120)
            assert answer is not None, handle.reason
            answers.append(answer)
        handle.cancel()
    assert all(a.track is not None for a in answers), "a run without the track"
    assert sum(a.track.seen for a in answers) >= len(answers) - 1
    pointed = [a.pointing for a in answers if a.pointing is not None]
    assert len(pointed) == 3, f"no pointing seen in {len(answers)} runs"
    assert [p.region for p in pointed].count("fridge") >= 2, [p.target for p in pointed]
