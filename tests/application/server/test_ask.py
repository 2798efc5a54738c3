"""``robokudo ask`` against the served kitchen prints the feedback and the milk; errors are reported."""

from __future__ import annotations

import json

import pytest

from robokudo.application import cli
from tests.application.server.conftest import Served


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
