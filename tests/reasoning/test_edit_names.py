"""Names, labels and synonyms in ontology edits: length caps, control characters, letters of any script."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from reasoning.errors import EditRejectedError
from reasoning.knowledge.editing import OntologyEditor
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.knowledge.words import MAX_LABEL_LENGTH, MAX_NAME_LENGTH, one_line, word_key
from robokudo.application.cli import main


@pytest.fixture()
def user_ontology(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    path = tmp_path / "user.ttl"
    monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(path))
    monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / "beliefs.sqlite"))
    return path


def add(*argv: str) -> int:
    return main(["ontology", "add-object", *argv, "--no-reasoner"])


def test_a_5000_character_class_name_is_rejected_before_anything_is_written(
    capsys: pytest.CaptureFixture[str], user_ontology: Path
) -> None:
    assert add("A" + "b" * 4999, "--is-a", "Cup") == 2
    err = capsys.readouterr().err
    assert f"the class name is 5000 characters long; at most {MAX_NAME_LENGTH} are allowed" in err
    assert not user_ontology.exists()


def test_a_label_longer_than_the_cap_is_rejected(capsys: pytest.CaptureFixture[str], user_ontology: Path) -> None:
    assert add("LongLabelCup", "--is-a", "Cup", "--label", "x" * (MAX_LABEL_LENGTH + 1)) == 2
    assert f"at most {MAX_LABEL_LENGTH} are allowed" in capsys.readouterr().err
    assert not user_ontology.exists()


def test_a_newline_in_a_synonym_is_rejected_and_nothing_is_written(
    capsys: pytest.CaptureFixture[str], user_ontology: Path
) -> None:
    assert add("TwoLineCup", "--is-a", "Cup", "--synonym", "two\nlines", "--text", "tab\there") == 2
    err = capsys.readouterr().err
    assert "synonym 'two\\nlines' contains control characters (\\n); write it on one line" in err
    assert "printed text 'tab\\there' contains control characters (\\t)" in err
    assert not user_ontology.exists()


def test_show_puts_a_hand_written_multi_line_synonym_on_one_line(
    capsys: pytest.CaptureFixture[str], user_ontology: Path
) -> None:
    user_ontology.write_text(
        "@prefix rk: <http://robokudo.org/ontology#> .\n"
        "@prefix owl: <http://www.w3.org/2002/07/owl#> .\n"
        "@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\n"
        "@prefix skos: <http://www.w3.org/2004/02/skos/core#> .\n"
        'rk:OddCup a owl:Class ; rdfs:subClassOf rk:Cup ; rdfs:label "odd cup"@en ;\n'
        '    skos:altLabel """two\nlines"""@en .\n',
        encoding="utf-8",
    )
    assert main(["ontology", "show", "OddCup"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert "  synonyms     two lines" in lines
    assert all(line.startswith("  ") for line in lines[1:])  # every line after the header is a field


def test_japanese_synonym_counts_as_letters_and_finds_the_class(
    capsys: pytest.CaptureFixture[str], user_ontology: Path
) -> None:
    assert add("Koppu", "--is-a", "Cup", "--synonym", "コップ") == 0
    capsys.readouterr()
    assert main(["ontology", "show", "コップ"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("Koppu  (object class, defined in user.ttl)")
    assert "synonyms     コップ" in out


def test_word_keys_keep_letters_and_digits_of_every_script() -> None:
    assert word_key("Cereal_Box") == "cerealbox"
    assert word_key("コップ") == "コップ"
    assert word_key("ＣＵＰ ２") == "cup2"
    assert word_key("Straße") == word_key("STRASSE")
    assert word_key("--- !") == ""


@pytest.fixture(scope="module")
def editor(tmp_path_factory: pytest.TempPathFactory) -> OntologyEditor:
    return OntologyEditor(KnowledgeBase.load(tmp_path_factory.mktemp("names") / "user.ttl"), use_reasoner=False)


_LETTERS = st.characters(categories=("Lu", "Ll", "Lo", "Nd"))


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    name=st.from_regex(r"[A-Z][A-Za-z0-9]{0,80}", fullmatch=True),
    synonym=st.text(_LETTERS, min_size=1, max_size=120) | st.text(min_size=1, max_size=20),
)
def test_any_accepted_class_round_trips_and_any_rejected_one_writes_nothing(
    editor: OntologyEditor, name: str, synonym: str
) -> None:
    path = editor.user_file
    before = path.read_bytes() if path.exists() else None
    try:
        editor.add_object(name, ["Cup"], synonyms=[synonym])
    except EditRejectedError as error:
        assert (path.read_bytes() if path.exists() else None) == before
        text = "\n".join(error.problems)
        assert len(name) <= MAX_NAME_LENGTH or "class name is" in text
        assert len(synonym) <= MAX_LABEL_LENGTH or "characters long" in text
        return
    try:
        assert len(name) <= MAX_NAME_LENGTH and len(synonym) <= MAX_LABEL_LENGTH
        assert "\n" not in synonym and word_key(synonym)
        assert editor.kb.resolve(name, ("class",)).name == name
        assume(len(editor.kb.resolve_all(synonym)) == 1)
        assert editor.kb.resolve(synonym, ("class",)).name == name
        assert one_line(synonym) in editor.kb.index.synonyms[name]
    finally:
        editor.remove_object(name)
