"""The planner plans exactly as before it was made fast: same plan (or error) for every stored random query."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from reasoning.knowledge.knowledge_base import KnowledgeBase
from robokudo.application.knowledge import load_knowledge_base
from tests.planning.plan_digests import GOLDEN, digest, sources

STORED: dict[str, dict[str, str]] = json.loads(GOLDEN.read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    return load_knowledge_base(Path(tmp_path_factory.mktemp("kb")) / "user.ttl")


@pytest.mark.parametrize("source_name", sorted(STORED))
def test_every_stored_query_plans_as_before(kb: KnowledgeBase, source_name: str) -> None:
    source = sources(kb)[source_name]
    changed = [text for text, expected in STORED[source_name].items() if digest(kb, text, source) != expected]
    assert not changed, f"{len(changed)} plans changed, e.g. {changed[:3]} (see tests/planning/plan_digests.py)"
