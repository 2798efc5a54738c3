"""The corpus in ``queries/corpus.jsonl``: query text -> expected model.

Each line holds ``form`` (nested, natural or json), ``input``, the expected
model in the tagged JSON form (``expected``) and its ``canonical`` print.
"""

from __future__ import annotations

import json
from collections import Counter
from importlib import resources
from typing import Any

import pytest

from queries import detect_form, format_query, parse_nested, parse_query, query_from_json, query_to_json


def load_corpus() -> list[dict[str, Any]]:
    """Read the corpus shipped with the package."""
    text = resources.files("queries").joinpath("corpus.jsonl").read_text(encoding="utf-8")
    return [json.loads(line) for line in text.splitlines() if line.strip()]


CORPUS = load_corpus()


def test_corpus_is_large_and_mixes_all_forms() -> None:
    assert len(CORPUS) >= 60
    forms = Counter(entry["form"] for entry in CORPUS)
    assert set(forms) == {"nested", "natural", "json"}
    assert min(forms.values()) >= 10


def test_corpus_inputs_are_unique() -> None:
    inputs = [entry["input"] for entry in CORPUS]
    assert len(inputs) == len(set(inputs))


@pytest.mark.parametrize("entry", CORPUS, ids=[entry["input"][:40] for entry in CORPUS])
def test_corpus_entry_gives_expected_model(entry: dict[str, Any]) -> None:
    text = entry["input"]
    assert detect_form(text) == entry["form"]
    query = parse_query(text)
    expected = query_from_json(entry["expected"])
    assert query == expected
    assert query_to_json(query) == entry["expected"]
    assert format_query(query) == entry["canonical"]
    assert parse_nested(entry["canonical"]) == expected
