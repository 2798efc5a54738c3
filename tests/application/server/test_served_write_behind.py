"""``robokudo serve --write-behind N``: the store commits in a writer process, and nothing answered is lost when
the server stops."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import roslibpy

from reasoning.beliefs.store import BeliefStore
from tests.application.server.conftest import REPO, start_server
from tests.application.server.test_roslibpy import ACTION, ACTION_TYPE, ended, send


def test_with_write_behind_the_answered_beliefs_are_in_the_store_after_a_sigterm(tmp_path: Path) -> None:
    served = start_server(tmp_path, "--write-behind", "4")
    try:
        client = roslibpy.Ros(host=served.host, port=served.port)
        client.run()
        try:
            action = roslibpy.ActionClient(client, ACTION, ACTION_TYPE)
            answers = []
            for _ in range(3):
                _, record = send(action, "find milk in fridge")
                result = ended(record)
                assert result["status"] is roslibpy.GoalStatus.SUCCEEDED
                answers.append(result["values"]["objects"])
        finally:
            client.close()
    finally:
        assert served.stop() == 0
    milk = [o for o in answers[-1] if "milk" in o["class"]["label"].lower()]
    assert milk, answers[-1]
    with BeliefStore(tmp_path / "beliefs.sqlite") as store:
        for answered in milk:
            stored = store.get(answered["id"])
            assert stored is not None, f"answered object {answered['id']} is not in the store"
            assert len(store.history(answered["id"])) >= 3  # every frame of the three goals was committed


@pytest.mark.parametrize("value", ["-1", "257"])
def test_a_write_behind_out_of_range_is_refused_before_serving(tmp_path: Path, value: str) -> None:
    done = subprocess.run(
        [sys.executable, "-m", "robokudo", "serve", "--write-behind", value, "--port", "0"],
        cwd=REPO,
        env={"PYTHONPATH": str(REPO), "ROBOKUDO_BELIEF_STORE": str(tmp_path / "b.sqlite"), "PATH": ""},
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2
    assert f"--write-behind must be 0 (off) or a number of frames up to 256, got {value}" in done.stderr
    assert not (tmp_path / "b.sqlite").exists()
