"""Beyond one machine, on a real local Ray cluster (2 CPUs, started once for this module and shut down after it).

* The tabletop tree with its colour expert on a Ray actor gives the local answer; the actor's process killed
  while it works makes that node FAIL with the reason, and the next run (on the restarted actor) works.
* ``robokudo eval segmentation --workers 2`` gives exactly the sequential figures on 4 shared mOSD scenes.

Without Ray these tests are skipped, except under CI (which installs the ``dev`` extra, Ray included), where a
missing Ray fails them. The messages the options give without Ray are tested by hiding the module.
"""

from __future__ import annotations

import contextlib
import itertools
import json
import logging
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType
from typing import ClassVar

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from py_trees.common import Status

from annotators.image.color import SemanticColorAnnotator
from robokudo.application import cli
from robokudo.application.parallel import map_on_cluster
from robokudo.core import compiled_call
from robokudo.core.annotator import Annotator
from robokudo.core.cas import CAS
from robokudo.core.compiled_call import BUFFER_BYTES, COMPILED_GRAPH, PLAIN_CALLS
from robokudo.core.engine import Engine
from robokudo.core.pipeline import Pipeline, pipelines
from robokudo.core.placement import Placement
from robokudo.core.remote import (
    ACTOR_ENV,
    CroppedMask,
    ExpertHost,
    FrameStore,
    MaskIndices,
    PlacementError,
    Recipe,
    RemoteAnnotator,
    in_transit,
    place_remote,
    restored,
)
from robokudo.core.types import CasType, ColorImage, DepthImage, ObjectHypothesis, Pose, SemanticColor, Text
from tests.annotators.conftest import SHARED_DATA, require_folder
from trees import tabletop

REPOSITORY = Path(__file__).resolve().parents[2]

DEADLINE = 60.0
"""Seconds a run may take on a loaded machine before the test gives up."""


def require_ray() -> ModuleType:
    try:
        import ray
    except ImportError:
        if os.environ.get("CI"):
            raise
        pytest.skip("Ray is not installed (pip install 'robokudo[ray]')")
    return ray


@pytest.fixture(scope="module")
def cluster() -> Iterator[ModuleType]:
    ray = require_ray()
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, logging_level=logging.ERROR)
    try:
        yield ray
    finally:
        ray.shutdown()


def run_to_end(engine: Engine) -> Status:
    start = time.monotonic()
    status = engine.tick()
    while status is Status.RUNNING:
        assert time.monotonic() - start < DEADLINE, "the tree did not finish in time"
        time.sleep(0.005)
        status = engine.tick()
    return status


def colours(root: object) -> list[tuple[tuple[int, int, int, int], list[tuple[str, object, str]]]]:
    """Each hypothesis' box and colours (name, confidence, source). Confidences are compared to 1e-9: Ray runs an
    actor with OMP_NUM_THREADS set to its CPUs, so BLAS may add up in another order than in this process."""
    cas = next(pipelines(root)).cas
    return [
        (h.roi, [(c.color, pytest.approx(c.confidence, rel=1e-9, abs=1e-12), c.source) for c in h.find(SemanticColor)])
        for h in cas.annotations(ObjectHypothesis)
    ]


def process_environment(pid: int) -> dict[str, str] | None:
    """The environment process ``pid`` started with (None where /proc cannot tell)."""
    try:
        raw = Path(f"/proc/{pid}/environ").read_bytes()
    except OSError:
        return None
    pairs = (entry.decode(errors="replace").partition("=") for entry in raw.split(b"\0") if entry)
    return {name: value for name, _, value in pairs}


@pytest.fixture(scope="module")
def local_colours() -> list:
    root = tabletop.create_tree()
    assert run_to_end(Engine(root, hz=1000)) is Status.SUCCESS
    found = colours(root)
    assert len(found) >= 2 and all(named for _, named in found)
    return found


def test_the_colour_expert_on_an_actor_gives_the_local_answer(cluster: ModuleType, local_colours: list) -> None:
    root = tabletop.create_tree()
    [remote] = place_remote(root, ["SemanticColorAnnotator"])
    try:
        assert isinstance(remote, RemoteAnnotator) and remote.name == "SemanticColorAnnotator"
        assert remote.actor_process_id() != os.getpid()
        assert run_to_end(Engine(root, hz=1000)) is Status.SUCCESS
        assert colours(root) == local_colours
        assert remote.call_path == COMPILED_GRAPH
        environment = process_environment(remote.actor_process_id())
        assert environment is None or ACTOR_ENV.items() <= environment.items()
    finally:
        remote.stop_actor()


