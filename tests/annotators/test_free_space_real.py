"""Free space on real tabletop frames (mOSD learn0, learn35, read in place from ../shared/data): the planned tree of a
free-space scan finds places on the table, and no labelled object point higher than 1 cm above the table lies
inside any of them (the labels score only)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from py_trees.common import Status

from queries import parse_query
from reasoning.planning.query_planner import plan_query
from robokudo.application.knowledge import load_knowledge_base
from robokudo.application.sensor_sources import sensor_source
from robokudo.core.engine import Engine
from robokudo.core.geometry import rotation_matrix
from robokudo.core.types import FreePlacement, Plane
from tests.annotators.conftest import require_folder
from trees.synthesis import build_tree

pytestmark = pytest.mark.real_data


@pytest.mark.parametrize("scene", ["learn0", "learn35"])
def test_placements_on_a_real_table_overlap_no_labelled_object(shared_data: Path, tmp_path: Path, scene: str) -> None:
    path = require_folder(shared_data / "pcl_mosd_tabletop" / "learn") / f"{scene}.pcd"
    kb = load_knowledge_base(tmp_path / "user.ttl")
    plan = plan_query(parse_query("scan { free_space: { footprint: [10cm, 10cm] } }"), kb, sensor_source(kb, str(path)))
    tree = build_tree(plan.plan)
    assert Engine(tree).run(until=lambda s: s in (Status.SUCCESS, Status.FAILURE)) is Status.SUCCESS
    reader = next(node for node in tree.iterate() if node.name == "PcdReader")
    labels = reader.last_frame.labels.reshape(-1)
    points = reader.last_frame.points.reshape(-1, 3)
    plane = max(tree.cas.annotations(Plane), key=lambda p: np.asarray(p.inlier_indices).size)
    table = points[(labels >= 1) & (labels <= 9) & np.isfinite(points).all(axis=1)]
    objects = points[(labels >= 20) & np.isfinite(points).all(axis=1)]
    objects = objects[objects @ plane.model[:3] + plane.model[3] > 0.01]
    placements = tree.cas.annotations(FreePlacement)
    assert placements, "a real table has room for a 10 cm square"
    for placement in placements:
        assert placement.frame == "camera" and min(placement.size) >= 0.1
        local = (objects - placement.position) @ rotation_matrix(placement.orientation)
        inside = (np.abs(local[:, 0]) <= placement.size[0] / 2) & (np.abs(local[:, 1]) <= placement.size[1] / 2)
        assert not inside.any(), f"{inside.sum()} object points inside a {placement.size} placement"
        on_table = (table - placement.position) @ rotation_matrix(placement.orientation)
        near = (np.abs(on_table[:, 0]) <= placement.size[0] / 2) & (np.abs(on_table[:, 1]) <= placement.size[1] / 2)
        assert near.any(), "a placement lies on the labelled table"
