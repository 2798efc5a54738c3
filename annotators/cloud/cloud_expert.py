"""CloudExpert: the shared input checks of experts that work on the 3-D points of each object hypothesis."""

from __future__ import annotations

from abc import abstractmethod
from typing import ClassVar

from annotators.cloud.point_cloud import cloud_problem
from robokudo.core.annotator import Annotator
from robokudo.core.types import ObjectHypothesis, PointCloud


class CloudExpert(Annotator):
    """Base of the pose, size and shape experts; ``purpose`` completes "no object hypotheses to ..."."""

    purpose: ClassVar[str] = "describe"

    @abstractmethod
    def analyse(self) -> None:
        """Describe each hypothesis (subclasses)."""

    def usable_cloud(self) -> PointCloud:
        """The point cloud, or FAILURE with the reason it cannot be used."""
        cloud = self.view(PointCloud)
        problem = cloud_problem(cloud)
        if problem:
            self.fail(problem)
        return cloud

    def hypotheses(self) -> list[ObjectHypothesis]:
        """The object hypotheses, or FAILURE when there are none."""
        found = self.annotations(ObjectHypothesis)
        if not found:
            self.fail(f"no object hypotheses to {self.purpose}")
        return found
