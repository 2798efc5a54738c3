"""What a robotics engineer trying robokudo on the shared real frames saw and a person would not agree with (the
trial's table: bench/profiles/realtrial-table.txt); each test asserts what the CLI prints."""

from __future__ import annotations

from pathlib import Path

import pytest

from robokudo.application import cli
from tests.annotators.conftest import SHARED_DATA, require_folder


@pytest.fixture(autouse=True)
def private_data(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / "beliefs.sqlite"))
    return tmp_path


def uoc() -> str:
    return str(require_folder(SHARED_DATA / "uoc_tabletop_realsense"))


def query(capsys: pytest.CaptureFixture[str], text: str, *options: str) -> list[str]:
    assert cli.main(["query", text, *options]) == 0, capsys.readouterr().err
    return capsys.readouterr().out.splitlines()


@pytest.mark.real_data
@pytest.mark.parametrize("text", ["find all objects", "find objects"])
def test_asking_for_any_object_shows_no_class_confidence_for_unknown_objects(
    capsys: pytest.CaptureFixture[str], text: str
) -> None:
    """uoc frame 4 (wipes, a can of cashews, a Duplo brick, a purple cup): "find all objects" printed ``#1 unknown
    object (blue) ..., class 0.99``: the probability that it answers to "object", which every object does, read as
    99 % sure of a class; a classified object shows its own class's confidence."""
    lines = query(capsys, text, "--input", uoc(), "--frame", "4")
    assert len(lines) >= 3
    unknown = [line for line in lines if " unknown object " in line]
    assert unknown and all(", class " not in line for line in unknown)
    named = [line for line in lines if " unknown object " not in line]
    assert all(", class " in line for line in named)
