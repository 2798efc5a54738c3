"""Run one bench script's worker in this checkout and in another git revision, on inputs prepared once.

The ``check_*`` scripts compare this checkout's output with a revision's to the last bit: the revision is exported
with ``git archive`` into a temporary folder, and each side runs ``SCRIPT REV --worker CHECKOUT FOLDER TAG`` in a
process of its own (so each imports its own code), writing its results into ``FOLDER`` under ``TAG`` ("ours" or
"theirs").
"""

from __future__ import annotations

import io
import subprocess
import sys
import tarfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def export_revision(revision: str, folder: Path) -> Path:
    """``revision``'s tree, exported with ``git archive`` into ``folder / "reference"``; that path."""
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", revision], check=True, capture_output=True)
    reference = folder / "reference"
    reference.mkdir()
    with tarfile.open(fileobj=io.BytesIO(archive.stdout)) as tar:
        tar.extractall(reference, filter="data")
    return reference


def run_both(script: str, revision: str, inputs: Path, reference: Path) -> None:
    """Run ``script``'s worker on ``inputs`` with this checkout (tag "ours") and with ``reference`` ("theirs")."""
    for tag, checkout in (("ours", str(ROOT)), ("theirs", str(reference))):
        subprocess.run([sys.executable, script, revision, "--worker", checkout, str(inputs), tag], check=True)
