"""A person's points leave out the support surfaces beside her: surfaces facing up below her shoulders (a table
she stands behind, the floor), which depth joins to her body where it meets their far edge.

On ray-cast clouds the floor is cut and a standing body is not; in the kitchen, the pose detector's points of a
person standing right behind the table (its far edge at her hips) hold almost none of the table, and her position
stays near the centroid of her visible surface (robokudo's definition, ``RenderedScene.person_position``). The
clearance and tilt were set from the body's shape (shoulders and head face up; a table is level), not on these
frames; the positions along the table are spread over its length and three distances behind it."""

from __future__ import annotations

from typing import ClassVar

import numpy as np
import pytest

from annotators.catalog import AnnotatorCatalog
from annotators.cloud.people import IMAGE_UP
from annotators.image.human_pose import HumanPoseDetector
from annotators.people.body_points import support_surfaces
from annotators.readers.frame_readers import KITCHEN_RECORDING
from annotators.simulation.kitchen_person import PERSON_OBJECT_ID, Motion, PersonScript, person_view
from annotators.simulation.kitchen_scene import RenderedScene, render_kitchen
from robokudo.core.annotator import Annotator
from robokudo.core.engine import Engine
from robokudo.core.pipeline import Pipeline
from robokudo.core.types import CameraInfo, CasType, ColorImage, DepthImage, PersonHypothesis, Pose
from tests.annotators.test_people_synthetic import CAMERA_HEIGHT, render

MAX_OTHER_SHARE = 0.05
"""The most of a person's points that may belong to something else (the renderer's ids say whose a pixel is)."""
MAX_POSITION_ERROR = 0.10


def test_the_floor_is_cut_and_a_standing_body_is_not() -> None:
    cloud = render([(0.0, 2.5, 0.2, 1.7)])
    allowed = np.isfinite(cloud[..., 2])
    height = -cloud[..., 1]  # camera frame: y points down, the camera is CAMERA_HEIGHT above the floor
    shoulders = 1.45 - CAMERA_HEIGHT
    cut = support_surfaces(cloud, allowed, IMAGE_UP, below=shoulders - 0.15)
    with np.errstate(invalid="ignore"):
        floor = allowed & (height < 0.02 - CAMERA_HEIGHT)
        body = allowed & (np.abs(cloud[..., 2] - 2.5) < 0.25) & (height > 0.1 - CAMERA_HEIGHT)
    assert body.sum() > 500 and floor.sum() > 500
    inner_floor = floor.copy()
    inner_floor[:3] = inner_floor[-3:] = False
    inner_floor[:, :3] = inner_floor[:, -3:] = False
    assert cut[inner_floor].mean() > 0.95  # the floor (but the image border, where a neighbour is missing)
    assert not cut[body].any()  # the body's sides face the camera, not up
    assert not support_surfaces(cloud, allowed, IMAGE_UP, below=-CAMERA_HEIGHT - 0.1).any()  # all higher: kept


class SceneReader(Annotator):
    """Writes one rendered kitchen frame as the kitchen reader does."""

    inputs: ClassVar[tuple[type[CasType], ...]] = ()
    outputs: ClassVar[tuple[type[CasType], ...]] = (ColorImage, DepthImage, CameraInfo)

    def __init__(self, scene: RenderedScene) -> None:
        super().__init__(name="KitchenSceneReader")
        self.scene = scene

    def analyse(self) -> None:
        scene = self.scene
        self.write(ColorImage(scene.color))
        self.write(DepthImage(scene.depth))
        self.write(CameraInfo(intrinsics=scene.intrinsics, cam_to_world=scene.cam_to_world, frame_id="kitchen/person",
                              timestamp=0.0, recording=KITCHEN_RECORDING))  # fmt: skip


@pytest.mark.parametrize("behind", [0.5, 0.55, 0.6])
@pytest.mark.parametrize("along", [-0.8, -0.4, 0.0, 0.4, 0.8])
def test_a_person_behind_the_table_has_her_own_points_and_position(along: float, behind: float) -> None:
    pose = PersonScript((Motion("walk", 1.0, ((along - 0.15, behind), (along + 0.15, behind))),)).pose_at(0.5)
    scene = render_kitchen(person_view(), seed=7, person=pose)
    catalog = AnnotatorCatalog.discover()
    detector = HumanPoseDetector()
    root = Pipeline(
        "person", [SceneReader(scene), catalog["PointCloudGenerator"](), catalog["RangeFilter"](), detector]
    )
    Engine(root).tick()
    (person,) = root.cas.annotations(PersonHypothesis)
    owners = scene.object_ids.reshape(-1)[person.point_indices]
    assert np.mean(owners != PERSON_OBJECT_ID) <= MAX_OTHER_SHARE
    rotation, shift = scene.cam_to_world[:3, :3], scene.cam_to_world[:3, 3]
    position = rotation @ person.first(Pose).position + shift
    assert np.linalg.norm(position - scene.person_position()) <= MAX_POSITION_ERROR
