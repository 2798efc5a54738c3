"""``robokudo serve --rerun FILE.rrd``: after SIGTERM the file holds the answered goal's frame, its beliefs and the
tree's status changes (not one entry per tick)."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from robokudo.application import cli
from tests.application.rerun_reading import labels, read_recording
from tests.application.server.conftest import start_server


def test_serve_records_the_answered_goals_frame_and_its_beliefs(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "served.rrd"
    served = start_server(tmp_path, "--rerun", str(path))
    try:
        assert cli.main(["ask", "--server", served.url, "find milk in fridge"]) == 0
        assert "lactose free milk" in capsys.readouterr().out
        time.sleep(3.0)  # the engine keeps ticking at 30 Hz with an idle slot (well past 12 ticks even when loaded)
    finally:
        assert served.stop() == 0
    recording = read_recording(path)
    (tick,) = recording.ticks("/world/camera/image/color")
    for entity in ("/world/camera/image/depth", "/world/camera/points", "/world/objects"):
        assert recording.ticks(entity) == [tick]
    hypotheses = labels(recording.at("/world/camera/image/hypotheses", tick), "Boxes2D")
    assert hypotheses and hypotheses[0].startswith("#1 lactose free milk")
    assert labels(recording.at("/world/beliefs/1", tick), "Points3D") == ["#1 lactose free milk"]
    tree = recording.of("/tree")
    texts = [row.components["TextLog:text"][0] for row in tree]
    assert any(text.startswith("query: SUCCESS") for text in texts)
    assert texts[-1].startswith("idle: SUCCESS")  # the slot idles again after the goal
    # a few status changes over ~90 ticks (3 s at 30 Hz), not one entry a tick (the last entry is the slot going
    # idle, so its tick says how long the goal ran, not how many ticks followed)
    assert len(tree) <= 12