def test_a_killed_actor_fails_its_node_with_the_reason_and_the_next_run_works(
    cluster: ModuleType, local_colours: list
) -> None:
    root = tabletop.create_tree()
    [remote] = place_remote(root, ["SemanticColorAnnotator"])
    engine = Engine(root, hz=1000)
    try:
        pid = remote.actor_process_id()
        os.kill(pid, signal.SIGSTOP)  # the actor cannot answer: the call is in flight when it is killed
        try:
            assert engine.tick() is Status.RUNNING
            waited = time.monotonic()
            while remote.status is not Status.RUNNING:
                assert time.monotonic() - waited < DEADLINE
                engine.tick()
            for _ in range(3):  # the tick loop goes on while the actor does not answer
                assert engine.tick() is Status.RUNNING and remote.status is Status.RUNNING
        finally:
            os.kill(pid, signal.SIGKILL)
        assert run_to_end(engine) is Status.FAILURE
        assert remote.status is Status.FAILURE
        assert "remote actor of SemanticColorAnnotator died" in remote.feedback_message
        assert run_to_end(engine) is Status.SUCCESS, remote.feedback_message
        assert colours(root) == local_colours
        assert remote.call_path == COMPILED_GRAPH  # a new graph, compiled on the restarted actor
        restarted = process_environment(remote.actor_process_id())
        assert restarted is None or ACTOR_ENV.items() <= restarted.items()
        assert remote.actor_process_id() != pid
    finally:
        remote.stop_actor()


def test_plain_actor_calls_give_the_local_answer_too(cluster: ModuleType, local_colours: list) -> None:
    root = tabletop.create_tree()
    [remote] = place_remote(root, ["SemanticColorAnnotator"], Placement(remote=True, compiled_graph=False))
    try:
        assert run_to_end(Engine(root, hz=1000)) is Status.SUCCESS
        assert colours(root) == local_colours
        assert remote.call_path.startswith(PLAIN_CALLS) and "compiled_graph=False" in remote.call_path
    finally:
        remote.stop_actor()


