"""The runtime's command line: tree list / show / run, and the parse command wiring."""

from __future__ import annotations

import shutil
from pathlib import Path

import cv2
import pytest

from robokudo.application import cli


def test_help_lists_every_command(capsys: pytest.CaptureFixture) -> None:
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["--help"])
    assert exit_info.value.code == 0
    text = capsys.readouterr().out
    for command in ("tree", "run", "parse", "plan", "query", "beliefs", "ontology"):
        assert command in text


def test_tree_list_and_show(capsys: pytest.CaptureFixture) -> None:
    assert cli.main(["tree", "list"]) == 0
    assert "tabletop" in capsys.readouterr().out
    assert cli.main(["tree", "show", "tabletop"]) == 0
    text = capsys.readouterr().out
    assert "Pipeline tabletop" in text and "ClutterSegmenter" in text
    assert "(PointCloud, Plane → ObjectHypothesis)" in text
    assert cli.main(["tree", "show", "tabletop", "--format", "dot"]) == 0
    assert capsys.readouterr().out.startswith("digraph ppt {")
    if shutil.which("dot"):
        assert cli.main(["tree", "show", "tabletop", "--format", "svg"]) == 0
        assert "<svg" in capsys.readouterr().out


def test_unknown_tree_is_a_clear_error(capsys: pytest.CaptureFixture) -> None:
    assert cli.main(["tree", "show", "nope"]) == 2
    assert "no tree named 'nope'; known trees: tabletop" in capsys.readouterr().err


def test_run_tabletop_prints_hypotheses_and_writes_the_annotated_image(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    image_path = tmp_path / "demo.png"
    assert cli.main(["run", "tabletop", "--annotated-image", str(image_path)]) == 0
    text = capsys.readouterr().out
    assert "✔ Pipeline tabletop" in text
    for colour in ("yellow", "red", "blue"):
        assert colour in text
    image = cv2.imread(str(image_path))
    assert image is not None and image.shape == (480, 640, 3)


def test_run_ticks_at_the_requested_rate_for_n_ticks(capsys: pytest.CaptureFixture) -> None:
    assert cli.main(["run", "tabletop", "--ticks", "3", "--hz", "50"]) == 0
    assert "KitchenSceneReader" in capsys.readouterr().out
