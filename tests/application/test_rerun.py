"""``--rerun FILE.rrd`` / ``--rerun-connect URL`` on ``robokudo run`` and ``query``: the recording read back with the
Rerun SDK's own reader holds the frames, clouds, boxes with labels, beliefs and tree status on the right timelines;
without the SDK the options are refused with the install hint."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest
import rerun_cli
from hypothesis import given, settings
from hypothesis import strategies as st
from py_trees.common import Status

from robokudo.application import cli
from robokudo.application.rerun_log import object_box, status_signature
from robokudo.core.composites import Sequence
from robokudo.core.geometry import quaternion_from_matrix, rotation_matrix
from robokudo.core.pipeline import Pipeline
from robokudo.core.slot import Idle, TaskSlot
from robokudo.core.types import ObjectHypothesis, PointCloud, Pose, Size
from tests.annotators.conftest import SHARED_DATA, require_folder
from tests.application.rerun_reading import Recording, camera_matrices, labels, read_recording
from tests.support import Scripted

REPO = Path(__file__).resolve().parents[2]
FRAME_ENTITIES = (
    "/world/camera",
    "/world/camera/image",
    "/world/camera/image/color",
    "/world/camera/image/depth",
    "/world/camera/image/hypotheses",
    "/world/camera/points",
    "/world/objects",
)


def run_cli(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """Run ``robokudo ARGV`` in this process; exit status, stdout, stderr."""
    capsys.readouterr()
    status = cli.main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def assert_views_line_up(recording: Recording, tick: int) -> None:
    """Every 3-D box's centre, seen through the logged camera pose and pinhole, falls inside the 2-D box of the
    same label (what a person sees when the 2-D and 3-D views agree)."""
    cam_to_world, k = camera_matrices(recording, tick)
    row_2d = recording.at("/world/camera/image/hypotheses", tick)
    boxes_2d = row_2d.components
    by_label = {label: i for i, label in enumerate(labels(row_2d, "Boxes2D"))}
    boxes_3d = recording.at("/world/objects", tick)
    assert labels(boxes_3d, "Boxes3D")
    for label, centre in zip(labels(boxes_3d, "Boxes3D"), boxes_3d.components["Boxes3D:centers"], strict=True):
        camera = np.linalg.inv(cam_to_world) @ np.append(centre, 1.0)
        u, v, w = k @ camera[:3]
        index = by_label[label]
        (cx, cy), (hx, hy) = boxes_2d["Boxes2D:centers"][index], boxes_2d["Boxes2D:half_sizes"][index]
        assert abs(u / w - cx) <= hx and abs(v / w - cy) <= hy, label


@pytest.mark.real_data
@pytest.mark.slow
def test_three_queries_on_three_real_frames_make_one_recording_of_three_frames(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    uoc = require_folder(SHARED_DATA / "uoc_tabletop_realsense")
    path = tmp_path / "frames.rrd"
    for frame in range(3):
        frame_input = ("--input", str(uoc), "--frame", str(frame))
        status, _, err = run_cli(capsys, "query", "detect {obj: {shape: box}}", *frame_input, "--rerun", str(path))
        assert status == 0, err
    recording = read_recording(path)
    assert len(recording.recording_ids) == 1  # each run continued the same recording
    ticks = recording.ticks("/world/camera/image/color")
    times = recording.frame_times("/world/camera/image/color")
    assert len(set(ticks)) == 3 and len(set(times)) == 3 and times == sorted(times)
    for entity in FRAME_ENTITIES:  # every part of a frame at the frame's tick and time
        assert recording.ticks(entity) == ticks, entity
        assert recording.frame_times(entity) == times, entity
    for tick in ticks:
        color = recording.at("/world/camera/image/color", tick).components["Image:format"][0]
        assert (color["width"], color["height"]) == (640, 480)
        assert recording.at("/world/camera/image/depth", tick).components["DepthImage:meter"] == [1.0]
        assert len(recording.at("/world/camera/points", tick).components["Points3D:positions"]) > 10_000
        boxes = labels(recording.at("/world/camera/image/hypotheses", tick), "Boxes2D")
        assert boxes and all(label.startswith("#") for label in boxes)  # every hypothesis named by its belief
        assert labels(recording.at("/world/objects", tick), "Boxes3D") == boxes  # every one got a 3-D box
        assert_views_line_up(recording, tick)
        text = recording.at("/tree", tick).components["TextLog:text"][0]
        assert text.startswith("query: SUCCESS") and "✔ AnswerStep" in text
    beliefs = recording.by_prefix("/world/beliefs/")
    assert beliefs and {r.tick for rows in beliefs.values() for r in rows} == set(ticks)
    first = recording.at("/world/camera/image/hypotheses", ticks[0])
    for label in labels(first, "Boxes2D"):  # the beliefs the first frame made are where its boxes are
        belief = recording.at(f"/world/beliefs/{label[1:].split()[0]}", ticks[0])
        assert labels(belief, "Points3D")[0] == label.split(":")[0]


def test_run_records_the_kitchen_in_the_world_frame_and_the_views_line_up(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    path = tmp_path / "kitchen.rrd"
    status, _, err = run_cli(capsys, "run", "tabletop", "--rerun", str(path))
    assert status == 0, err
    recording = read_recording(path)
    (tick,) = recording.ticks("/world/camera/image/color")
    cam_to_world, _ = camera_matrices(recording, tick)
    assert not np.allclose(cam_to_world, np.eye(4))  # the kitchen camera's pose: boxes are in the world frame
    assert sorted(labels(recording.at("/world/objects", tick), "Boxes3D")) == [
        "hypothesis 1: yellow",
        "hypothesis 2: blue",
        "hypothesis 3: red",
    ]
    assert_views_line_up(recording, tick)
    assert recording.at("/tree", tick).components["TextLog:text"][0].startswith("tabletop: SUCCESS")
    status, _, err = run_cli(capsys, "run", "tabletop", "--rerun", str(path))  # a second run continues the file
    assert status == 0, err
    again = read_recording(path)
    assert again.recording_ids == recording.recording_ids
    assert again.ticks("/world/camera/image/color") == [tick, tick + 1]


def test_a_file_that_is_no_recording_is_refused_and_one_where_nothing_ran_is_left_as_it_was(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    text = tmp_path / "notes.rrd"
    text.write_text("not a recording")
    status, out, err = run_cli(capsys, "run", "tabletop", "--rerun", str(text))
    assert (status, out) == (2, "") and "is not a Rerun recording" in err
    assert text.read_text() == "not a recording"
    status, _, err = run_cli(capsys, "run", "tabletop", "--rerun", str(tmp_path / "frames.txt"))
    assert status == 2 and "ending in .rrd" in err
    recorded = tmp_path / "kept.rrd"
    assert run_cli(capsys, "run", "tabletop", "--rerun", str(recorded))[0] == 0
    before = recorded.read_bytes()
    fresh = tmp_path / "fresh.rrd"
    for path in (recorded, fresh):  # a planning error: nothing runs, nothing is recorded
        status, _, err = run_cli(capsys, "query", "find milk in fridge", "--input", str(tmp_path), "--rerun", str(path))
        assert status == 2, err
    assert recorded.read_bytes() == before
    assert not fresh.exists()
    assert [p.name for p in tmp_path.iterdir() if p.name.endswith(".part")] == []


BLOCKER = """
import importlib.abc
import sys


