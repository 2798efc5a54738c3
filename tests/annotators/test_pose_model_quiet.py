"""Loading the pose model printed ``AttributeError: 'MessageFactory' object has no attribute 'GetPrototype'`` on
stderr (mediapipe's protobuf bindings, harmless), which a user asking ``find the person`` read as a crash."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def test_loading_the_pose_model_prints_no_python_error() -> None:
    pytest.importorskip("mediapipe")
    code = "from annotators.image.human_pose import load_pose_model; load_pose_model().close(); print('loaded')"
    done = subprocess.run(
        [sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == 0 and done.stdout.strip() == "loaded", done.stderr
    assert "Error" not in done.stderr and "Traceback" not in done.stderr, done.stderr
