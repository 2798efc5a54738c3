"""Fixtures of the application tests: the user ontology, the belief store and the user data dir are temporary;
a belief store filled by perception once, and private copies of it."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from robokudo.application import cli


@pytest.fixture(autouse=True)
def _private_user_data(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Never read or write the real user data: the ontology, store and data dir point into ``tmp_path``."""
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / "beliefs.sqlite"))
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))


@pytest.fixture(scope="session")
def perceived(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A store filled by two kitchen queries: the milk in the fridge (#1) and three table objects (#2..#4)."""
    folder = tmp_path_factory.mktemp("perceived")
    path = folder / "beliefs.sqlite"
    with pytest.MonkeyPatch.context() as env:
        env.setenv("ROBOKUDO_USER_ONTOLOGY", str(folder / "user.ttl"))
        env.setenv("ROBOKUDO_BELIEF_STORE", str(folder / "unused.sqlite"))
        assert cli.main(["query", "find milk in fridge", "--store", str(path)]) == 0
        assert cli.main(["query", "scan the table", "--store", str(path)]) == 0
    return path


@pytest.fixture
def store(perceived: Path, tmp_path: Path) -> Path:
    """A private copy of the perceived store."""
    return Path(shutil.copy(perceived, tmp_path / "perceived.sqlite"))
