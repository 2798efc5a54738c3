"""The ``robokudo ontology`` subcommand module, driven through its own argparse parser."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from robokudo.application.commands import ontology as ontology_cli


def run(*argv: str) -> int:
    parser = argparse.ArgumentParser(prog="robokudo ontology")
    ontology_cli.add_arguments(parser)
    return ontology_cli.run(parser.parse_args(list(argv)))


def test_show_a_class(capsys: pytest.CaptureFixture[str], user_file: Path) -> None:
    assert run("--user-file", str(user_file), "show", "milk") == 0
    out = capsys.readouterr().out
    assert out.startswith("Milk  (object class, defined in objects.ttl)")
    assert "stored in    Fridge (regions: fridge)" in out


def test_show_a_region_an_annotator_and_a_colour(capsys: pytest.CaptureFixture[str], user_file: Path) -> None:
    assert run("show", "fridge", "--user-file", str(user_file)) == 0
    assert "position     1.3 0.85 0.8" in capsys.readouterr().out
    assert run("show", "ClusterExtractor", "--user-file", str(user_file)) == 0
    assert "NotForTransparentObjects" in capsys.readouterr().out
    assert run("show", "gray", "--user-file", str(user_file)) == 0
    assert capsys.readouterr().out.startswith("Grey  (color")


def test_show_unknown_name_exits_2(capsys: pytest.CaptureFixture[str], user_file: Path) -> None:
    assert run("--user-file", str(user_file), "show", "mlik") == 2
    assert "did you mean 'milk'" in capsys.readouterr().err


def test_add_show_remove(capsys: pytest.CaptureFixture[str], user_file: Path) -> None:
    code = run(
        "--user-file", str(user_file), "--no-reasoner",
        "add-object", "OatMilk", "--is-a", "Milk", "--color", "white", "--text", "oat", "--synonym", "oat drink",
    )  # fmt: skip
    assert code == 0
    out = capsys.readouterr().out
    assert f"added OatMilk ({user_file})" in out
    assert "stored in    Fridge (regions: fridge)   (from Milk)" in out
    assert run("--user-file", str(user_file), "show", "oat drinks") == 0
    assert capsys.readouterr().out.startswith("OatMilk  (object class, defined in user.ttl)")
    assert run("remove-object", "OatMilk", "--user-file", str(user_file)) == 0
    assert run("--user-file", str(user_file), "show", "OatMilk") == 2


def test_rejected_edit_exits_2_and_writes_nothing(capsys: pytest.CaptureFixture[str], user_file: Path) -> None:
    assert run("--user-file", str(user_file), "--no-reasoner", "add-object", "OatMilk", "--is-a", "Milk") == 0
    before = user_file.read_bytes()
    capsys.readouterr()
    assert run("--user-file", str(user_file), "add-object", "Soy", "--is-a", "Milk", "--stored-in", "Fridgde") == 2
    err = capsys.readouterr().err
    assert "edit rejected, nothing was written" in err
    assert "unknown region class 'Fridgde'" in err
    assert user_file.read_bytes() == before


def test_check_without_reasoner(capsys: pytest.CaptureFixture[str], user_file: Path) -> None:
    assert run("--user-file", str(user_file), "--no-reasoner", "check", "--no-code") == 0
    assert "ontology OK" in capsys.readouterr().out


@pytest.mark.slow
def test_check_with_hermit_and_code(capsys: pytest.CaptureFixture[str], user_file: Path) -> None:
    code = run("--user-file", str(user_file), "check")
    out = capsys.readouterr().out
    assert "reasoner: HermiT: consistent" in out
    assert code == 0, out


def test_works_as_a_robokudo_subcommand(capsys: pytest.CaptureFixture[str], user_file: Path) -> None:
    from robokudo.application import cli

    assert cli.main(["ontology", "--user-file", str(user_file), "show", "cereal boxes"]) == 0
    assert capsys.readouterr().out.startswith("CerealBox  (object class")
    assert cli.main(["ontology", "--user-file", str(user_file), "show", "mlik"]) == 2


def test_log_undo_synonym_export_and_import(
    capsys: pytest.CaptureFixture[str], user_file: Path, tmp_path: Path
) -> None:
    base = ("--user-file", str(user_file), "--no-reasoner")
    assert run(*base, "add-object", "OatMilk", "--is-a", "Milk", "--synonym", "oat drink") == 0
    assert run(*base, "synonym", "milk", "--add", "moo juice") == 0
    assert "changed the synonyms of Milk" in capsys.readouterr().out
    assert run(*base, "log") == 0
    lines = capsys.readouterr().out.splitlines()
    assert "add-object OatMilk" in lines[1] and "synonym Milk" in lines[2] and lines[2].endswith("+1 -0")
    exported = tmp_path / "layer.owl"
    assert run(*base, "export", "--format", "owl", "--output", str(exported)) == 0
    assert exported.read_text(encoding="utf-8").startswith('<?xml version="1.0" encoding="UTF-8"?>\n<Ontology')
    assert run(*base, "undo", "2") == 0
    assert "undid edit 2 (synonym Milk), edit 1 (add-object OatMilk)" in capsys.readouterr().out
    assert run(*base, "show", "moo juice") == 2
    assert run(*base, "import", str(exported)) == 0
    assert "imported 2 class(es) from layer.owl" in capsys.readouterr().out
    assert run(*base, "show", "oat drinks") == 0
    assert run(*base, "undo", "9") == 2
    assert "can be undone" in capsys.readouterr().err


def test_import_of_a_foreign_class_needs_a_map(
    capsys: pytest.CaptureFixture[str], user_file: Path, tmp_path: Path
) -> None:
    foreign = tmp_path / "food.ttl"
    foreign.write_text(
        "@prefix owl: <http://www.w3.org/2002/07/owl#> .\n@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .\n"
        "<http://example.org/food#SoyMilk> a owl:Class ; rdfs:subClassOf <http://example.org/food#Milch> .\n",
        encoding="utf-8",
    )
    base = ("--user-file", str(user_file), "--no-reasoner")
    assert run(*base, "import", str(foreign)) == 2
    assert "IRI(s) outside the rk: namespace" in capsys.readouterr().err
    assert not user_file.exists()
    mapped = ("--map", "http://example.org/food#", "--map", "http://example.org/food#Milch=Milk")
    assert run(*base, "import", str(foreign), *mapped) == 0
    assert run(*base, "show", "SoyMilk") == 0
    assert "is a         Milk" in capsys.readouterr().out


def test_export_of_the_merged_ontology_to_stdout(capsysbinary: pytest.CaptureFixture[bytes], user_file: Path) -> None:
    assert run("--user-file", str(user_file), "export", "--merged", "--format", "xml") == 0
    out = capsysbinary.readouterr().out
    assert b"http://robokudo.org/ontology/merged" in out and b"rdf:RDF" in out
