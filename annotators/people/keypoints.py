"""Named access to a person's body keypoints and the arm geometry both activity and pointing read."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robokudo.core.types import BodyKeypoints


@dataclass(frozen=True)
class Arm:
    """One arm's 3-D joints (camera frame): shoulder, elbow, wrist; ``side`` is ``left`` or ``right``."""

    side: str
    shoulder: np.ndarray
    elbow: np.ndarray
    wrist: np.ndarray

    @property
    def reach(self) -> np.ndarray:
        """Shoulder to wrist."""
        return self.wrist - self.shoulder

    @property
    def straightness(self) -> float:
        """Shoulder-wrist distance over the length along the elbow (1 for a straight arm)."""
        along = np.linalg.norm(self.elbow - self.shoulder) + np.linalg.norm(self.wrist - self.elbow)
        return float(np.linalg.norm(self.reach) / along) if along > 0 else 0.0


def point(keypoints: BodyKeypoints, name: str) -> np.ndarray | None:
    """The 3-D point of keypoint ``name``, None when it has no depth or the model has no such keypoint."""
    if name not in keypoints.names:
        return None
    found = np.asarray(keypoints.points[keypoints.names.index(name)], dtype=np.float64)
    return found if np.all(np.isfinite(found)) else None


def midpoint(keypoints: BodyKeypoints, first: str, second: str) -> np.ndarray | None:
    """The middle of two keypoints (or the one that has depth)."""
    a, b = point(keypoints, first), point(keypoints, second)
    if a is None or b is None:
        return a if b is None else b
    return (a + b) / 2


def arms(keypoints: BodyKeypoints) -> list[Arm]:
    """The arms whose shoulder, elbow and wrist all have a 3-D point."""
    found = []
    for side in ("left", "right"):
        joints = [point(keypoints, f"{side}_{joint}") for joint in ("shoulder", "elbow", "wrist")]
        if all(j is not None for j in joints):
            shoulder, elbow, wrist = joints
            found.append(Arm(side, shoulder, elbow, wrist))  # type: ignore[arg-type]
    return found


def body_down(keypoints: BodyKeypoints, up: np.ndarray | None) -> np.ndarray | None:
    """The unit direction from the shoulders down the body: the world's down when ``up`` is known, else from the
    shoulders to the hips; None when neither is available."""
    if up is not None:
        return -np.asarray(up, dtype=np.float64) / np.linalg.norm(up)
    shoulders = midpoint(keypoints, "left_shoulder", "right_shoulder")
    hips = midpoint(keypoints, "left_hip", "right_hip")
    if shoulders is None or hips is None or np.linalg.norm(hips - shoulders) < 1e-6:
        return None
    return (hips - shoulders) / np.linalg.norm(hips - shoulders)


def angle(a: np.ndarray, b: np.ndarray) -> float:
    """The angle between two vectors, radians."""
    cosine = float(np.dot(a, b) / (np.linalg.norm(a) * np.linalg.norm(b)))
    return float(np.arccos(np.clip(cosine, -1.0, 1.0)))
