"""HumanTracker: follows one person from frame to frame with a particle filter over the people detections."""

from __future__ import annotations

from typing import ClassVar

from annotators.tracking.tracker import TargetTracker
from robokudo.core.capability import Capability
from robokudo.core.types import PERSON_CLASS, CameraInfo, CasType, PersonHypothesis, PersonTrack, PointCloud


class HumanTracker(TargetTracker):
    """Follows one person: a particle filter (predict; associate the nearest person detection; weight; resample)
    giving the person's 3-D and image position in every frame."""

    inputs: ClassVar[tuple[type[CasType], ...]] = (PersonHypothesis,)
    optional_inputs: ClassVar[tuple[type[CasType], ...]] = (PointCloud, CameraInfo)
    outputs: ClassVar[tuple[type[CasType], ...]] = (PersonTrack,)
    capability: ClassVar[Capability] = Capability(
        label="human tracker",
        synonyms=("people tracker", "person follower"),
        classes=(PERSON_CLASS,),
        cost_ms=2.0,
        reliability=0.8,
    )
    track_type = PersonTrack
    hypothesis_type = PersonHypothesis

    def target_name(self) -> str:
        """A person."""
        return PERSON_CLASS
