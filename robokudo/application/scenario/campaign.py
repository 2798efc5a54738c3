"""Many runs of the storage mission on one answering service: :func:`run_storage_scenario`."""

from __future__ import annotations

import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from annotators.readers.streams import KitchenCameraStream
from robokudo.application.scenario.mission import StorageMission
from robokudo.application.scenario.scoring import DEFAULT_FOLLOW_TOLERANCE, RunRecord, RunScore, score_run
from robokudo.application.scenario.setup import RunSetup
from robokudo.application.service import AnsweringService

CAMERA_RATE_HZ = 5.0
"""The kitchen camera's frame rate during the scenario (an unloaded machine's tracking loop keeps up with it)."""
DEFAULT_CLOCK = "frames"
"""The scene advances one camera period per frame (the runs do not depend on how busy the machine is); ``wall``
lets it advance with the wall clock (a slow loop misses frames of her walk)."""
ENGINE_HZ = 30.0
"""The engine's tick rate."""


@dataclass(frozen=True)
class ScenarioResult:
    """Every run's record and score, and the per-expert run times (ms) of all goals."""

    records: tuple[RunRecord, ...]
    scores: tuple[RunScore, ...]
    expert_ms: dict[str, list[float]]


def verdict_line(score: RunScore) -> str:
    """``pointing=ok following=FAIL ...`` for one run."""
    verdicts = (score.pointing, score.following, score.free_space, score.process)
    names = ("pointing", "following", "free-space", "process")
    return " ".join(f"{name}={'ok' if ok else 'FAIL'}" for name, ok in zip(names, verdicts, strict=True))


def run_storage_scenario(
    runs: int,
    seed: int = 0,
    tolerance: float = DEFAULT_FOLLOW_TOLERANCE,
    log: Callable[[str], None] = lambda _: None,
    clock: str = DEFAULT_CLOCK,
    budget_s: float | None = None,
) -> ScenarioResult:
    """Play ``runs`` runs (seeds ``seed``, ``seed + 1``, ...) of the storage mission on one answering service
    serving the kitchen camera (its own temporary belief store; the scene's ``clock``, see
    ``annotators.readers.streams.CLOCKS``), score each, and collect the experts' times. With ``budget_s``, no run
    starts once that many seconds have passed (the result holds the runs done, at least one)."""
    if runs < 1:
        raise ValueError(f"the scenario needs at least one run, not {runs}")
    first = RunSetup.draw(seed)
    stream = KitchenCameraStream(CAMERA_RATE_HZ, view="table", person=first.standing(), clock=clock)
    records: list[RunRecord] = []
    scores: list[RunScore] = []
    with (
        tempfile.TemporaryDirectory() as folder,
        AnsweringService.open(Path(folder) / "beliefs.sqlite", hz=ENGINE_HZ, stream=stream) as service,
    ):
        service.run_in_background()
        mission = StorageMission(service, stream)
        started = time.monotonic()
        for index in range(runs):
            if index and budget_s is not None and time.monotonic() - started >= budget_s:
                log(f"time budget of {budget_s:g} s spent after {index} runs")
                break
            setup = first if index == 0 else RunSetup.draw(seed + index)
            log(f"run {index + 1}/{runs} (seed {setup.seed}): she points at {setup.target}")
            record = mission.run(setup, log)
            score = score_run(record, tolerance)
            records.append(record)
            scores.append(score)
            log(f"  {verdict_line(score)}" + "".join(f"\n    {why}" for why in score.why))
        if service.perception is not None:
            mission.times.add_tree(service.perception)
    return ScenarioResult(tuple(records), tuple(scores), dict(mission.times.samples))
