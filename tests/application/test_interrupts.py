"""An interrupted ``robokudo query`` (SIGINT, SIGTERM) says so in one line, stops its experts and closes the store.

The query runs in a real subprocess and is interrupted while the text reader (OCR, a threaded expert running
ONNX sessions) works: the moment its native library is loaded into the process.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from reasoning.beliefs.store import BeliefStore

REPOSITORY = Path(__file__).resolve().parents[2]
OCR_LIBRARY = "onnxruntime"
"""Appears in the process's memory map when the text reader builds its OCR engine (imported on first use)."""


def _wait_for_library(process: subprocess.Popen[str], library: str, limit: float = 120.0) -> bool:
    """True once ``library`` is mapped into ``process``; False when the process ended or ``limit`` s passed."""
    maps = Path(f"/proc/{process.pid}/maps")
    deadline = time.monotonic() + limit
    while process.poll() is None and time.monotonic() < deadline:
        try:
            if library in maps.read_text():
                return True
        except OSError:
            return False
        time.sleep(0.01)
    return False


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/maps").exists(), reason="needs /proc to see when the OCR starts")
@pytest.mark.parametrize("sent", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_an_interrupted_query_exits_130_with_one_line(tmp_path: Path, sent: signal.Signals) -> None:
    store = tmp_path / "beliefs.sqlite"
    env = dict(
        os.environ,
        PYTHONPATH=str(REPOSITORY),
        HOME=str(tmp_path),
        XDG_DATA_HOME=str(tmp_path / "data"),
        ROBOKUDO_USER_ONTOLOGY=str(tmp_path / "user.ttl"),
        ROBOKUDO_BELIEF_STORE=str(tmp_path / "default.sqlite"),
    )
    process = subprocess.Popen(
        [sys.executable, "-m", "robokudo", "query", "find milk in fridge", "--store", str(store)],
        cwd=REPOSITORY,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        assert _wait_for_library(process, OCR_LIBRARY), "the query ended before its text reader started"
        process.send_signal(sent)
        out, err = process.communicate(timeout=120)
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()
    assert process.returncode == 130, err
    assert err == "interrupted\n"
    assert "#1" not in out  # no answer: the run was interrupted
    assert not Path(f"{store}-wal").exists()  # the store was closed (SQLite removes the WAL on a clean close)
    with BeliefStore(store) as opened:
        assert opened.integrity_check() == "ok"
