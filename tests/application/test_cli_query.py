"""``robokudo query`` / ``run`` / ``plan``: object ids, timeouts, the store checked up front, inputs."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from annotators.readers.choice import reader_choice
from annotators.readers.frame_readers import TumPairReader
from reasoning.beliefs.store import BeliefStore
from robokudo.application import cli
from robokudo.application.service import AnsweringService
from robokudo.core.threaded import has_workers

TUM_SAMPLE = Path("../shared/data/tum_rgbd_sample_open3d")


def query(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """Run ``robokudo query ARGV``; exit status, stdout, stderr."""
    capsys.readouterr()
    status = cli.main(["query", *argv])
    out, err = capsys.readouterr()
    return status, out, err


def test_inspect_by_id_answers_only_that_object(capsys: pytest.CaptureFixture[str], store: Path) -> None:
    before = store.read_bytes()
    status, out, err = query(capsys, "inspect { obj: { id: 999 } }", "--store", str(store))
    assert (status, out) == (2, "") and "no object 999" in err
    assert store.read_bytes() == before  # nothing ran
    for text, wanted in (("inspect object 3", 3), ("inspect { obj: { id: 1 } }", 1)):
        status, out, _ = query(capsys, text, "--json", "--store", str(store))
        assert status == 0
        assert [o["id"] for o in json.loads(out)["objects"]] == [wanted]  # seen again, and nothing else


def test_a_timeout_that_passes_answers_from_memory_at_once(capsys: pytest.CaptureFixture[str], store: Path) -> None:
    with BeliefStore(store) as opened:
        last_seen = opened.get(1).last_seen  # type: ignore[union-attr]
    status, out, err = query(capsys, "detect {obj:{type:Milk}, timeout: 0.0001ms}", "--json", "--store", str(store))
    assert status == 0
    answer = json.loads(out)
    assert answer["timed_out"] is True and answer["from_memory"] is True
    assert [o["id"] for o in answer["objects"]] == [1]
    assert "timeout passed before perception finished" in err
    with BeliefStore(store) as opened:
        assert opened.get(1).last_seen == last_seen  # type: ignore[union-attr]  # nothing was fused
    status, out, _ = query(capsys, "detect {obj:{type:Milk}, timeout: 60s}", "--json", "--store", str(store))
    assert status == 0 and json.loads(out)["timed_out"] is False


def test_a_timeout_stops_the_running_tree_and_a_track_task(tmp_path: Path) -> None:
    with AnsweringService.open(tmp_path / "beliefs.sqlite") as service:
        outcome = service.answer("detect {obj: {type: Milk}, timeout: 0.05s}")
        assert outcome.answer.timed_out and outcome.answer.objects == ()
        assert service.engine.tasks.slot("task").subtree.name == "idle"  # the stopped tree was taken out
        handle = service.start("track {obj: {type: cup, color: red}, timeout: 1s}")
        list(handle.answers())
        assert handle.done and handle.reason == "timed out after 1 s"
    assert not has_workers(outcome.tree)  # closing waited for the interrupted text reader


def test_a_corrupt_default_store_is_refused_before_anything_runs(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("ROBOKUDO_BELIEF_STORE")
    default = BeliefStore.default_path()
    assert default.is_relative_to(tmp_path)
    default.parent.mkdir(parents=True)
    default.write_bytes(b"\x00garbage" * 100)
    status, out, from_default = query(capsys, "find milk in fridge")
    assert (status, out) == (2, "")
    assert f"belief store {default} is not usable" in from_default and "mv " in from_default
    status, out, from_option = query(capsys, "find milk in fridge", "--store", str(default))
    assert (status, out, from_option) == (2, "", from_default)
    assert default.read_bytes() == b"\x00garbage" * 100


@pytest.mark.parametrize(
    "argv",
    [
        ["query", "find milk", "--frame", "3"],
        ["plan", "find milk", "--frame", "3"],
        ["run", "tabletop", "--frame", "3"],
    ],
)
def test_frame_without_input_is_refused(capsys: pytest.CaptureFixture[str], argv: list[str]) -> None:
    assert cli.main(argv) == 2
    out, err = capsys.readouterr()
    assert out == "" and "--frame needs --input" in err


@pytest.mark.real_data
def test_the_tum_sample_folder_is_an_input(capsys: pytest.CaptureFixture[str]) -> None:
    if not TUM_SAMPLE.is_dir():
        pytest.skip(f"{TUM_SAMPLE} is absent")
    choice = reader_choice(str(TUM_SAMPLE))
    assert choice.reader is TumPairReader and choice.parameters["path"] == str(TUM_SAMPLE / "TUM_color.png")
    assert cli.main(["run", "tabletop", "--input", str(TUM_SAMPLE)]) == 0
    assert "no object hypotheses" not in capsys.readouterr().out
    assert cli.main(["run", "tabletop", "--input", str(TUM_SAMPLE), "--frame", "1"]) == 2
    assert "holds 1 colour/depth pair(s), no frame 1" in capsys.readouterr().err


def test_uoc_named_images_without_camera_parameters_are_not_guessed_as_pairs(tmp_path: Path) -> None:
    image = np.zeros((48, 64, 3), dtype=np.uint8)
    cv2.imwrite(str(tmp_path / "000000-color.png"), image)
    cv2.imwrite(str(tmp_path / "000000-depth.png"), np.zeros((48, 64), dtype=np.uint16))
    with pytest.raises(ValueError, match="matches no known layout"):
        reader_choice(str(tmp_path))


def test_a_broken_png_fails_the_reader_with_the_reason_and_libpng_stays_quiet(
    capfd: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    folder = tmp_path / "frames"
    folder.mkdir()
    rng = np.random.default_rng(0)
    cv2.imwrite(str(folder / "000000-color.png"), rng.integers(0, 255, (480, 640, 3), dtype=np.uint8))
    cv2.imwrite(str(folder / "000000-depth.png"), np.full((480, 640), 1000, dtype=np.uint16))
    params = {"fx": 600.0, "fy": 600.0, "x_offset": 320.0, "y_offset": 240.0, "img_width": 640, "img_height": 480}
    (folder / "camera_params.json").write_text(json.dumps(params))
    color = folder / "000000-color.png"
    color.write_bytes(color.read_bytes()[: color.stat().st_size // 2])
    capfd.readouterr()
    status = cli.main(["query", "find red things", "--input", str(folder), "--store", str(tmp_path / "b.sqlite")])
    err = capfd.readouterr().err
    assert status == 1
    assert f"ColorDepthPairReader: cannot decode {color}: truncated: chunk IDAT" in err
    assert "libpng" not in err


def test_the_annotated_image_boxes_the_answered_objects(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    picture = tmp_path / "milk.png"
    status, out, err = query(capsys, "find milk in fridge", "--annotated-image", str(picture))
    assert status == 0 and out.startswith("#1 lactose free milk"), err
    assert f"annotated image: {picture}" in err
    drawn = cv2.cvtColor(cv2.imread(str(picture)), cv2.COLOR_BGR2RGB)
    box = np.all(drawn == (0, 229, 255), axis=2)  # the answer's box colour
    rows, columns = np.nonzero(box)
    assert box.sum() > 200
    assert drawn.shape[:2] == (480, 640) and columns.min() > 150 and columns.max() < 500 and rows.min() > 50


def test_a_frame_a_uoc_folder_lacks_is_refused_before_anything_runs(
    capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    for number in (0, 1, 2):
        cv2.imwrite(str(tmp_path / f"{number:06d}-color.png"), np.zeros((48, 64, 3), dtype=np.uint8))
        cv2.imwrite(str(tmp_path / f"{number:06d}-depth.png"), np.zeros((48, 64), dtype=np.uint16))
    (tmp_path / "camera_params.json").write_text('{"fx": 60, "fy": 60, "x_offset": 32, "y_offset": 24}')
    assert reader_choice(str(tmp_path), 2).parameters["frame"] == 2
    with pytest.raises(ValueError, match=r"holds frames 0 to 2, no frame 7"):
        reader_choice(str(tmp_path), 7)
    assert cli.main(["plan", "find milk", "--input", str(tmp_path), "--frame", "7"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and "no frame 7" in err
