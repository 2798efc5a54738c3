"""Whether this checkout's support plane is exactly another git revision's, on the clutter checks' inputs.

``python bench/check_support_planes.py REV`` prepares the inputs of :mod:`bench.check_clutter_labels` once (the
uoc, mOSD, pcl_tabletop_pcd and grabber frames and the rendered 15-object scene, each with its range mask); then this
checkout and REV (exported with ``git archive``) each fit the support plane the tabletop tree uses
(:func:`~annotators.cloud.support_choice.find_support_plane`, or the RANSAC plane of a revision without it) on
them in a worker process of their own, and the models (to the last bit) and inlier indices are compared input by
input. Prints one line per differing input and ``identical on N/N inputs``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from check_clutter_labels import prepare
from revision_workers import compare_with_revision, report_npz_pairs


def worker(checkout: str, folder: Path, names: list[str], tag: str) -> None:
    """Fit the checkout's support plane on every prepared input; write ``{tag}-{name}.npz`` with model and inliers."""
    sys.path.insert(0, checkout)
    try:  # the plane the tabletop tree uses; revisions before the support choice used the dominant plane
        from annotators.cloud.support_choice import find_support_plane as support_plane
    except ImportError:
        from annotators.cloud.plane import ransac_support_plane as support_plane

    for name in names:
        data = np.load(folder / f"{name}.npz")
        fit = support_plane(data["points"], data["mask"])
        model = np.full(4, np.nan) if fit is None else fit.model
        inliers = np.zeros(0, np.int64) if fit is None else np.asarray(fit.inlier_indices, dtype=np.int64)
        np.savez(folder / f"{tag}-{name}.npz", model=model, inliers=inliers)


def report(inputs: Path, names: list[str]) -> None:
    """Compare the two sides' planes input by input and print the differences and the count."""
    report_npz_pairs(
        inputs,
        names,
        lambda ours, theirs: (
            np.array_equal(ours["model"], theirs["model"], equal_nan=True)
            and np.array_equal(ours["inliers"], theirs["inliers"])
        ),
        lambda ours, theirs: f"{ours['inliers'].size} vs {theirs['inliers'].size} inliers",
    )


def main() -> None:
    compare_with_revision(__file__, __doc__.split("\n")[0], prepare, worker, report, lambda stem: "-" not in stem)


if __name__ == "__main__":
    main()
