"""End to end: `robokudo query "find milk in fridge" --json` on the built-in scene, twice.

The answer is one milk with a pose, region fridge and its contributing experts, written to the belief store;
the second run updates the same belief.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from reasoning.beliefs.store import BeliefStore
from robokudo.application import cli


def test_find_milk_in_fridge_twice_updates_one_belief(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    store_path = tmp_path / "beliefs.sqlite"
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(store_path))
    ids = []
    for _ in range(2):
        assert cli.main(["query", "find milk in fridge", "--json"]) == 0
        answer = json.loads(capsys.readouterr().out)
        (milk,) = answer["objects"]
        assert "milk" in milk["class"]["label"] and milk["class"]["iri"].endswith("Milk")
        assert milk["pose"]["frame"] == "world" and len(milk["pose"]["position"]) == 3
        assert len(milk["pose"]["orientation"]) == 4
        assert milk["region"].lower() == "fridge"
        assert milk["experts"] and milk["roi"] is not None
        ids.append(milk["id"])
    assert ids[0] == ids[1]
    with BeliefStore(store_path) as store:
        belief = store.get(ids[0])
        assert belief is not None and belief.observations == 2 and len(store.history(ids[0])) == 2
