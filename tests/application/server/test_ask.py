"""``robokudo ask`` against the served kitchen prints the feedback and the milk; errors are reported."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys

import pytest

from robokudo.application import cli
from tests.application.server.conftest import REPO, Served


def test_ask_prints_feedback_and_the_milk_in_the_fridge(kitchen_server: Served, capsys: pytest.CaptureFixture) -> None:
    assert cli.main(["ask", "find milk in fridge", "--server", kitchen_server.url]) == 0
    out, err = capsys.readouterr()
    assert "planning" in err and "running:" in err
    assert "milk" in out.lower() and "in fridge" in out


def test_ask_json_prints_the_object_designators(kitchen_server: Served, capsys: pytest.CaptureFixture) -> None:
    assert cli.main(["ask", "find milk in fridge", "--json", "--server", kitchen_server.url]) == 0
    answer = json.loads(capsys.readouterr().out)
    assert answer["objects"] and all(o["region"] == "fridge" for o in answer["objects"])


def test_ask_reports_a_bad_query_with_its_location(kitchen_server: Served, capsys: pytest.CaptureFixture) -> None:
    assert cli.main(["ask", "detect {obj: {type: Milk", "--server", kitchen_server.url]) == 1
    assert "goal aborted" in capsys.readouterr().err


def test_ask_without_a_server_says_so(capsys: pytest.CaptureFixture) -> None:
    assert cli.main(["ask", "find milk", "--server", "ws://127.0.0.1:9"]) == 2
    assert "cannot talk to ws://127.0.0.1:9" in capsys.readouterr().err


def test_ctrl_c_cancels_the_goal_and_exits_130(kitchen_server: Served) -> None:
    command = [sys.executable, "-m", "robokudo", "ask", "track milk in fridge", "--server", kitchen_server.url]
    environment = {**os.environ, "PYTHONPATH": str(REPO)}
    process = subprocess.Popen(command, cwd=REPO, env=environment, stderr=subprocess.PIPE, text=True)
    assert process.stderr is not None
    lines = []
    for line in process.stderr:  # a continuous goal: it runs until cancelled
        lines.append(line)
        if line.startswith("answer:"):
            process.send_signal(signal.SIGINT)
            break
    rest = process.stderr.read()
    assert process.wait(60) == 130
    assert "goal canceled: cancelled by the client" in rest and "interrupted" in rest


@pytest.mark.parametrize(
    ("options", "problem"),
    [
        (["--rate", "0"], "--rate must be positive"),
        (["--sensor-rate", "-1"], "--sensor-rate must be positive"),
        (["--host", "0.0.0.0"], "needs a token"),
        (["--once"], "--once plays a recording once"),
        (["--topic", "/camera/rgb"], "--topic names topics of a bag"),
        (["--input", "/no/such/recording"], "no such file or folder"),
    ],
)
def test_serve_refuses_bad_options(
    options: list[str], problem: str, capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("ROBOKUDO_TOKEN", raising=False)
    assert cli.main(["serve", *options]) == 2
    assert problem in capsys.readouterr().err


def test_serve_reports_a_port_in_use(kitchen_server: Served, capsys: pytest.CaptureFixture) -> None:
    assert cli.main(["serve", "--port", str(kitchen_server.port)]) == 2
    assert "address already in use" in capsys.readouterr().err.lower()
