"""``robokudo beliefs | head -1``: when the reader of the output goes away the command stops quietly (no traceback),
with the exit status a shell gives a killed pipe writer."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from robokudo.application.console import BROKEN_PIPE_STATUS

REPOSITORY = Path(__file__).resolve().parents[2]


def test_a_closed_output_pipe_ends_the_command_without_a_traceback(tmp_path: Path) -> None:
    read_end, write_end = os.pipe()
    os.close(read_end)  # the reader is gone before the command writes anything
    try:
        finished = subprocess.run(
            [sys.executable, "-m", "robokudo", "beliefs", "--store", str(tmp_path / "beliefs.sqlite")],
            stdout=write_end,
            stderr=subprocess.PIPE,
            text=True,
            cwd=REPOSITORY,
            env={**os.environ, "ROBOKUDO_USER_ONTOLOGY": str(tmp_path / "user.ttl")},
            timeout=120,
        )
    finally:
        os.close(write_end)
    assert "Traceback" not in finished.stderr
    assert "BrokenPipeError" not in finished.stderr
    assert finished.returncode == BROKEN_PIPE_STATUS
