"""Sensor sources: which reader starts a plan for a given input or live stream, as a plan step."""

from __future__ import annotations

from annotators.readers.choice import reader_choice
from annotators.readers.frame_readers import PERSON_VIEW
from annotators.readers.streams import FrameStream, KitchenCameraStream, PerceivedFrameReader
from annotators.simulation.kitchen_person import person_spec_pose
from annotators.simulation.kitchen_scene import camera_looking_at
from reasoning.knowledge.knowledge_base import KnowledgeBase
from reasoning.planning.plan import Step
from reasoning.planning.planner import SensorSource
from robokudo.core.types import CameraIntrinsics

READERS_WITH_CAMERA_POSE: frozenset[str] = frozenset({"KitchenSceneReader"})
"""The readers whose frames carry the camera pose (``CameraInfo.cam_to_world``); recorded inputs have none."""


def kitchen_view_for(region: str | None, people: bool = False) -> str:
    """The kitchen camera view that looks at ``region`` ("table" for None, "overview" when no view looks at it);
    with ``people`` (a query about a person in a kitchen that holds one) and no region, the view that sees the
    table and the person behind it."""
    if region is None:
        return PERSON_VIEW if people else "table"
    try:
        return camera_looking_at(region)
    except ValueError:
        return "overview"


def served_source(kb: KnowledgeBase, stream: FrameStream) -> SensorSource:
    """The source of a task in a served tree: the frame the engine perceived from ``stream`` this run (frames of
    the kitchen camera carry its pose, recordings none)."""
    spec = kb.annotator(PerceivedFrameReader.__name__)
    step = Step(
        annotator=spec.name,
        implemented_by=spec.implemented_by,
        inputs=spec.inputs,
        outputs=spec.outputs,
        parameters=(),
        reason=f"{spec.name}: takes the frame the engine perceived from {stream.name}",
    )
    return SensorSource(step, camera_pose=isinstance(stream, KitchenCameraStream))


def sensor_source(
    kb: KnowledgeBase,
    input_path: str | None,
    frame: int = 0,
    region: str | None = None,
    intrinsics: CameraIntrinsics | None = None,
    person: str | None = None,
) -> SensorSource:
    """The reader for ``input_path`` (the built-in kitchen when None, looking at ``region`` if given; the camera
    ``intrinsics`` of a point-cloud input when given). ``person`` puts a person into the kitchen (a spec such as
    ``point:red_cup@0.2,0.7``, see ``annotators.simulation.kitchen_person``); the camera then looks at the table
    and the person unless a region is named.

    The source says whether the reader's frames carry the camera pose, which regions of the map need. The reader is
    picked from the path's layout (``annotators.readers.choice.reader_choice``); a path of no known
    layout raises ValueError listing the supported ones.
    """
    if input_path is None:
        view = kitchen_view_for(region)
        reason = f"renders the built-in kitchen from the {view!r} camera"
        if region is not None:
            reason += f" (the robot looks at region {region!r})"
        spec = kb.annotator("KitchenSceneReader")
        parameters: tuple[tuple[str, object], ...] = (("view", view),)
        if person is not None:
            person_spec_pose(person)  # a bad spec is refused here, with the reason, before anything runs
            view = view if region is not None else PERSON_VIEW
            parameters = (("person", person), ("view", view))
            reason = f"renders the built-in kitchen with a person ({person}) from the {view!r} camera"
    elif person is not None:
        raise ValueError("a person can be put only into the built-in kitchen, not into a recorded input")
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
