"""Sensor sources: which reader starts a plan for a given input, as a plan step."""

from __future__ import annotations

from annotators.readers.choice import reader_choice
from annotators.simulation.kitchen_scene import camera_looking_at
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.plan import Step
from reasoning.planning.planner import SensorSource
from robokudo.core.types import CameraIntrinsics

READERS_WITH_CAMERA_POSE: frozenset[str] = frozenset({"KitchenSceneReader"})
"""The readers whose frames carry the camera pose (``CameraInfo.cam_to_world``); recorded inputs have none."""


def sensor_source(
    kb: KnowledgeBase,
    input_path: str | None,
    frame: int = 0,
    region: str | None = None,
    intrinsics: CameraIntrinsics | None = None,
) -> SensorSource:
    """The reader for ``input_path`` (the built-in kitchen when None, looking at ``region`` if given; the camera
    ``intrinsics`` of a point-cloud input when given).

    The source says whether the reader's frames carry the camera pose, which regions of the map need. The reader is
    picked from the path's layout (``annotators.readers.choice.reader_choice``); a path of no known
    layout raises ValueError listing the supported ones.
    """
    if input_path is None:
        view = "table"
        reason = "renders the built-in kitchen from the 'table' camera"
        if region is not None:
            try:
                view = camera_looking_at(region)
            except ValueError:
                view = "overview"
            reason = f"renders the built-in kitchen from the {view!r} camera (the robot looks at region {region!r})"
        spec = kb.annotator("KitchenSceneReader")
        parameters: tuple[tuple[str, object], ...] = (("view", view),)
    else:
        choice = reader_choice(input_path, frame, intrinsics)
        spec = kb.annotator(choice.name)
        parameters = tuple(sorted(choice.parameters.items()))
        reason = f"reads frame {frame} of {input_path}"
    step = Step(
        annotator=spec.name,
        implemented_by=spec.implemented_by,
        inputs=spec.inputs,
        outputs=spec.outputs,
        parameters=parameters,
        reason=f"{spec.name}: {reason}",
    )
    return SensorSource(step, camera_pose=spec.name in READERS_WITH_CAMERA_POSE)
