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
