"""Fixtures of the annotator tests: where the shared real RGB-D data lives."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]
SHARED_DATA = REPO_ROOT.parent / "shared" / "data"


def require_folder(path: Path) -> Path:
    """``path`` when it is a folder; else skip (CI unset) or fail (CI set: the data must be there)."""
    if path.is_dir():
        return path
    if "CI" in os.environ:
        pytest.fail(f"real data folder {path} is missing (CI={os.environ['CI']!r} requires it)")
    pytest.skip(f"real data folder {path} is missing")


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The shared data folder ``../shared/data`` beside the repository."""
    return require_folder(SHARED_DATA)


@pytest.fixture(scope="session")
def uoc_folder(shared_data: Path) -> Path:
    """The real RealSense tabletop frames (uoc layout), read in place."""
    return require_folder(shared_data / "uoc_tabletop_realsense")
