"""``robokudo beliefs`` and ``robokudo ontology remove-object`` against a belief store filled by perception."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from reasoning.beliefs.store import BeliefStore
from reasoning.fusion.rule import CLASS_ATTRIBUTE, AttributeBelief, ValueSupport
from reasoning.fusion.tracking import ObjectBelief
from robokudo.application import cli


def beliefs(capsys: pytest.CaptureFixture[str], store: Path, *argv: str) -> tuple[int, str, str]:
    """Run ``robokudo beliefs ARGV --store STORE``; exit status, stdout, stderr."""
    capsys.readouterr()
    status = cli.main(["beliefs", *argv, "--store", str(store)])
    out, err = capsys.readouterr()
    return status, out, err


def listed_ids(capsys: pytest.CaptureFixture[str], store: Path, *argv: str) -> list[int]:
    status, out, _ = beliefs(capsys, store, *argv, "--json")
    assert status == 0
    return [o["id"] for o in json.loads(out)["objects"]]


def test_the_store_holds_what_perception_found(capsys: pytest.CaptureFixture[str], store: Path) -> None:
    assert sorted(listed_ids(capsys, store)) == [1, 2, 3, 4]
    assert listed_ids(capsys, store, "milk") == [1]


def test_clear_with_a_query_forgets_only_what_it_matches(capsys: pytest.CaptureFixture[str], store: Path) -> None:
    status, out, _ = beliefs(capsys, store, "--clear", "milk")
    assert status == 0
    assert f"forgot 1 object(s) matching 'milk' in {store}" in out
    assert sorted(listed_ids(capsys, store)) == [2, 3, 4]
    with BeliefStore(store) as opened:
        assert opened.get(1) is None and opened.history(1) == []
        assert len(opened.history(2)) == 1


def test_clearing_everything_needs_yes_and_ambiguous_requests_lose_nothing(
    capsys: pytest.CaptureFixture[str], store: Path
) -> None:
    before = store.read_bytes()
    refused = {
        ("--clear",): "add --yes to confirm",
        ("--clear", "--yes", "milk"): "ambiguous",
        ("--yes",): "--yes only confirms --clear",
        ("--clear", "unicorn"): "unknown object class 'unicorn'",
        ("--clear", "inspect object 999"): "no object 999",
    }
    for argv, reason in refused.items():
        status, out, err = beliefs(capsys, store, *argv)
        assert status == 2, argv
        assert reason in err and out == ""
    assert store.read_bytes() == before
    assert sorted(listed_ids(capsys, store)) == [1, 2, 3, 4]
    status, out, _ = beliefs(capsys, store, "--clear", "--yes", "--json")
    assert status == 0 and json.loads(out) == {"cleared": 4, "store": str(store)}
    assert listed_ids(capsys, store, "--all") == []


def test_an_object_id_selects_that_belief(capsys: pytest.CaptureFixture[str], store: Path) -> None:
    assert listed_ids(capsys, store, "inspect object 3") == [3]
    assert listed_ids(capsys, store, "inspect { obj: { id: 3 } }") == [3]
    status, out, err = beliefs(capsys, store, "inspect { obj: { id: 999 } }")
    assert status == 2 and out == "" and "no object 999" in err


def test_unknown_words_are_reported_as_query_reports_them(capsys: pytest.CaptureFixture[str], store: Path) -> None:
    before = store.read_bytes()
    for text in ("find the unicorn", "find milk in the garage", "detect { obj: { type: cup, color: blurple } }"):
        status, out, err = beliefs(capsys, store, text)
        assert (status, out) == (2, ""), text
        assert cli.main(["query", text, "--store", str(store)]) == 2
        from_query = capsys.readouterr().err
        assert err.removeprefix("robokudo beliefs: ") == from_query.removeprefix("robokudo query: ")
        assert "unknown" in err
    status, _, err = beliefs(capsys, store, "unicorn")  # memory questions may omit the verb
    assert status == 2 and "unknown object class 'unicorn'" in err
    assert store.read_bytes() == before


def _oat_milk_belief() -> ObjectBelief:
    """A belief classified as OatMilk, with a weaker Juice alternative."""
    stated = {
        "OatMilk": ValueSupport(2.0, 2, {"KnowledgeClassifier"}, 10.0, 20.0),
        "Juice": ValueSupport(0.5, 1, {"ObjectDetector"}, 10.0, 10.0),
    }
    return ObjectBelief(
        id=1,
        frame="world",
        position=np.array([1.3, 0.8, 1.05]),
        attributes={CLASS_ATTRIBUTE: AttributeBelief(CLASS_ATTRIBUTE, stated)},
        existence=2.0,
        region="fridge",
        region_class="Fridge",
        sources={"KnowledgeClassifier", "ObjectDetector"},
        class_name="OatMilk",
    )


def test_removing_a_class_moves_its_beliefs_to_the_parent_keeping_the_alternatives(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    store = tmp_path / "oat.sqlite"
    assert cli.main(["ontology", "--no-reasoner", "add-object", "OatMilk", "--is-a", "Milk", "--text", "oat"]) == 0
    with BeliefStore(store) as opened:
        opened.put([_oat_milk_belief()])
    assert listed_ids(capsys, store, "oat milk") == [1]

    assert cli.main(["ontology", "remove-object", "OatMilk", "--store", str(store)]) == 0
    assert f"reclassified 1 stored belief(s) of OatMilk as Milk ({store})" in capsys.readouterr().out
    status, out, _ = beliefs(capsys, store, "milk", "--json")
    assert status == 0
    (milk,) = json.loads(out)["objects"]
    assert milk["class"]["label"] == "milk"
    assert {a["value"] for a in milk["attributes"]["class"]["alternatives"]} == {"Milk", "Juice"}
    status, _, err = beliefs(capsys, store, "oat milk")
    assert status == 2 and "unknown object class" in err


def test_remove_object_with_an_unusable_store_removes_nothing(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    store = tmp_path / "broken.sqlite"
    store.write_bytes(b"not a database" * 10)
    assert cli.main(["ontology", "--no-reasoner", "add-object", "OatMilk", "--is-a", "Milk"]) == 0
    capsys.readouterr()
    assert cli.main(["ontology", "remove-object", "OatMilk", "--store", str(store)]) == 2
    assert "is not usable" in capsys.readouterr().err
    assert cli.main(["ontology", "show", "OatMilk"]) == 0


def test_an_unknown_word_of_a_bare_memory_question_is_located_in_what_was_typed(
    capsys: pytest.CaptureFixture[str], store: Path
) -> None:
    status, out, err = beliefs(capsys, store, "milk in the garage")
    assert (status, out) == (2, "")
    assert "unknown region or region class 'garage'" in err and "at line 1, column 6" in err
    assert err.splitlines()[-2:] == ["  milk in the garage", "       ^"]
