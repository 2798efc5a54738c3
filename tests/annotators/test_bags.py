"""Bag decoding on small synthetic frames: every supported encoding, pairing by stamp, camera info arriving late,
and clear failures for what cannot be paired or decoded."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from annotators.readers.bag_io import bag_frames, read_bag_frame
from annotators.readers.choice import reader_name_for
from annotators.readers.frame_io import Frame, FrameError
from robokudo.core.types import CameraIntrinsics
from tests.annotators.bag_writing import write_bag

H, W = 24, 32
K = CameraIntrinsics(fx=30.0, fy=31.0, cx=15.5, cy=11.5, width=W, height=H)


def frames(count: int = 3) -> list[Frame]:
    """Frames with distinct colours and depths (depth on whole millimetres, so 16-bit depth is exact)."""
    generator = np.random.default_rng(7)
    made = []
    for _ in range(count):
        color = generator.integers(0, 256, (H, W, 3), dtype=np.uint8)
        depth = (generator.integers(300, 3000, (H, W)) / 1000.0).astype(np.float32)
        depth[0, :5] = 0.0  # no data
        made.append(Frame(color, depth, K))
    return made


@pytest.mark.parametrize("ros1", [True, False], ids=["ros1", "ros2"])
@pytest.mark.parametrize(
    ("color_encoding", "depth_encoding"), [("rgb8", "16UC1"), ("bgr8", "mono16"), ("rgb8", "32FC1")]
)
def test_every_encoding_reads_back_as_the_frame(
    tmp_path: Path, ros1: bool, color_encoding: str, depth_encoding: str
) -> None:
    written = frames()
    bag = write_bag(
        tmp_path / ("f.bag" if ros1 else "f"), written, ros1=ros1, color_encoding=color_encoding,
        depth_encoding=depth_encoding,
    )  # fmt: skip
    read = list(bag_frames(bag))
    assert len(read) == len(written)
    for original, frame in zip(written, read, strict=True):
        assert np.array_equal(frame.color, original.color)
        assert np.allclose(frame.depth, original.depth, atol=1e-6)
        assert frame.intrinsics == K


def test_pairs_made_before_the_first_camera_info_wait_for_it(tmp_path: Path) -> None:
    written = frames()
    bag = write_bag(tmp_path / "late", written, ros1=False, info_offset_ns=50_000_000)
    read = list(bag_frames(bag))
    assert len(read) == 3 and np.array_equal(read[0].color, written[0].color)


def test_colour_and_depth_too_far_apart_are_not_paired(tmp_path: Path) -> None:
    bag = write_bag(tmp_path / "apart.bag", frames(), ros1=True, depth_offset_ns=30_000_000)
    assert list(bag_frames(bag)) == []
    with pytest.raises(FrameError, match="holds 0 frame"):
        read_bag_frame(bag, 0)


def test_the_frame_stamp_is_the_colour_stamp(tmp_path: Path) -> None:
    bag = write_bag(tmp_path / "s", frames(), ros1=False, period_ns=250_000_000)
    assert [f.timestamp for f in bag_frames(bag)] == pytest.approx([1.7e9, 1.7e9 + 0.25, 1.7e9 + 0.5])


def test_a_ros2_bag_reads_from_its_folder_or_its_storage_file(tmp_path: Path) -> None:
    written = frames(2)
    for mcap, suffix in ((True, ".mcap"), (False, ".db3")):
        folder = write_bag(tmp_path / f"bag{suffix}-folder", written, ros1=False, mcap=mcap)
        (storage,) = folder.glob(f"*{suffix}")
        for path in (folder, storage):
            assert reader_name_for(str(path)) == "BagReader"
            assert np.array_equal(read_bag_frame(path, 1).color, written[1].color)


def test_a_file_that_is_no_bag_is_refused_with_the_layouts(tmp_path: Path) -> None:
    junk = tmp_path / "junk.bag"
    junk.write_bytes(b"not a bag at all")
    with pytest.raises(ValueError, match="cannot open the bag") as caught:
        reader_name_for(str(junk))
    assert "supported inputs" in str(caught.value) and junk.read_bytes() == b"not a bag at all"
