"""Fixtures of the reasoning tests: a shared knowledge base and per-test user ontology files."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.sources import USER_ONTOLOGY_ENV
from robokudo.application.knowledge import load_knowledge_base


@pytest.fixture(autouse=True)
def _private_user_ontology(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """Never read or write the real user data directory: the default user file and belief store are temporary."""
    monkeypatch.setenv(USER_ONTOLOGY_ENV, str(tmp_path / "default-user.ttl"))
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / "default-beliefs.sqlite"))
    yield


@pytest.fixture(scope="session")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    """The shipped ontology with the built-in kitchen map, every annotator class of the catalog and an empty user
    file, as the application loads it (shared: do not edit)."""
    return load_knowledge_base(tmp_path_factory.mktemp("kb") / "user.ttl")


@pytest.fixture()
def user_file(tmp_path: Path) -> Path:
    """A user ontology path that does not exist yet."""
    return tmp_path / "data" / "user.ttl"
