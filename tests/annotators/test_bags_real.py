"""ROS 1 and ROS 2 bags written with rosbags' own writers from shared real frames read back as the same frames.

The uoc frames are written as sensor_msgs/Image colour (rgb8) + depth (16UC1, mm) + CameraInfo, the organized PCD
as a PointCloud2; BagReader must put a known pixel at the same 3-D point as the uoc reader (within 1 mm), and the
tabletop tree must run on the bag as on any other input.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from py_trees.common import Status

from annotators.readers.bag_io import read_bag_frame
from annotators.readers.choice import reader_choice, reader_name_for
from annotators.readers.frame_io import Frame, read_color_depth_pair
from annotators.readers.frame_readers import BagCloudReader, BagReader, ColorDepthPairReader, PcdReader
from annotators.readers.pcd_io import read_pcd
from robokudo.application import cli
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import CameraInfo, ObjectHypothesis
from tests.annotators.bag_writing import COLOR_TOPIC, DEPTH_TOPIC, INFO_TOPIC, write_bag
from tests.annotators.conftest import require_folder
from tests.annotators.test_readers_real import PIXELS, cloud_of
from trees.tabletop import create_tree

pytestmark = pytest.mark.real_data

FRAMES = 3


@pytest.fixture(scope="module")
def uoc_frames(uoc_folder: Path) -> list[Frame]:
    return [read_color_depth_pair(uoc_folder, i) for i in range(FRAMES)]


@pytest.fixture(scope="module", params=["ros1", "ros2"])
def bag(request: pytest.FixtureRequest, uoc_frames: list[Frame], tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp(request.param)
    ros1 = request.param == "ros1"
    return write_bag(folder / ("frames.bag" if ros1 else "frames"), uoc_frames, ros1=ros1)


def test_the_entry_point_chooses_the_bag_reader(bag: Path) -> None:
    choice = reader_choice(str(bag), 2)
    assert (choice.name, choice.parameters) == ("BagReader", {"path": str(bag), "frame": 2})


@pytest.mark.parametrize("frame", [0, 2])
def test_a_pixel_lands_where_the_uoc_reader_puts_it(bag: Path, uoc_folder: Path, frame: int) -> None:
    pipeline, cloud = cloud_of(BagReader(bag, frame=frame))
    _, expected = cloud_of(ColorDepthPairReader(uoc_folder, frame=frame))
    for u, v in PIXELS:
        assert np.isfinite(expected.points[v, u]).all()
        error = np.linalg.norm(cloud.points[v, u].astype(np.float64) - expected.points[v, u])
        assert error < 0.001, f"pixel ({u}, {v}) of frame {frame} is {1000 * error:.2f} mm off"
    info = pipeline.cas.view(CameraInfo)
    assert info.recording == str(bag.resolve()) and info.timestamp == pytest.approx(1.7e9 + 0.1 * frame)


def test_topics_can_be_named_and_a_wrong_name_is_a_clear_failure(bag: Path) -> None:
    named = BagReader(bag, frame=1, color_topic=COLOR_TOPIC, depth_topic=DEPTH_TOPIC, info_topic=INFO_TOPIC)
    cloud_of(named)
    wrong = BagReader(bag, color_topic="/camera/rgb")
    pipeline_status = _run(wrong)
    assert pipeline_status is Status.FAILURE
    assert "no topic /camera/rgb" in wrong.feedback_message and COLOR_TOPIC in wrong.feedback_message


def test_a_frame_past_the_end_names_the_count(bag: Path) -> None:
    reader = BagReader(bag, frame=FRAMES)
    assert _run(reader) is Status.FAILURE
    assert f"holds {FRAMES} frame(s), no frame {FRAMES}" in reader.feedback_message


def test_the_tabletop_tree_runs_on_the_bag(bag: Path) -> None:
    pipeline = create_tree(str(bag), frame=1)
    pipeline.tick_once()
    assert pipeline.status is Status.SUCCESS, [(n.name, n.feedback_message) for n in pipeline.children]
    assert pipeline.cas.annotations(ObjectHypothesis)


def test_a_point_cloud_bag_reads_back_as_the_same_cloud(shared_data: Path, tmp_path: Path) -> None:
    pcd = require_folder(shared_data / "pcl_tabletop_pcd") / "table_scene_mug_stereo_textured.pcd"
    original = read_pcd(pcd)
    for ros1 in (True, False):
        bag = write_bag(tmp_path / ("cloud.bag" if ros1 else "cloud"), [original], ros1=ros1, cloud=True)
        assert reader_name_for(str(bag)) == "BagCloudReader"
        frame = read_bag_frame(bag)
        assert frame.points is not None and original.points is not None
        assert np.array_equal(frame.points, original.points, equal_nan=True)
        assert np.array_equal(frame.color, original.color)
        assert frame.intrinsics == original.intrinsics
        _, cloud = cloud_of(BagCloudReader(bag))
        _, expected = cloud_of(PcdReader(pcd))
        assert np.array_equal(cloud.mask, expected.mask)


def _run(reader: BagReader) -> Status:
    pipeline = Pipeline("read", [reader])
    pipeline.tick_once()
    return reader.status


def test_robokudo_query_on_the_bag_answers_as_on_the_uoc_folder(
    bag: Path, uoc_folder: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    answers = []
    for name, source in (("bag", bag), ("uoc", uoc_folder)):
        monkeypatch.setenv("ROBOKUDO_BELIEF_STORE", str(tmp_path / f"{name}.sqlite"))
        monkeypatch.setenv("ROBOKUDO_USER_ONTOLOGY", str(tmp_path / f"{name}.ttl"))
        # frame 1 holds the blue mug and no cup (a can once answered "cup" there)
        query = ["query", "detect { obj: { type: Mug } }", "--input", str(source), "--frame", "1", "--json"]
        assert cli.main(query) == 0
        answers.append(json.loads(capsys.readouterr().out)["objects"])
    from_bag, from_uoc = ([np.asarray(o["pose"]["position"]) for o in objects] for objects in answers)
    assert len(from_bag) == len(from_uoc) > 0
    for position, expected in zip(sorted(from_bag, key=tuple), sorted(from_uoc, key=tuple), strict=True):
        assert np.linalg.norm(position - expected) < 0.001
