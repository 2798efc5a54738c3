"""Fixtures of the application tests: the user ontology, the belief store and the user data dir are temporary."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture(autouse=True)
def _private_user_data(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Never read or write the real user data: the ontology, store and data dir point into ``tmp_path``."""
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / "user.ttl"))
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / "beliefs.sqlite"))
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
