"""Crash safety: a writer killed with SIGKILL at random points never corrupts the store or loses a commit."""

from __future__ import annotations

import os
import random
import re
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

from reasoning.beliefs.store import BeliefStore

REPO_ROOT = Path(__file__).resolve().parents[2]

WRITER = """
import sys
import numpy as np
from reasoning.fusion.rule import Evidence
from reasoning.fusion.frame import FrameObject
from reasoning.beliefs.store import BeliefStore

store = BeliefStore(sys.argv[1], write_behind=int(sys.argv[3]))
base = int(sys.argv[2])
print("ready", flush=True)
previous = None
returned = []  # with write-behind, a frame is known committed once write_behind later frames have returned
for i in range(base, base + 100000):
    seen = [FrameObject(position=np.array([float(i), 0.0, 0.0]), frame="world",
                        evidence=[Evidence("color", "red", 0.8, "Writer")], sources={"Writer"})]
    if previous is not None:  # also update a belief, so kills hit updates as well as inserts
        seen.append(FrameObject(position=previous, frame="world",
                                evidence=[Evidence("color", "red", 0.8, "Writer")], sources={"Writer"}))
    step = store.integrate(seen, float(i))
    previous = seen[0].position
    returned.append([(belief.id, belief.observations) for belief in step.changed])
    if len(returned) > store.write_behind:
        for belief_id, observations in returned.pop(0):
            print(belief_id, observations, flush=True)  # only after the commit
"""

ROUNDS = 20


@pytest.mark.slow
@pytest.mark.parametrize("write_behind", [0, 1])
def test_sigkill_at_random_points_keeps_the_store_sound_and_every_commit(tmp_path: Path, write_behind: int) -> None:
    """With write-behind, the frames whose commit the writer had not confirmed may be lost (at most
    ``write_behind``); every frame confirmed is kept."""
    path = tmp_path / "beliefs.sqlite"
    rng = random.Random(20240611)
    committed: dict[int, int] = {}
    env = {**os.environ, "PYTHONPATH": str(REPO_ROOT)}
    for round_index in range(ROUNDS):
        with subprocess.Popen(
            [sys.executable, "-c", WRITER, str(path), str(round_index * 1_000_000), str(write_behind)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=REPO_ROOT,
            env=env,
        ) as writer:
            assert writer.stdout is not None
            ready = writer.stdout.readline()
            assert ready == "ready\n", writer.stderr.read() if writer.stderr else ready
            time.sleep(rng.uniform(0.0, 0.25))
            writer.send_signal(signal.SIGKILL)
            # Read on through the same buffered file object as readline() above: communicate() would read the pipe's
            # file descriptor directly and lose whatever readline() had already buffered, splitting a line there.
            out = writer.stdout.read()
            writer.wait(timeout=10)
        assert writer.returncode == -signal.SIGKILL
        for line in out.split("\n")[:-1]:  # the text after the last newline was cut off by the kill
            match = re.fullmatch(r"(\d+) (\d+)", line)
            assert match is not None, f"unexpected writer output {line!r} in round {round_index}"
            belief_id, observations = int(match[1]), int(match[2])
            committed[belief_id] = max(committed.get(belief_id, 0), observations)
    assert len(committed) > ROUNDS  # the writers did get work done before being killed

    with sqlite3.connect(path) as raw:
        assert raw.execute("PRAGMA integrity_check").fetchall() == [("ok",)]
    with BeliefStore(path) as store:
        assert store.integrity_check() == "ok"
        stored = {b.id: b.observations for b in store.beliefs(include_gone=True)}
    missing = {i for i in committed if i not in stored}
    assert not missing, f"committed beliefs lost: {sorted(missing)[:10]}"
    regressed = {i: (n, stored[i]) for i, n in committed.items() if stored[i] < n}
    assert not regressed, f"committed updates lost: {regressed}"
