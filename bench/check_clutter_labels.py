"""Whether this checkout's clutter segmentation gives exactly the segments of another git revision's.

``python bench/check_clutter_labels.py REV`` prepares the segmenter's inputs once (organized points, range mask,
RANSAC plane, colours) for every frame of ../shared/data/uoc_tabletop_realsense, every mOSD learn scene, the
pcl_tabletop_pcd clouds, the pcl_grabber TIFF frames and the rendered 15-object scene of
:mod:`bench.bench_segmentation`; then this checkout and REV (exported with ``git archive``) each segment them in a
worker process of their own, and their segments (point indices, masks, ROIs, in order) are compared input by input.
Prints one line per differing input and ``identical on N/N inputs``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from revision_workers import compare_with_revision, report_npz_pairs

ROOT = Path(__file__).resolve().parents[1]
DATA = (ROOT.parent / "shared" / "data").resolve()


def prepare(folder: Path) -> list[str]:
    """Write each input's ``points``, ``mask``, ``model``, ``plane`` and ``colors`` to ``folder``; their names."""
    sys.path.insert(0, str(ROOT))
    from annotators.cloud.filters import range_mask
    from annotators.cloud.point_cloud import back_project, pixel_rays
    from annotators.cloud.support_choice import find_support_plane
    from annotators.readers.frame_io import FrameError, read_color_depth_pair
    from annotators.readers.pcd_io import read_pcd
    from annotators.readers.tiff_io import read_tiff_frame
    from bench.bench_segmentation import fifteen_objects

    frames: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for index in range(5):
        frame = read_color_depth_pair(DATA / "uoc_tabletop_realsense", index)
        frames[f"uoc{index}"] = back_project(frame.depth, pixel_rays(frame.intrinsics)), frame.color
    for path in sorted((DATA / "pcl_mosd_tabletop" / "learn").glob("*.pcd")) + sorted(
        (DATA / "pcl_tabletop_pcd").glob("*.pcd")
    ):
        try:
            frame = read_pcd(path)
        except FrameError as error:  # a cloud without colour: not a frame the tree reads
            print(f"skipped {path.name}: {error}")
            continue
        if frame.points is not None:
            frames[path.stem] = frame.points, frame.color
    grabber = DATA / "pcl_grabber_sequences"
    for index in range(len(list((grabber / "tiff").glob("*_depth.tiff")))):
        frame = read_tiff_frame(grabber, index)
        frames[f"grabber{index}"] = back_project(frame.depth, pixel_rays(frame.intrinsics)), frame.color
    frames["fifteen_objects"] = fifteen_objects()
    for name, (points, colors) in frames.items():
        points = np.ascontiguousarray(points, dtype=np.float32)
        mask = range_mask(points, np.isfinite(points[..., 2]), 0.2, 2.5)
        fit = find_support_plane(points, mask)
        np.savez(
            folder / f"{name}.npz", points=points, mask=mask, model=fit.model, plane=fit.inlier_indices, colors=colors
        )
    return list(frames)


def worker(checkout: str, folder: Path, names: list[str], tag: str) -> None:
    """Segment every prepared input with the checkout's segmenter; write ``{tag}-{name}.npz`` with the segments."""
    sys.path.insert(0, checkout)
    from annotators.cloud.clutter import ClutterParameters, segment_clutter

    for name in names:
        data = np.load(folder / f"{name}.npz")
        segments = segment_clutter(
            data["points"], data["mask"], data["model"], data["plane"], ClutterParameters(), data["colors"]
        )
        np.savez(
            folder / f"{tag}-{name}.npz",
            sizes=np.array([s.indices.size for s in segments], dtype=np.int64),
            indices=np.concatenate([s.indices for s in segments]) if segments else np.zeros(0, np.int64),
            masks=np.array([np.packbits(s.mask) for s in segments]),
            rois=np.array([s.roi for s in segments], dtype=np.int64),
        )


def report(inputs: Path, names: list[str]) -> None:
    """Compare the two sides' results input by input and print the differences and the count."""
    report_npz_pairs(
        inputs,
        names,
        lambda ours, theirs: all(np.array_equal(ours[k], theirs[k]) for k in ("sizes", "indices", "masks", "rois")),
        lambda ours, theirs: f"{ours['sizes'].size} vs {theirs['sizes'].size} segments",
    )


def main() -> None:
    compare_with_revision(__file__, __doc__.split("\n")[0], prepare, worker, report, lambda stem: "-" not in stem)


if __name__ == "__main__":
    main()
