"""Named regions of a semantic map: oriented boxes (the table top, the fridge interior, ...)."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from robokudo.core.geometry import pose_matrix


@dataclass(frozen=True, slots=True)
class RegionBox:
    """A named region: a box with its centre pose in ``frame`` (position in metres, unit quaternion x, y, z, w)
    and its size along its own axes; ``region_class`` is the ontology class, ``semantic_map`` the map it is in."""

    name: str
    region_class: str
    frame: str
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]
    size: tuple[float, float, float]
    label: str = ""
    semantic_map: str = ""

    @property
    def pose(self) -> np.ndarray:
        """The 4x4 homogeneous transform of the box centre in ``frame``."""
        return pose_matrix(self.position, self.orientation)

    def contains(self, point: np.ndarray | tuple[float, float, float], margin: float = 1e-9) -> bool:
        """True when ``point`` (in ``frame``) lies inside the box (grown by ``margin``)."""
        pose = self.pose
        local = pose[:3, :3].T @ (np.asarray(point, dtype=np.float64).reshape(3) - pose[:3, 3])
        return bool(np.all(np.abs(local) <= np.asarray(self.size, dtype=np.float64) / 2.0 + margin))


def region_of(point: np.ndarray | tuple[float, float, float], regions: Iterable[RegionBox]) -> RegionBox | None:
    """The first of ``regions`` whose box contains ``point``, or None."""
    for region in regions:
        if region.contains(point):
            return region
    return None
