"""The input entry point: which reader a path gets, with which arguments, and the errors for unknown layouts."""

from __future__ import annotations

import json
from pathlib import Path

import cv2
import numpy as np
import pytest

from annotators.readers.choice import SUPPORTED_LAYOUTS, reader_choice, reader_for, reader_name_for
from annotators.readers.frame_readers import TumPairReader
from annotators.readers.tum_io import TimedImage, associate, pair_paths


def touch_image(path: Path, channels: int = 3) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    shape = (4, 4, 3) if channels == 3 else (4, 4)
    cv2.imwrite(str(path), np.zeros(shape, np.uint8 if channels == 3 else np.uint16))
    return path


def test_no_path_is_the_kitchen() -> None:
    assert reader_name_for(None) == "KitchenSceneReader"
    assert type(reader_for(None)).__name__ == "KitchenSceneReader"


def test_folders_are_recognised_by_their_layout(tmp_path: Path) -> None:
    tum = tmp_path / "tum"
    tum.mkdir()
    (tum / "rgb.txt").write_text("")
    (tum / "depth.txt").write_text("")
    assert reader_choice(str(tum), 4).name == "TumSequenceReader"
    assert reader_choice(str(tum), 4).parameters == {"folder": str(tum), "frame": 4}

    uoc = tmp_path / "uoc"
    touch_image(uoc / "000002-color.png")
    (uoc / "camera_params.json").write_text(json.dumps({}))
    assert reader_name_for(str(uoc), 2) == "ColorDepthPairReader"
    with pytest.raises(ValueError, match="holds frame 2, no frame 0"):  # a frame the folder lacks, up front
        reader_choice(str(uoc), 0)
    single = reader_choice(str(uoc / "000002-color.png"))
    assert single.name == "ColorDepthPairReader" and single.parameters == {"folder": str(uoc), "frame": 2}

    grabber = tmp_path / "grabber"
    touch_image(grabber / "tiff" / "frame_1_rgb.tiff")
    touch_image(grabber / "tiff" / "frame_1_depth.tiff", channels=1)
    assert reader_name_for(str(grabber)) == "TiffSequenceReader"
    assert reader_name_for(str(grabber / "tiff")) == "TiffSequenceReader"

    clouds = tmp_path / "clouds"
    clouds.mkdir()
    for name in ("scene10.pcd", "scene2.pcd"):
        (clouds / name).write_text("")
    assert reader_choice(str(clouds), 1).parameters == {"path": str(clouds / "scene10.pcd")}  # natural order
    assert reader_choice(str(clouds / "scene2.pcd")).name == "PcdReader"


def test_a_tum_style_pair_is_found_from_either_file(tmp_path: Path) -> None:
    color, depth = touch_image(tmp_path / "TUM_color.png"), touch_image(tmp_path / "TUM_depth.png", channels=1)
    assert pair_paths(color) == (color, depth)
    assert pair_paths(depth) == (color, depth)
    assert pair_paths(tmp_path / "shot_rgb_01.png") == (tmp_path / "shot_rgb_01.png", tmp_path / "shot_depth_01.png")
    assert reader_name_for(str(color)) == "TumPairReader"
    assert reader_name_for(str(depth)) == "TumPairReader"
    with pytest.raises(ValueError, match="single frame"):
        reader_for(str(color), 1)


def test_unknown_inputs_list_the_supported_layouts(tmp_path: Path) -> None:
    (tmp_path / "empty").mkdir()
    lonely = touch_image(tmp_path / "holiday.png")
    for path in (tmp_path / "missing", tmp_path / "empty", lonely):
        with pytest.raises(ValueError, match="supported inputs") as error:
            reader_name_for(str(path))
        assert all(layout in str(error.value) for layout in SUPPORTED_LAYOUTS)
    with pytest.raises(ValueError, match=">= 0"):
        reader_name_for(None, -1)


def test_choosing_a_reader_names_its_class_without_reading_the_frame(tmp_path: Path) -> None:
    color = touch_image(tmp_path / "x_color.png")
    touch_image(tmp_path / "x_depth.png", channels=1)
    choice = reader_choice(str(color))
    assert choice.reader is TumPairReader and choice.name == "TumPairReader"
    color.unlink()  # nothing was read while choosing; the reader reads when it runs
    assert isinstance(choice.create(), TumPairReader)


def test_association_takes_the_nearest_depth_within_the_tolerance() -> None:
    colors = [TimedImage(1.0, Path("c1")), TimedImage(2.0, Path("c2")), TimedImage(3.0, Path("c3"))]
    depths = [TimedImage(1.015, Path("d1")), TimedImage(1.99, Path("d2")), TimedImage(2.005, Path("d3"))]
    pairs = [(c.path.name, d.path.name) for c, d in associate(colors, depths)]
    assert pairs == [("c1", "d1"), ("c2", "d3")]
