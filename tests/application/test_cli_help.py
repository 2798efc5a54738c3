"""The help a newcomer reads: every option's text stands on its own and the belief store options name their
default."""

from __future__ import annotations

import argparse
from collections.abc import Iterator

import pytest

from robokudo.application import cli
from robokudo.application.cli import build_parser


def _parsers(parser: argparse.ArgumentParser, name: str = "robokudo") -> Iterator[tuple[str, argparse.ArgumentParser]]:
    """The parser and every sub-command parser below it, with their command lines."""
    yield name, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub_name, sub in action.choices.items():
                yield from _parsers(sub, f"{name} {sub_name}")


def _option_helps() -> list[tuple[str, str, str]]:
    return [
        (command, "/".join(action.option_strings) or action.dest, action.help or "")
        for command, parser in _parsers(build_parser())
        for action in parser._actions
    ]


def test_no_option_help_points_to_text_the_screen_does_not_show() -> None:
    vague = [(c, o, h) for c, o, h in _option_helps() if "see above" in h or "see below" in h]
    assert not vague, vague


def test_every_belief_store_option_names_its_default() -> None:
    stores = [(c, o, h) for c, o, h in _option_helps() if o in ("--store", "--db")]
    assert {c for c, _, _ in stores} >= {"robokudo beliefs", "robokudo query", "robokudo serve"}
    for command, option, text in stores:
        assert "$ROBOKUDO_BELIEF_STORE" in text, (command, option, text)


def test_an_unknown_option_is_reported_by_the_command_that_was_given(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as caught:
        cli.main(["ask", "--port", "9391", "find milk"])
    assert caught.value.code == 2
    err = capsys.readouterr().err
    assert "usage: robokudo ask" in err and "robokudo ask: error: unrecognized arguments: --port" in err
    with pytest.raises(SystemExit):
        cli.main(["ontology", "show", "Milk", "--colour", "red"])
    err = capsys.readouterr().err
    assert "usage: robokudo ontology show" in err and "unrecognized arguments: --colour red" in err