class NoRerun(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in ("rerun", "rerun_bindings"):
            raise ImportError(f"No module named {name!r} (blocked by the test)", name=name)
        return None


sys.meta_path.insert(0, NoRerun())
"""


@pytest.mark.parametrize(
    "argv",
    [
        ("run", "tabletop", "--rerun", "out.rrd"),
        ("query", "find milk in fridge", "--rerun-connect"),
        ("serve", "--port", "0", "--rerun", "out.rrd"),
    ],
)
def test_without_the_rerun_sdk_the_options_say_how_to_install_it(tmp_path: Path, argv: tuple[str, ...]) -> None:
    (tmp_path / "sitecustomize.py").write_text(BLOCKER)
    environment = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join((str(tmp_path), str(REPO))),
        "ROBOKUDO_USER_ONTOLOGY": str(tmp_path / "user.ttl"),
        "ROBOKUDO_BELIEF_STORE": str(tmp_path / "beliefs.sqlite"),
        "XDG_DATA_HOME": str(tmp_path / "data"),
    }
    probe = subprocess.run(
        [sys.executable, "-c", "import rerun"], env=environment, capture_output=True, text=True, check=False
    )
    assert probe.returncode == 1 and "blocked by the test" in probe.stderr  # the blocker works
    done = subprocess.run(
        [sys.executable, "-m", "robokudo", *argv],
        cwd=tmp_path,
        env=environment,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 2, done.stderr
    assert "pip install 'robokudo[rerun]'" in done.stderr
    assert "Traceback" not in done.stderr
    assert not (tmp_path / "out.rrd").exists()


def free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@pytest.fixture
def viewer(tmp_path: Path) -> Iterator[tuple[str, Path]]:
    """A headless Rerun viewer server (the ``rerun`` binary saving what it receives); its URL and file."""
    port = free_port()
    received = tmp_path / "received.rrd"
    binary = Path(rerun_cli.__file__).parent / "rerun"
    process = subprocess.Popen(
        [str(binary), "--bind", "127.0.0.1", "--port", str(port), "--save", str(received)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + 30
        while True:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                assert time.monotonic() < deadline and process.poll() is None, "the Rerun viewer did not start"
                time.sleep(0.1)
        yield f"rerun+http://127.0.0.1:{port}/proxy", received
    finally:
        process.terminate()
        process.wait(30)


@pytest.mark.filterwarnings("ignore:RRD file has no footer")  # the viewer saves a stream, not a finished file
def test_rerun_connect_streams_to_a_running_viewer(
    capsys: pytest.CaptureFixture[str], viewer: tuple[str, Path]
) -> None:
    url, received = viewer
    status, _, err = run_cli(capsys, "run", "tabletop", "--rerun-connect", url)
    assert status == 0, err
    deadline = time.monotonic() + 30
    logged: set[str] = set()
    while logged != set(FRAME_ENTITIES):  # the viewer saves what it receives as it arrives
        assert time.monotonic() < deadline, f"the viewer saved only {sorted(logged)}"
        time.sleep(0.2)
        try:
            recording = read_recording(received)
        except (OSError, RuntimeError, ValueError, IndexError):  # not written yet, or a message half written
            continue
        logged = {entity for entity in FRAME_ENTITIES if recording.ticks(entity)}


def test_rerun_connect_without_a_viewer_is_refused(capsys: pytest.CaptureFixture[str]) -> None:
    port = free_port()
    for target in (f"rerun+http://127.0.0.1:{port}/proxy", str(port)):
        status, out, err = run_cli(capsys, "run", "tabletop", "--rerun-connect", target)
        assert (status, out) == (2, "") and f"no Rerun viewer at rerun+http://127.0.0.1:{port}/proxy" in err
    status, _, err = run_cli(capsys, "run", "tabletop", "--rerun-connect", "http://example.org/")
    assert status == 2 and "is no Rerun viewer URL" in err


# ---------------------------------------------------------------------------------------------- the parts


def test_a_served_tree_without_a_task_logs_its_status_once_not_every_tick() -> None:
    reader = Scripted("read frame", [Status.SUCCESS, Status.RUNNING])  # a new frame every other tick
    slot = TaskSlot("task")
    slot.set_subtree(Idle())
    root = Sequence("robot", [Pipeline("perception", [reader]), slot])
    signatures = []
    for _ in range(30):
        reader.updates = 0 if len(signatures) % 2 else 1
        root.tick_once()
        signatures.append(status_signature(root, slot.subtree))
    assert len(set(signatures)) == 1
    reader.script = [Status.SUCCESS]
    slot.set_subtree(Pipeline("query", [Scripted("expert", [Status.RUNNING, Status.SUCCESS])]))
    running, finished = [(root.tick_once(), status_signature(root, slot.subtree))[1] for _ in range(2)]
    assert len({signatures[0], running, finished}) == 3  # a task's every change is logged


@settings(max_examples=40, deadline=None)
@given(
    extents=st.permutations([0.04, 0.1, 0.22]),
    quaternion=st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(lambda q: np.linalg.norm(q) > 0.3),
    centre=st.lists(st.floats(-1, 1), min_size=3, max_size=3),
)
def test_a_size_goes_to_the_pose_axes_along_which_the_object_spreads(
    extents: list[float], quaternion: list[float], centre: list[float]
) -> None:
    """Size lists extents largest first; the 3-D box puts each on the pose axis of that spread, for any pose."""
    rotation = rotation_matrix(np.asarray(quaternion) / np.linalg.norm(quaternion))
    grid = np.stack(np.meshgrid(*(np.linspace(-e / 2, e / 2, 12) for e in extents), indexing="ij"), -1).reshape(-1, 3)
    points = grid @ rotation.T + np.asarray(centre) + [0.0, 0.0, 2.0]  # in front of the camera
    cloud = PointCloud(points=points.reshape(-1, 1, 3).astype(np.float32), mask=np.ones((len(points), 1), bool))
    hypothesis = ObjectHypothesis(point_indices=np.arange(len(points)), mask=cloud.mask, roi=(0, 0, 1, 1))
    hypothesis.annotations += [
        Pose(position=points.mean(axis=0), orientation=quaternion_from_matrix(rotation), frame="camera"),
        Size(dimensions=tuple(sorted(extents, reverse=True)), size_class="medium"),  # type: ignore[arg-type]
    ]
    box = object_box(hypothesis, cloud, None)
    assert box is not None
    np.testing.assert_allclose(box.half_sizes * 2, extents, atol=1e-9)
    np.testing.assert_allclose(rotation_matrix(box.orientation), rotation, atol=1e-6)
