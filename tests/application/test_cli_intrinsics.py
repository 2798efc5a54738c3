"""``--intrinsics`` gives the camera of an unorganized point cloud to ``robokudo run`` and ``robokudo query``."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from robokudo.application import cli
from robokudo.application.commands.input_options import parse_intrinsics
from robokudo.core.types import CameraIntrinsics
from tests.annotators.conftest import SHARED_DATA, require_folder
from tests.annotators.test_unorganized_real import write_unorganized


@pytest.fixture(scope="module")
def unorganized(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """learn0 (two boxes) as a shuffled HEIGHT 1 cloud, with nothing beside it."""
    learn = require_folder(SHARED_DATA / "pcl_mosd_tabletop" / "learn")
    path = tmp_path_factory.mktemp("unorganized") / "boxes.pcd"
    write_unorganized(path, learn / "learn0.pcd")
    return path


def command(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    capsys.readouterr()
    status = cli.main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


@pytest.mark.real_data
def test_run_and_query_read_an_unorganized_cloud_with_the_given_camera(
    capsys: pytest.CaptureFixture[str], unorganized: Path, tmp_path: Path
) -> None:
    camera = "--intrinsics=525,525,319.5,239.5"
    status, out, _ = command(capsys, "run", "tabletop", "--input", str(unorganized), camera)
    table = out[out.index("#  colour") :].splitlines()[1:]
    assert status == 0 and [row.split()[0] for row in table if row.strip()] == ["1", "2"], out  # the two boxes
    store = str(tmp_path / "beliefs.sqlite")
    status, out, err = command(
        capsys, "query", "find all objects", "--input", str(unorganized), camera, "--json", "--store", store
    )
    assert status == 0, err
    assert len(json.loads(out)["objects"]) == 2


def test_intrinsics_are_parsed_and_checked(capsys: pytest.CaptureFixture[str]) -> None:
    assert parse_intrinsics("525,525,319.5,239.5") == CameraIntrinsics(525.0, 525.0, 319.5, 239.5, 640, 480)
    assert parse_intrinsics("600,600,300,200,600,400").width == 600
    for bad in ("525,525,319.5", "a,b,c,d", "0,525,319.5,239.5"):
        with pytest.raises(ValueError, match="fx,fy,cx,cy"):
            parse_intrinsics(bad)
    status, out, err = command(capsys, "run", "tabletop", "--intrinsics", "525,525,319.5,239.5")
    assert (status, out) == (2, "") and "--intrinsics needs --input" in err
    status, out, err = command(capsys, "query", "find a box", "--input", "x.pcd", "--intrinsics", "1,2")
    assert (status, out) == (2, "") and "fx,fy,cx,cy" in err
