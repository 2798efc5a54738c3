"""The storage scenario (``robokudo scenario storage``): the mission completes on one running engine with every
goal handled, and the scoring notices wrong answers (a blocked placement, the wrong object, a lost or distant
track, a goal whose tree never ran)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from annotators.image.human_pose import PoseModelError, load_pose_model
from annotators.readers.streams import KitchenCameraStream
from annotators.simulation.kitchen_scene import kitchen_albedos, kitchen_objects
from annotators.simulation.storage import free_spots, random_layout, shelf_occupants
from robokudo.application.cli import main
from robokudo.application.scenario.scoring import (
    FollowSample,
    FreeSpaceRecord,
    GoalRecord,
    Placement,
    RunRecord,
    score_run,
)
from robokudo.application.scenario.setup import TABLE_OBJECTS, RunSetup
from robokudo.application.service import AnsweringService

IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
FOOTPRINT = (0.12, 0.12)


def _occupants() -> tuple:
    layout = random_layout(7)
    return shelf_occupants((*kitchen_objects(), *layout.objects))


def _good_record() -> RunRecord:
    """A run whose every answer is right (built from the ground truth itself)."""
    truth = {o.name: tuple(float(v) for v in o.position) for o in kitchen_objects() if o.name in TABLE_OBJECTS}
    occupants = _occupants()
    spot = free_spots(occupants, FOOTPRINT)[0]
    record = RunRecord(seed=1, target="red_cup", region="fridge", table_truth=truth)
    record.detected = {1: truth["cereal_box"], 2: truth["red_cup"], 3: truth["bowl"]}
    record.pointed_object, record.pointed_position, record.pointed_region = 2, truth["red_cup"], "fridge"
    record.follow = [FollowSample(float(t), True, (0.1 * t, 0.7, 1.2), (0.1 * t + 0.05, 0.7, 1.18)) for t in range(5)]
    record.follow_ended = "cancelled"
    placement = Placement(tuple(float(v) for v in spot), IDENTITY, FOOTPRINT)
    record.free_space = [FreeSpaceRecord((placement,), occupants, FOOTPRINT, True, room_in_view=40)]
    record.goals = [GoalRecord("detect", "find objects on the table", "answered", True, True)]
    return record


def test_a_run_with_right_answers_scores_on_every_criterion() -> None:
    score = score_run(_good_record())
    assert (score.pointing, score.following, score.free_space, score.process) == (True, True, True, True), score.why


def test_a_reported_placement_on_a_blocked_place_fails_free_space() -> None:
    record = _good_record()
    scan = record.free_space[0]
    blocked = next(o for o in scan.occupants if o.name.startswith("stored_"))
    centre = (float(blocked.position[0]), float(blocked.position[1]), 0.95)
    placements = (*scan.placements, Placement(centre, IDENTITY, FOOTPRINT))
    record.free_space = [FreeSpaceRecord(placements, scan.occupants, scan.footprint, True)]
    score = score_run(record)
    assert not score.free_space and score.pointing and score.following and score.process
    assert any("blocked place" in why for why in score.why)


def test_no_placement_although_room_was_in_view_fails_free_space() -> None:
    record = _good_record()
    scan = record.free_space[0]
    record.free_space = [FreeSpaceRecord((), scan.occupants, scan.footprint, True, room_in_view=40)]
    assert not score_run(record).free_space
    # room hidden from the camera (behind objects) cannot be reported: no place is then no mistake
    record.free_space = [FreeSpaceRecord((), scan.occupants, scan.footprint, True, room_in_view=0)]
    assert score_run(record).free_space


def test_pointing_at_the_wrong_object_or_region_fails_pointing() -> None:
    record = _good_record()
    record.pointed_object, record.pointed_position = 3, record.table_truth["bowl"]
    assert not score_run(record).pointing
    record = _good_record()
    record.pointed_region = "table"
    assert not score_run(record).pointing
    record = _good_record()
    record.pointed_object = 99  # an object that phase 1 did not detect
    assert not score_run(record).pointing


def test_a_lost_unseen_or_distant_track_fails_following() -> None:
    record = _good_record()
    record.follow_ended = "target lost: the human not seen for 5.10 s (lost after 5 s)"
    assert not score_run(record).following
    record = _good_record()
    record.follow[2] = FollowSample(2.0, False, (0.2, 0.7, 1.2), (0.25, 0.7, 1.18))
    assert not score_run(record).following
    record = _good_record()
    record.follow[3] = FollowSample(3.0, True, (0.3, 0.2, 1.2), (0.35, 0.7, 1.18))  # 0.5 m off
    assert not score_run(record).following
    assert score_run(record, tolerance=0.6).following


def test_a_goal_that_never_ran_or_ended_unexpectedly_or_an_error_fails_process_handling() -> None:
    record = _good_record()
    record.goals.append(GoalRecord("free space", "scan ...", "replaced by another task", True, False))
    assert not score_run(record).process
    record = _good_record()
    record.goals.append(GoalRecord("free space", "scan ...", "hung for 60 s", False, True))
    assert not score_run(record).process
    record = _good_record()
    record.error = "RuntimeError: boom"
    assert not score_run(record).process


def test_runs_are_seeded_and_vary() -> None:
    setups = [RunSetup.draw(seed) for seed in range(12)]
    again = RunSetup.draw(3)
    same = setups[3]
    assert (again.start, again.spot, again.target, again.wait_s) == (same.start, same.spot, same.target, same.wait_s)
    assert [o.position.tolist() for o in again.layout.objects] == [o.position.tolist() for o in same.layout.objects]
    assert len({s.target for s in setups}) > 1 and len({s.start for s in setups}) == 12
    assert len({len(s.layout.objects) for s in setups}) > 1


def test_grasp_and_place_events_change_the_rendered_scene() -> None:
    setup = RunSetup.draw(0)
    with KitchenCameraStream(view="table", person=setup.standing()) as stream:
        stream.stage(setup.standing(), setup.layout.extra())
        cup = stream.grasp("red_cup")
        assert "red_cup" not in {o.name for o in stream.ground_truth()}
        scene = stream._scene("table")
        assert not np.any(scene.object_ids == cup.object_id)  # gone from the frame, not only from the truth
        with pytest.raises(ValueError, match="no object 'red_cup'"):
            stream.grasp("red_cup")
        moved = np.array(cup.pose)
        moved[:3, 3] = (0.3, -0.2, cup.position[2])
        stream.place(replace(cup, pose=moved), kitchen_albedos()["red_cup"])
        scene = stream._scene("table")
        assert np.any(scene.object_ids == cup.object_id)
        with pytest.raises(ValueError, match="in the scene already"):
            stream.place(cup, kitchen_albedos()["red_cup"])
        stream.stage(setup.standing())  # a new run: every kitchen object back in place, nothing added
        assert {o.name for o in stream.ground_truth()} == {o.name for o in kitchen_objects()}


@pytest.mark.slow
def test_the_storage_scenario_completes_five_runs_with_every_goal_handled(capsys: pytest.CaptureFixture) -> None:
    try:
        load_pose_model()
    except PoseModelError as error:
        pytest.skip(str(error))
    status = main(["scenario", "storage", "--runs", "5", "--quiet"])
    out = capsys.readouterr().out
    print(out)
    assert status == 0, out
    rows = {line.split()[0]: line.split() for line in out.splitlines() if line.strip()}
    assert rows["process"][2] == "5/5"  # "process handling 5/5 100.0"
    for criterion in ("pointing", "following", "free"):
        assert criterion in rows
    assert "HumanPoseDetector" in out and "FreeSpaceEstimator" in out and "p90 ms" in out


def test_a_query_about_the_person_looks_at_her_and_a_region_query_at_the_region(tmp_path) -> None:
    stream = KitchenCameraStream(view="table", person=RunSetup.draw(0).standing())
    with AnsweringService.open(tmp_path / "beliefs.sqlite", stream=stream) as service:  # the engine does not tick
        for query, view in (
            ("which object is the person pointing at", "person"),
            ("find objects on the table", "table"),
            ("track the person", "person"),
            ("scan { free_space: { region: fridge, for: Cup } }", "fridge"),
        ):
            service.submit(query)
            assert stream.view == view, query
    without = KitchenCameraStream(view="table")
    with AnsweringService.open(tmp_path / "other.sqlite", stream=without) as service:
        service.submit("find the person")  # nobody in this kitchen: the camera stays on the table
        assert without.view == "table"


def test_the_frames_clock_advances_the_scene_one_camera_period_per_frame() -> None:
    setup = RunSetup.draw(2)
    script = setup.walking_to_storage()
    with KitchenCameraStream(rate_hz=10.0, view="person", person=script, clock="frames") as stream:
        frames = [stream.next_frame() for _ in range(3)]
        stamps = [f.camera.timestamp for f in frames]
        assert np.allclose(np.diff(stamps), 0.1)
        for index, stamp in enumerate(stamps):
            pose = stream.pose_at_stamp(stamp)
            assert pose is not None
            assert np.allclose(pose.position, script.pose_at(0.1 * index).position)
        stream.play(setup.standing())  # a new script starts at the next frame's time
        assert np.allclose(stream.pose_at_stamp(stream.next_frame().camera.timestamp).position, (*setup.start, 0.0))
    with pytest.raises(ValueError, match="unknown clock"):
        KitchenCameraStream(clock="sundial")
