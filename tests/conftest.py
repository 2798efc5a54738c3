"""Every test runs with its own user ontology and belief store: nothing reads or writes the user's data dir."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

# The machines running the suite are shared and noisy: property tests check rules, never speed.
settings.register_profile("shared-machine", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile("shared-machine")


@pytest.fixture(autouse=True)
def private_user_data(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    """Point the user ontology, belief store and data dir at a fresh folder (tests may set their own on top)."""
    folder: Path = tmp_path_factory.mktemp("user-data")
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(folder / "user.ttl"))
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(folder / "beliefs.sqlite"))
    monkeypatch.setenv("XDG_DATA_HOME", str(folder / "data"))
