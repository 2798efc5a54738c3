"""The ``parse QUERY [--json]`` subcommand."""

from __future__ import annotations

import argparse
import io
import json
import subprocess
import sys

import pytest

from queries import parse_query, query_from_json
from robokudo.application.commands.parse import EXIT_BAD_QUERY, add_arguments, main, run


def parse_args(argv: list[str]) -> argparse.Namespace:
    """Parse arguments the way the ``robokudo parse`` subcommand does."""
    parser = argparse.ArgumentParser(prog="robokudo parse")
    add_arguments(parser)
    return parser.parse_args(argv)


def test_prints_canonical_form(capsys: pytest.CaptureFixture[str]) -> None:
    assert run(parse_args(["detect{obj:{type:Milk,location:Fridge}}"])) == 0
    out = capsys.readouterr().out
    assert out == "detect { obj: { type: Milk, location: Fridge } }\n"


def test_words_of_a_phrase_are_joined(capsys: pytest.CaptureFixture[str]) -> None:
    assert run(parse_args(["find", "the", "red", "cup"])) == 0
    assert capsys.readouterr().out == "detect { obj: { type: cup, color: red }, max_results: 1 }\n"


def test_json_option_prints_lossless_model(capsys: pytest.CaptureFixture[str]) -> None:
    assert run(parse_args(["find milk in fridge", "--json"])) == 0
    data = json.loads(capsys.readouterr().out)
    assert query_from_json(data) == parse_query("find milk in fridge")
    assert data["kind"] == "detect"


def test_bad_query_exits_2_with_located_error(capsys: pytest.CaptureFixture[str]) -> None:
    assert run(parse_args(["detect { obj: { type: Milk, } }"])) == EXIT_BAD_QUERY == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert "at line 1, column 29" in captured.err
    assert captured.err.rstrip().endswith("^")


def test_dash_reads_the_query_from_stdin(capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(sys, "stdin", io.StringIO("stop {\n  task: 7\n}\n"))
    assert main(["-"]) == 0
    assert capsys.readouterr().out == "stop { task: 7 }\n"


def test_module_runs_as_a_command() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "robokudo.application.commands.parse", "stop", "{", "task:", "x", "}"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0
    assert result.stdout == "stop { task: x }\n"
    bad = subprocess.run(
        [sys.executable, "-m", "robokudo.application.commands.parse", "stop {}"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert bad.returncode == 2
    assert "'stop' needs a 'task'" in bad.stderr
