"""Run one bench script's worker in this checkout and in another git revision, on inputs prepared once.

The ``check_*`` scripts compare this checkout's output with a revision's to the last bit: the revision is exported
with ``git archive`` into a temporary folder, and each side runs ``SCRIPT REV --worker CHECKOUT FOLDER TAG`` in a
process of its own (so each imports its own code), writing its results into ``FOLDER`` under ``TAG`` ("ours" or
"theirs").
"""

from __future__ import annotations

import argparse
import io
import subprocess
import sys
import tarfile
import tempfile
from collections.abc import Callable
from pathlib import Path

import numpy as np

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


def compare_with_revision(
    script: str,
    description: str,
    prepare: Callable[[Path], list[str]],
    worker: Callable[[str, Path, list[str], str], None],
    report: Callable[[Path, list[str]], None],
    is_input: Callable[[str], bool] = lambda stem: True,
) -> None:
    """The command line of a ``check_*`` script: ``SCRIPT REV`` prepares the inputs (``prepare(folder)`` returns their
    names), runs ``worker(checkout, folder, names, tag)`` on both sides and calls ``report(folder, names)``; the
    hidden ``--worker CHECKOUT FOLDER TAG`` runs one side (its inputs: the ``.npz`` files whose stem ``is_input``)."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("reference", help="git revision to compare with")
    parser.add_argument("--worker", nargs=3, metavar=("CHECKOUT", "FOLDER", "TAG"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        checkout, folder, tag = args.worker
        names = sorted(path.stem for path in Path(folder).glob("*.npz") if is_input(path.stem))
        worker(checkout, Path(folder), names, tag)
        return
    with tempfile.TemporaryDirectory() as temporary:
        folder = Path(temporary)
        reference = export_revision(args.reference, folder)
        inputs = folder / "inputs"
        inputs.mkdir()
        names = prepare(inputs)
        run_both(script, args.reference, inputs, reference)
        report(inputs, names)


def report_npz_pairs(
    inputs: Path, names: list[str], equal: Callable[[dict, dict], bool], describe: Callable[[dict, dict], str]
) -> None:
    """Compare each input's ``ours-NAME.npz`` with ``theirs-NAME.npz`` by ``equal``, print each difference (what
    ``describe`` says of it) and the count of identical inputs."""
    same = 0
    for name in names:
        ours, theirs = np.load(inputs / f"ours-{name}.npz"), np.load(inputs / f"theirs-{name}.npz")
        if equal(ours, theirs):
            same += 1
        else:
            print(f"DIFFERENT: {name} ({describe(ours, theirs)})")
    print(f"identical on {same}/{len(names)} inputs")