def test_without_compiled_graphs_the_calls_are_plain_and_say_why(
    cluster: ModuleType, local_colours: list, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(compiled_call, "unavailable_reason", lambda ray: "this Ray has no compiled graphs (hidden)")
    root = tabletop.create_tree()
    [remote] = place_remote(root, ["SemanticColorAnnotator"])
    try:
        assert run_to_end(Engine(root, hz=1000)) is Status.SUCCESS
        assert colours(root) == local_colours
        assert remote.call_path == f"{PLAIN_CALLS} (this Ray has no compiled graphs (hidden))"
    finally:
        remote.stop_actor()


class Echo(Annotator):
    """Reports the first pixel of its colour image and the image's shape; takes ``slow`` seconds when that pixel
    is 255 (a long run to cancel)."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage,)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (DepthImage,)
    outputs: ClassVar[tuple[type[CasType], ...]] = (Text,)

    def __init__(self, slow: float = 0.0) -> None:
        super().__init__(name="echo")
        self.slow = slow

    def analyse(self) -> None:
        image = self.view(ColorImage).image
        if image[0, 0, 0] == 255:
            time.sleep(self.slow)
        depth = self.optional_view(DepthImage)
        total = "" if depth is None else f" depth {int(depth.depth.sum())}"
        self.write(Text(text=f"{int(image[0, 0, 0])} {image.shape}{total}"))


class Frame(Annotator):
    """Writes a new frame each run: a colour image whose first pixel is the next of ``firsts``, and a depth
    image of ones, of the next of ``shapes`` (the last one again when they run out)."""

    outputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage, DepthImage)

    def __init__(self, firsts: list[int], shapes: list[tuple[int, int]]) -> None:
        super().__init__(name="frame")
        self.firsts = firsts
        self.shapes = shapes

    def analyse(self) -> None:
        shape = self.shapes.pop(0) if len(self.shapes) > 1 else self.shapes[0]
        image = np.zeros((*shape, 3), np.uint8)
        image[0, 0, 0] = self.firsts.pop(0)
        self.write(ColorImage(image))
        self.write(DepthImage(np.ones(shape, np.float32)))


def echo_tree(
    firsts: list[int], shapes: list[tuple[int, int]], timeout: float, slow: float = 3.0
) -> tuple[Pipeline, RemoteAnnotator]:
    tree = Pipeline("echo", [Frame(firsts, shapes), Echo(slow=slow)])
    [node] = place_remote(tree, ["echo"])
    node.timeout = timeout
    return tree, node


def echoed(tree: Pipeline) -> list[str]:
    return [text.text for text in tree.cas.annotations(Text)]


def test_a_timed_out_call_is_drained_and_the_next_run_gets_its_own_answer(cluster: ModuleType) -> None:
    """The compiled graph cannot cancel the slow execution: the run times out (FAILURE, as a local threaded
    annotator), the actor finishes it, and its result is dropped unread; each later run answers its own frame."""
    tree, node = echo_tree([1, 255, 2, 3], [(48, 64)], timeout=15.0)
    engine = Engine(tree, hz=1000)
    try:
        assert run_to_end(engine) is Status.SUCCESS and echoed(tree) == ["1 (48, 64, 3) depth 3072"]
        assert node.call_path == COMPILED_GRAPH
        node.timeout = 0.3
        assert run_to_end(engine) is Status.FAILURE
        assert node.feedback_message == "timed out after 0.3 s"
        node.timeout = 15.0
        assert run_to_end(engine) is Status.SUCCESS and echoed(tree) == ["2 (48, 64, 3) depth 3072"]
        assert run_to_end(engine) is Status.SUCCESS and echoed(tree) == ["3 (48, 64, 3) depth 3072"]
        assert node.call_path == COMPILED_GRAPH and node.compiled_calls().compiles == 1  # one graph throughout
    finally:
        node.stop_actor()


def test_a_run_whose_actor_never_answered_says_so_when_it_times_out(cluster: ModuleType) -> None:
    """An actor that reserves a GPU on this CPU-only cluster never starts: the run times out, and the message says
    that the actor had not answered yet and what it reserves (a robot's operator otherwise sees only "timed out")."""
    tree = Pipeline("echo", [Frame([1], [(48, 64)]), Echo()])
    [node] = place_remote(tree, ["echo"], Placement(remote=True, num_gpus=1))
    node.timeout = 1.0
    try:
        assert run_to_end(Engine(tree, hz=1000)) is Status.FAILURE
        assert node.feedback_message == (
            "timed out after 1 s (its actor had not answered yet: its process may still be starting, or no node has "
            "the 1 CPU, 1 GPU it reserves free)"
        )
    finally:
        node.stop_actor()


def test_an_interrupted_call_ends_its_worker_at_once_and_the_next_run_works(cluster: ModuleType) -> None:
    tree, node = echo_tree([1, 255, 2], [(48, 64)], timeout=15.0)
    engine = Engine(tree, hz=1000)
    try:
        assert run_to_end(engine) is Status.SUCCESS
        assert engine.tick() is Status.RUNNING
        waited = time.monotonic()
        while node.status is not Status.RUNNING:
            assert time.monotonic() - waited < DEADLINE
            engine.tick()
        time.sleep(0.2)  # the actor works on the slow frame
        tree.stop(Status.INVALID)  # as a Fallback moving on interrupts it
        assert node.stop_worker(timeout=1.0)  # the worker stops waiting at once (the actor goes on)
        assert run_to_end(engine) is Status.SUCCESS and echoed(tree) == ["2 (48, 64, 3) depth 3072"]
        assert node.call_path == COMPILED_GRAPH
    finally:
        node.stop_actor()


def test_a_call_that_sleeps_through_the_expected_wait_answers_and_can_be_interrupted_in_its_sleep(
    cluster: ModuleType,
) -> None:
    tree, node = echo_tree([255, 255, 2], [(48, 64)], timeout=30.0, slow=1.0)
    calls = node.compiled_calls()
    assert calls is not None
    calls.nap_fraction = 0.8
    engine = Engine(tree, hz=1000)
    try:
        assert run_to_end(engine) is Status.SUCCESS and echoed(tree) == ["255 (48, 64, 3) depth 3072"]
        assert engine.tick() is Status.RUNNING  # the next call sleeps ~0.8 s before it reads
        time.sleep(0.2)
        tree.stop(Status.INVALID)
        assert node.stop_worker(timeout=0.4)  # before its sleep (0.6 s more) would have ended: it checked
        assert run_to_end(engine) is Status.SUCCESS and echoed(tree) == ["2 (48, 64, 3) depth 3072"]
        assert calls.compiles == 1
    finally:
        node.stop_actor()


def test_a_new_graph_that_does_not_answer_has_its_actor_restarted_and_the_run_goes_on(
    cluster: ModuleType, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The first graph's actor is stopped right after the graph compiled (as if its loop never started): its first
    call gets no answer, the actor's process is ended for Ray to restart, a new graph is compiled there, and the
    run answers its frame."""
    monkeypatch.setattr(compiled_call, "VERIFY_SECONDS", 1.0)
    compile_graph = compiled_call.CompiledCalls._compiled
    stopped: list[int] = []

    def compile_and_stop_the_first(self: compiled_call.CompiledCalls) -> object:
        fresh = self._graph is None
        graph = compile_graph(self)
        if fresh and not stopped:
            stopped.append(self._process_id)
            os.kill(self._process_id, signal.SIGSTOP)
        return graph

    monkeypatch.setattr(compiled_call.CompiledCalls, "_compiled", compile_and_stop_the_first)
    tree, node = echo_tree([1, 2], [(48, 64)], timeout=60.0)
    engine = Engine(tree, hz=1000)
    try:
        assert run_to_end(engine) is Status.SUCCESS, node.feedback_message
        assert echoed(tree) == ["1 (48, 64, 3) depth 3072"]
        calls = node.compiled_calls()
        assert calls.compiles == 2 and node.call_path == COMPILED_GRAPH, (
            calls.compiles,
            node.call_path,
            calls.unavailable,
            node.feedback_message,
        )
        assert node.actor_process_id() != stopped[0]
        assert run_to_end(engine) is Status.SUCCESS and echoed(tree) == ["2 (48, 64, 3) depth 3072"]
    finally:
        for pid in stopped:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        node.stop_actor()


def test_an_idle_graph_is_torn_down_and_the_next_call_compiles_it_again(cluster: ModuleType) -> None:
    tree, node = echo_tree([1, 2], [(48, 64)], timeout=30.0)
    calls = node.compiled_calls()
    assert calls is not None
    calls.idle_seconds = 0.3
    engine = Engine(tree, hz=1000)
    try:
        assert run_to_end(engine) is Status.SUCCESS and echoed(tree) == ["1 (48, 64, 3) depth 3072"]
        waited = time.monotonic()
        while calls.idle_releases == 0:
            assert time.monotonic() - waited < DEADLINE, "the idle graph was not torn down"
            time.sleep(0.05)
        assert calls.compiles == 1
        assert run_to_end(engine) is Status.SUCCESS and echoed(tree) == ["2 (48, 64, 3) depth 3072"]
        assert calls.compiles == 2 and node.call_path == COMPILED_GRAPH
    finally:
        node.stop_actor()


def test_inputs_larger_than_the_channel_buffers_grow_them(cluster: ModuleType) -> None:
    """A 640x480 RGB-D frame fits the channels as they start; a 1280x960 one (8.6 MB) is larger, and Ray grows
    them: the call stays on the compiled graph and gets the right answer."""
    assert 640 * 480 * (3 + 4) < BUFFER_BYTES < 1280 * 960 * (3 + 4)
    shapes = [(480, 640), (960, 1280), (480, 640), (1920, 2560)]
    tree, node = echo_tree([7, 8, 9, 10], list(shapes), timeout=30.0)
    engine = Engine(tree, hz=1000)
    try:
        for first, shape in zip((7, 8, 9, 10), shapes, strict=True):
            assert run_to_end(engine) is Status.SUCCESS, node.feedback_message
            assert echoed(tree) == [f"{first} ({shape[0]}, {shape[1]}, 3) depth {shape[0] * shape[1]}"]
            assert node.call_path == COMPILED_GRAPH and node.compiled_calls().compiles == 1
    finally:
        node.stop_actor()


def scene_paths() -> list[str]:
    learn = require_folder(SHARED_DATA / "pcl_mosd_tabletop" / "learn")
    return [str(learn / f"learn{n}.pcd") for n in (0, 17, 30, 40)]


def figures(capsys: pytest.CaptureFixture[str], *argv: str) -> dict:
    capsys.readouterr()
    assert cli.main(["eval", "segmentation", *argv, "--json"]) == 0
    document = json.loads(capsys.readouterr().out)
    for scene in document["scenes"]:
        assert scene.pop("milliseconds") >= 0  # a time, measured where the scene ran
    return document


def nap(seconds: float) -> tuple[float, float]:
    """A task that sleeps, returning when it started and ended (CLOCK_MONOTONIC: one clock for all processes)."""
    start = time.monotonic()
    time.sleep(seconds)
    return start, time.monotonic()


def test_fewer_workers_than_the_cluster_has_cpus_run_one_task_at_a_time(cluster: ModuleType) -> None:
    """The 2-CPU cluster could run two one-CPU tasks at once; ``workers=1`` holds it to one (a placement group)."""
    spans = sorted(map_on_cluster(nap, [0.2] * 4, workers=1))
    assert all(end <= next_start for (_, end), (next_start, _) in itertools.pairwise(spans))


def fail_or_hold(item: str, folder: Path) -> str:
    """A task that fails at once for ``"fail"``; otherwise it runs until ``folder/release`` exists (at most 60 s)
    and then leaves ``folder/ended``."""
    if item == "fail":
        raise ValueError("this task failed")
    deadline = time.monotonic() + 60.0
    while not (folder / "release").exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    (folder / "ended").touch()
    return item


def test_a_failure_is_reported_without_waiting_longer_than_asked_for_a_task_still_running(
    cluster: ModuleType, tmp_path: Path
) -> None:
    """A failed map waits for its tasks in flight only ``failure_wait`` seconds: one that runs on is left to the
    cluster, and the failure is raised while it still runs."""
    with pytest.raises(ValueError, match="this task failed"):
        map_on_cluster(fail_or_hold, ["hold", "fail"], tmp_path, workers=2, failure_wait=1.0)
    still_running = not (tmp_path / "ended").exists()
    (tmp_path / "release").touch()
    assert still_running
    deadline = time.monotonic() + 60.0
    while not (tmp_path / "ended").exists():  # the held task ends once released, freeing its CPU for the next tests
        assert time.monotonic() < deadline, "the held task did not end once released"
        time.sleep(0.05)


@pytest.mark.real_data
def test_eval_with_two_workers_gives_exactly_the_sequential_figures(
    cluster: ModuleType, capsys: pytest.CaptureFixture[str]
) -> None:
    paths = scene_paths()
    sequential = figures(capsys, *paths)
    parallel = figures(capsys, *paths, "--workers", "2")
    assert [s["scene"] for s in parallel["scenes"]] == ["learn0", "learn17", "learn30", "learn40"]
    assert parallel == sequential


@pytest.mark.real_data
def test_an_error_in_a_task_is_reported_as_in_one_process(
    cluster: ModuleType, capsys: pytest.CaptureFixture[str]
) -> None:
    unlabelled = require_folder(SHARED_DATA / "pcl_tabletop_pcd") / "milk_color.pcd"
    capsys.readouterr()
    assert cli.main(["eval", "segmentation", str(unlabelled), "--workers", "2"]) == 2
    assert capsys.readouterr().err == f"robokudo eval: {unlabelled} has no label field to score against\n"


FAILING_AMONG_RUNNING = """
import logging, random, sys, time
import ray
from robokudo.application.parallel import map_on_cluster

def work(item, failing):
    time.sleep(random.random() * 0.02)
    if item == failing:
        raise ValueError(item)
    return item

ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False, logging_level=logging.ERROR)
failures = 0
for run in range(int(sys.argv[1])):
    try:
        map_on_cluster(work, list(range(8)), run % 4, workers=2)
    except ValueError:
        failures += 1
print("failures", failures)
"""


def test_many_evals_whose_task_fails_among_running_ones_leave_the_process_alive() -> None:
    """A task's exception ends the map once the tasks still running have ended (their results dropped).
    Cancelling them instead made Ray 2.60 abort the whole process now and then (exit 1, or a stack trace from
    ``TaskManager::CompletePendingTask``) when one ended as it was cancelled, even after checking that it had not;
    so this runs in its own process."""
    require_ray()
    runs = 60
    ended = subprocess.run(
        [sys.executable, "-c", FAILING_AMONG_RUNNING, str(runs)],
        cwd=REPOSITORY,
        env={**os.environ, "PYTHONPATH": str(REPOSITORY)},
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert (ended.returncode, ended.stdout) == (0, f"failures {runs}\n"), ended.stderr[-2000:]


# ------------------------------------------------------------------------------------------ without a cluster


def test_the_actor_side_runs_the_expert_on_the_declared_inputs_alone() -> None:
    """What an actor does with the inputs it is sent, in this process: the colour expert's attachments come back
    naming the hypotheses by their position."""
    image = np.zeros((40, 60, 3), np.uint8)
    image[:, 30:] = (200, 30, 30)
    mask = np.zeros((40, 60), bool)
    mask[10:30, 35:55] = True
    hypothesis = ObjectHypothesis(point_indices=np.flatnonzero(mask), mask=mask, roi=(35, 10, 55, 30))
    require_ray()  # the recipe checks with Ray's pickler that the parameters can be sent
    host = ExpertHost(Recipe.of(SemanticColorAnnotator(name="colour", max_pixels=500)))
    status, message, writes, seconds, (entered, left) = host.analyse([hypothesis], ColorImage(image))
    assert (status, message) == ("SUCCESS", "") and 0 < seconds <= left - entered
    [(kind, index, colour)] = writes
    assert (kind, index, colour.color, colour.source) == ("attach", 0, "red", "colour")
    assert not hypothesis.annotations  # the actor's writes are returned, not applied
    status, message, writes, _, _ = host.analyse([hypothesis])
    assert (status, message, writes) == ("FAILURE", "no ColorImage in the CAS", [])


def test_only_declared_inputs_are_sent() -> None:
    require_ray()
    mask = np.ones((4, 4), bool)
    hypothesis = ObjectHypothesis(point_indices=np.arange(16), mask=mask, roi=(0, 0, 4, 4))
    hypothesis.annotations.append(Pose(position=np.zeros(3), orientation=np.array([0.0, 0.0, 0.0, 1.0])))
    cas = CAS()
    cas.set_view(ColorImage(np.zeros((4, 4, 3), np.uint8)))
    cas.set_view(DepthImage(np.ones((4, 4), np.float32)))
    cas.add(hypothesis)
    node = place_remote_probe()
    from robokudo.core.annotator import _Run

    node._run = _Run(cas, thread_ident=None)
    views, sent, local = node._inputs()
    assert [type(v) for v in views] == [ColorImage]
    assert local == [hypothesis] and sent[0] is not hypothesis
    assert sent[0].annotations == [] and sent[0].mask is hypothesis.mask  # shares its arrays, drops the pose
    assert hypothesis.annotations and isinstance(hypothesis.annotations[0], Pose)


@given(
    mask=arrays(bool, st.tuples(st.integers(1, 12), st.integers(1, 12))),
    corners=st.tuples(*(st.floats(0, 1) for _ in range(4))),
)
def test_a_mask_in_transit_comes_back_as_it_was(mask: np.ndarray, corners: tuple[float, ...]) -> None:
    """For any mask and box: the mask goes cut to the box only when nothing of it lies outside, and the actor's
    side restores exactly the full-frame mask."""
    height, width = mask.shape
    xs = sorted(round(c * width) for c in corners[:2])
    ys = sorted(round(c * height) for c in corners[2:])
    roi = (xs[0], ys[0], xs[1], ys[1])
    hypothesis = ObjectHypothesis(point_indices=np.flatnonzero(mask), mask=mask, roi=roi)
    sent = in_transit(hypothesis, (ObjectHypothesis,))
    outside = np.count_nonzero(mask) - np.count_nonzero(mask[roi[1] : roi[3], roi[0] : roi[2]])
    assert isinstance(sent.mask, CroppedMask) == (outside == 0 and (roi[2] - roi[0]) * (roi[3] - roi[1]) < mask.size)
    back = restored(sent)
    assert back.mask.shape == mask.shape and back.mask.dtype == mask.dtype and np.array_equal(back.mask, mask)
    indices = hypothesis.point_indices
    assert back.point_indices.dtype == indices.dtype and np.array_equal(back.point_indices, indices)
    assert hypothesis.mask is mask and hypothesis.point_indices is indices  # the local one unchanged


@given(indices=arrays(np.int64, st.integers(0, 30), elements=st.integers(0, 47)), dtype=st.sampled_from(["<i4", "<i8"]))
def test_point_indices_in_transit_come_back_as_they_were(indices: np.ndarray, dtype: str) -> None:
    """Indices that are not the mask's own (any order, repeats, other points) go as they are."""
    mask = np.zeros((6, 8), bool)
    mask[1:4, 2:5] = True
    hypothesis = ObjectHypothesis(point_indices=indices.astype(dtype), mask=mask, roi=(2, 1, 5, 4))
    back = restored(in_transit(hypothesis, (ObjectHypothesis,)))
    assert back.point_indices.dtype == np.dtype(dtype) and np.array_equal(back.point_indices, indices)
    own = ObjectHypothesis(point_indices=np.flatnonzero(mask).astype(dtype), mask=mask, roi=(2, 1, 5, 4))
    sent = in_transit(own, (ObjectHypothesis,))
    assert isinstance(sent.point_indices, MaskIndices)
    back = restored(sent)
    assert back.point_indices.dtype == np.dtype(dtype) and np.array_equal(back.point_indices, own.point_indices)
    for others in (own.point_indices[::-1], np.repeat(own.point_indices[:1], len(own.point_indices))):
        hypothesis = ObjectHypothesis(point_indices=others.copy(), mask=mask, roi=(2, 1, 5, 4))  # as many, not its
        back = restored(in_transit(hypothesis, (ObjectHypothesis,)))
        assert np.array_equal(back.point_indices, others)


def test_a_frame_goes_into_the_object_store_once(cluster: ModuleType) -> None:
    frames = FrameStore(size=2)
    first, second, third = (ColorImage(np.full((4, 4, 3), n, np.uint8)) for n in (1, 2, 3))
    [reference] = frames.references(cluster, [first])
    assert frames.references(cluster, [first]) == [reference]  # a second expert on the frame: the same object
    assert cluster.get(reference).image[0, 0, 0] == 1
    frames.references(cluster, [second, third])  # two newer frames push the first out
    assert frames.references(cluster, [first]) != [reference]


def place_remote_probe() -> RemoteAnnotator:
    from robokudo.core.pipeline import Pipeline

    pipeline = Pipeline("probe", [SemanticColorAnnotator()])
    [node] = place_remote(pipeline, ["SemanticColorAnnotator"], start=False)
    return node


def test_placement_hints_are_checked() -> None:
    with pytest.raises(ValueError, match="num_gpus"):
        Placement(remote=True, num_gpus=-1)
    assert Placement(remote=True, num_cpus=2, num_gpus=1).describe() == "remote (2 CPU, 1 GPU)"


def test_parameters_that_cannot_be_sent_are_named() -> None:
    require_ray()
    from robokudo.core.pipeline import Pipeline

    colour = SemanticColorAnnotator()
    colour.guard = threading.Lock()  # a lock cannot go to another process
    with pytest.raises(PlacementError, match="attribute 'guard'"):
        place_remote(Pipeline("probe", [colour]), ["SemanticColorAnnotator"], start=False)


@pytest.fixture
def without_ray(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray raises ImportError


@pytest.mark.real_data
def test_without_ray_the_options_say_what_to_install(without_ray: None, capsys: pytest.CaptureFixture[str]) -> None:
    [path, *_] = scene_paths()
    assert cli.main(["eval", "segmentation", path, "--workers", "2"]) == 2
    err = capsys.readouterr().err
    assert "--workers 2 needs Ray" in err and "pip install 'robokudo[ray]'" in err
    assert cli.main(["run", "tabletop", "--remote", "SemanticColorAnnotator"]) == 2
    err = capsys.readouterr().err
    assert "--remote needs Ray" in err and "pip install 'robokudo[ray]'" in err
