"""Identity across frames: which of this frame's objects is which known belief.

The cost of pairing an observation with a belief is a sum of squared normalised distances, each gated:

* position: ``(d / position_sigma)^2``, gate ``d <= gate_distance`` (metres; both in the same frame);
* size: ``(log(ratio) / size_sigma)^2`` of the typical sizes (geometric mean of the extents, the cube root of the
  box volume: less swayed than the largest extent by one axis a partial view or stray points of the supporting
  surface stretch), gate ``ratio <= size_ratio_gate``;
* appearance: ``(bhattacharyya_distance / appearance_sigma)^2`` of the colour histograms, gate
  ``<= appearance_gate``; when a histogram is missing, a mismatch of the stated colours adds ``color_penalty``;
* class: incompatible classes (neither subsumes the other) add ``class_penalty``; they are not gated out, since
  one object classified differently in two frames is still one object (the conflict is kept in its class
  alternatives).

Only positions of one world are compared (:func:`same_world`): the same fixed frame (``world``, known when the
camera pose is), or the same camera frame of the same recording.

:func:`pair_cost` states the rule for one pair; :func:`gated_costs` computes its position, size and appearance
terms for a whole frame at once (numpy distance matrix as the pre-gate, then the near pairs only) and returns the
feasible pairs once (:class:`GatedPairs`), which is what the tracker adds its penalties to and assigns on
(:func:`assign_pairs`). The assignment minimising the total cost is found with one
``scipy.optimize.linear_sum_assignment`` per frame on the gated matrix (infeasible pairs get a prohibitive cost and
are rejected afterwards); when no two feasible pairs share an observation or a belief (a sparse frame, the common
case) that assignment is all of them, and the solver is not called. Observations left over become new objects.
:func:`visible_from` predicts whether a belief should have been seen (in the image, in range, and not hidden behind
a nearer surface in the depth image), which is what lets unseen objects lose confidence.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from reasoning.fusion.frame import WORLD_FRAME
from reasoning.fusion.rule import ClassTest
from robokudo.core.types import CameraIntrinsics


class Trackable(Protocol):
    """What association needs of an observation or a belief."""

    @property
    def position(self) -> np.ndarray: ...

    @property
    def frame(self) -> str: ...

    @property
    def recording(self) -> str: ...

    @property
    def dimensions(self) -> np.ndarray | None: ...

    @property
    def appearance(self) -> np.ndarray | None: ...


@dataclass(frozen=True, slots=True)
class AssociationConfig:
    """Gates and scales of the association cost (metres, ratios, Bhattacharyya distances)."""

    gate_distance: float = 0.15
    position_sigma: float = 0.05
    size_ratio_gate: float = 2.5
    size_sigma: float = 0.5
    appearance_gate: float = 0.75
    appearance_sigma: float = 0.3
    color_penalty: float = 4.0
    class_penalty: float = 4.0


@dataclass(frozen=True, slots=True)
class Association:
    """The result: ``matches`` are (observation index, belief index, cost) pairs."""

    matches: tuple[tuple[int, int, float], ...]
    new: tuple[int, ...]
    unmatched: tuple[int, ...]


INFEASIBLE = 1e9
"""Cost standing for a gated-out pair."""


def world_key(frame: str, recording: str) -> str:
    """What must be equal for two positions to be comparable: the fixed frame, or the camera frame of a recording."""
    return frame if frame == WORLD_FRAME else f"{frame}@{recording}"


def same_world(a: Trackable, b: Trackable) -> bool:
    """True when the positions of ``a`` and ``b`` can be compared (see :func:`world_key`)."""
    return world_key(a.frame, a.recording) == world_key(b.frame, b.recording)


def bhattacharyya_distance(a: np.ndarray, b: np.ndarray) -> float:
    """Hellinger form ``sqrt(1 - Σ sqrt(a_i b_i))`` of two normalised histograms, in [0, 1]."""
    coefficient = float(np.sum(np.sqrt(np.clip(a, 0.0, None) * np.clip(b, 0.0, None))))
    return math.sqrt(max(0.0, 1.0 - min(coefficient, 1.0)))


def pair_cost(
    observation: Trackable,
    belief: Trackable,
    config: AssociationConfig,
    *,
    observation_colors: set[str] | None = None,
    belief_color: str | None = None,
    observation_classes: set[str] | None = None,
    belief_class: str | None = None,
    class_test: ClassTest | None = None,
) -> float:
    """The gated cost of pairing ``observation`` with ``belief`` (:data:`INFEASIBLE` when a gate fails)."""
    if not same_world(observation, belief):
        return INFEASIBLE
    distance = math.dist(_triple(observation.position), _triple(belief.position))
    if not distance <= config.gate_distance:
        return INFEASIBLE
    cost = (distance / config.position_sigma) ** 2
    a, b = observation.dimensions, belief.dimensions
    if a is not None and b is not None and len(a) and len(b):
        big_a, big_b = typical_size(a), typical_size(b)
        if big_a > 0 and big_b > 0:
            ratio = max(big_a, big_b) / min(big_a, big_b)
            if ratio > config.size_ratio_gate:
                return INFEASIBLE
            cost += (math.log(ratio) / config.size_sigma) ** 2
    ha, hb = observation.appearance, belief.appearance
    if ha is not None and hb is not None and ha.shape == hb.shape:
        appearance = bhattacharyya_distance(ha, hb)
        if appearance > config.appearance_gate:
            return INFEASIBLE
        cost += (appearance / config.appearance_sigma) ** 2
    elif observation_colors and belief_color and belief_color not in observation_colors:
        cost += config.color_penalty
    if observation_classes and belief_class:
        test = class_test or (lambda x, y: x == y)
        if not any(test(c, belief_class) or test(belief_class, c) for c in observation_classes):
            cost += config.class_penalty
    return cost


def typical_size(dimensions: np.ndarray) -> float:
    """The geometric mean of the positive extents (0 when there is none)."""
    extents = np.asarray(dimensions, dtype=np.float64)
    extents = extents[extents > 0]
    return float(np.exp(np.mean(np.log(extents)))) if extents.size else 0.0


def typical_sizes(items: Sequence[Trackable]) -> np.ndarray:
    """:func:`typical_size` of every item's dimensions (0 when it has none), computed for all at once."""
    dimensions = [item.dimensions for item in items]
    extents = _stacked(dimensions)
    if extents is not None and (extents > 0).all():  # the common case: three positive extents each
        return np.exp(np.log(extents).sum(axis=1) / 3.0)
    sizes = np.zeros(len(dimensions))
    full = [k for k, d in enumerate(dimensions) if d is not None and len(d) == 3]
    if full:
        chosen = dimensions if len(full) == len(dimensions) else [dimensions[k] for k in full]
        extents = np.array(chosen, dtype=np.float64)
        positive = (extents > 0).all(axis=1)
        if positive.all():  # no zero extent, no masking
            sizes[full] = np.exp(np.log(extents).sum(axis=1) / 3.0)
        else:
            logs = np.log(np.where(positive[:, None], extents, 1.0))
            sizes[np.asarray(full)[positive]] = np.exp(logs[positive].sum(axis=1) / 3.0)
            for k in np.asarray(full)[~positive].tolist():
                sizes[k] = typical_size(dimensions[k])  # type: ignore[arg-type]
    if len(full) < len(dimensions):
        for k, d in enumerate(dimensions):
            if d is not None and len(d) != 3 and len(d):
                sizes[k] = typical_size(d)
    return sizes


def _stacked(vectors: Sequence[np.ndarray | None]) -> np.ndarray | None:
    """The vectors as one Nx3 float array when every one is a 3-vector (N >= 1), else None."""
    if not vectors:
        return None
    try:
        stacked = np.array(vectors, dtype=np.float64)
    except (TypeError, ValueError):  # None among them, or vectors of several lengths
        return None
    return stacked if stacked.ndim == 2 and stacked.shape[1] == 3 else None


def _positions(items: Sequence[Trackable]) -> np.ndarray:
    """The first three coordinates of every item's position, as one Nx3 float array."""
    stacked = _stacked([item.position for item in items])
    if stacked is not None:
        return stacked
    return np.array([item.position[:3] for item in items], dtype=np.float64)


@dataclass(frozen=True, slots=True)
class GatedPairs:
    """The feasible (observation, belief) pairs of a frame in row-major order, found once: ``rows[k]``, ``cols[k]``
    and the cost ``costs[k]`` of pair ``k``, and whether both histograms were compared there (then the colour
    penalty does not apply). ``shape`` is (observations, beliefs)."""

    shape: tuple[int, int]
    rows: np.ndarray
    cols: np.ndarray
    costs: np.ndarray
    compared: np.ndarray

    def with_costs(self, costs: np.ndarray) -> GatedPairs:
        """The same pairs with other costs (those not below :data:`INFEASIBLE` dropped, as :func:`assign` does)."""
        keep = costs < INFEASIBLE
        if keep.all():
            return GatedPairs(self.shape, self.rows, self.cols, costs, self.compared)
        return GatedPairs(self.shape, self.rows[keep], self.cols[keep], costs[keep], self.compared[keep])

    def matrix(self) -> np.ndarray:
        """The full cost matrix (:data:`INFEASIBLE` outside the pairs)."""
        cost = np.full(self.shape, INFEASIBLE)
        cost[self.rows, self.cols] = self.costs
        return cost


def gated_costs(
    observations: Sequence[Trackable], beliefs: Sequence[Trackable], config: AssociationConfig
) -> GatedPairs:
    """The position, size and appearance terms of :func:`pair_cost` on the pairs that pass every gate, in one
    vectorised pass: the distance pre-gate on all pairs, then sizes and histograms on the near pairs only."""
    shape = (len(observations), len(beliefs))
    rows, cols, distance = _near_pairs(observations, beliefs, config.gate_distance)
    if rows.size == 0:
        return GatedPairs(shape, rows, cols, distance, np.zeros(0, dtype=bool))
    total = (distance / config.position_sigma) ** 2
    size_a, size_b = typical_sizes(observations)[rows], typical_sizes(beliefs)[cols]
    sized = (size_a > 0) & (size_b > 0)
    ratio = np.maximum(size_a, size_b) / np.where(sized, np.minimum(size_a, size_b), 1.0)
    feasible = ~sized | (ratio <= config.size_ratio_gate)
    total += np.where(sized, (np.log(np.where(sized, ratio, 1.0)) / config.size_sigma) ** 2, 0.0)
    compared = np.zeros(rows.size, dtype=bool)
    histograms = any(o.appearance is not None for o in observations) and any(b.appearance is not None for b in beliefs)
    pairs = list(zip(rows.tolist(), cols.tolist(), strict=True)) if histograms else []  # else nothing to compare
    for k, (i, j) in enumerate(pairs):
        ha, hb = observations[i].appearance, beliefs[j].appearance
        if ha is None or hb is None or ha.shape != hb.shape or not feasible[k]:
            continue
        appearance = bhattacharyya_distance(ha, hb)
        compared[k] = True
        if appearance > config.appearance_gate:
            feasible[k] = False
        else:
            total[k] += (appearance / config.appearance_sigma) ** 2
    feasible &= total < INFEASIBLE  # what the cost matrix would not count as feasible
    if not feasible.all():
        rows, cols, total, compared = rows[feasible], cols[feasible], total[feasible], compared[feasible]
    return GatedPairs(shape, rows, cols, total, compared)


def geometric_costs(
    observations: Sequence[Trackable], beliefs: Sequence[Trackable], config: AssociationConfig
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`gated_costs` as matrices: the cost matrix (:data:`INFEASIBLE` where a gate fails) and where both
    histograms were compared on a feasible pair."""
    pairs = gated_costs(observations, beliefs, config)
    compared = np.zeros(pairs.shape, dtype=bool)
    compared[pairs.rows, pairs.cols] = pairs.compared
    return pairs.matrix(), compared


def _near_pairs(
    observations: Sequence[Trackable], beliefs: Sequence[Trackable], gate: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Row and column indices of the pairs of one world within ``gate`` metres, and their distances."""
    if not observations or not beliefs:
        empty = np.empty(0, dtype=np.int64)
        return empty, empty, np.empty(0)
    a, b = _positions(observations), _positions(beliefs)
    delta = a[:, None, :] - b[None, :, :]
    distance = np.sqrt(np.einsum("ijk,ijk->ij", delta, delta))
    near = distance <= gate
    if {o.frame for o in observations} | {x.frame for x in beliefs} == {WORLD_FRAME}:
        keys_a = keys_b = [WORLD_FRAME]  # one world: every pair is comparable
    else:
        keys_a = [world_key(o.frame, o.recording) for o in observations]
        keys_b = [world_key(x.frame, x.recording) for x in beliefs]
    if len(set(keys_a) | set(keys_b)) > 1:
        near &= np.array(keys_a, dtype=object)[:, None] == np.array(keys_b, dtype=object)[None, :]
    rows, cols = np.nonzero(near)
    return rows, cols, distance[rows, cols]


def _triple(position: np.ndarray) -> tuple[float, float, float]:
    return float(position[0]), float(position[1]), float(position[2])


def assign(cost: np.ndarray) -> Association:
    """Optimal assignment on a cost matrix (rows: observations, columns: beliefs) honouring the gates."""
    rows, cols = np.nonzero(cost < INFEASIBLE)
    return assign_pairs(GatedPairs(cost.shape, rows, cols, cost[rows, cols], np.zeros(rows.size, dtype=bool)))


def assign_pairs(pairs: GatedPairs) -> Association:
    """:func:`assign` on the feasible pairs (the same assignment; the matrix is only made when the solver runs)."""
    rows, cols = pairs.shape
    pair_rows, pair_cols = pairs.rows.tolist(), pairs.cols.tolist()
    if rows == 0 or cols == 0 or not pair_rows:
        return Association((), tuple(range(rows)), tuple(range(cols)))
    if len(set(pair_rows)) == len(pair_rows) and len(set(pair_cols)) == len(pair_cols):
        # no two feasible pairs share an observation or a belief: the optimal assignment takes them all (leaving
        # one out would put a prohibitive cost in its place), so there is nothing to choose
        matches = tuple(zip(pair_rows, pair_cols, pairs.costs.tolist(), strict=True))
    elif rows == 1 or cols == 1:
        k = int(np.argmin(pairs.costs))  # the first least cost in row-major order, as argmin over the matrix
        matches = ((pair_rows[k], pair_cols[k], float(pairs.costs[k])),)
    else:
        from scipy.optimize import linear_sum_assignment

        cost = pairs.matrix()
        chosen_rows, chosen_cols = linear_sum_assignment(cost)
        kept = cost[chosen_rows, chosen_cols] < INFEASIBLE
        matched_rows, matched_cols = chosen_rows[kept], chosen_cols[kept]
        matches = tuple(
            zip(matched_rows.tolist(), matched_cols.tolist(), cost[matched_rows, matched_cols].tolist(), strict=True)
        )
    taken_rows, taken_cols = {m[0] for m in matches}, {m[1] for m in matches}
    return Association(
        matches,
        tuple(i for i in range(rows) if i not in taken_rows),
        tuple(j for j in range(cols) if j not in taken_cols),
    )


def associate(
    observations: Sequence[Trackable],
    beliefs: Sequence[Trackable],
    config: AssociationConfig | None = None,
    cost_of: Callable[[Trackable, Trackable], float] | None = None,
) -> Association:
    """Match observations to beliefs; ``cost_of`` overrides :func:`pair_cost` (e.g. to add colours, classes)."""
    config = config or AssociationConfig()
    if cost_of is None:
        return assign(geometric_costs(observations, beliefs, config)[0])
    cost = np.full((len(observations), len(beliefs)), INFEASIBLE)
    for i, j in gated_pairs(observations, beliefs, config.gate_distance):
        cost[i, j] = cost_of(observations[i], beliefs[j])
    return assign(cost)


def gated_pairs(observations: Sequence[Trackable], beliefs: Sequence[Trackable], gate: float) -> np.ndarray:
    """The (observation, belief) index pairs of one world within ``gate`` metres (vectorised pre-gate)."""
    rows, cols, _ = _near_pairs(observations, beliefs, gate)
    return np.column_stack((rows, cols))


@dataclass(frozen=True, slots=True)
class CameraModel:
    """A pinhole camera at a pose, with the frame's depth image (metres, 0 or NaN = no data)."""

    intrinsics: CameraIntrinsics
    to_frame: np.ndarray
    """4x4 transform from the optical frame to ``frame``, the frame beliefs are expressed in."""
    frame: str = "world"
    depth: np.ndarray | None = None
    recording: str = ""
    """The recording of the frame; beliefs of another recording are not in view unless ``frame`` is fixed."""
    looks_for: Callable[[str], bool] | None = None
    """Whether the frame's detectors report objects of a stored class ("" for no class): a belief of a class they do
    not look for (a person, for a tree that segments objects only) is not missed when in view. None: every class."""
    max_range: float = 4.0
    border: int = 5
    occlusion_margin: float = 0.05


def in_view(positions: np.ndarray, camera: CameraModel) -> np.ndarray:
    """Which of the Nx3 ``positions`` project inside the image (away from the border) within range."""
    points = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    to_camera = np.linalg.inv(camera.to_frame)
    p = points @ to_camera[:3, :3].T + to_camera[:3, 3]
    z = p[:, 2]
    ahead = (z > 0.05) & (z <= camera.max_range)
    k = camera.intrinsics
    u, v = k.project(np.column_stack((p[:, :2], np.where(ahead, z, 1.0)))).T
    b = camera.border
    return ahead & (u >= b) & (u < k.width - b) & (v >= b) & (v < k.height - b)


def visible_from(position: np.ndarray, camera: CameraModel) -> bool:
    """True when a belief at ``position`` should have been seen by ``camera``.

    It must project inside the image (away from the border), lie in front within ``max_range``, and the depth
    image (when given) must have data there that is not nearer than the belief by more than the margin.
    """
    if not bool(in_view(position, camera)[0]):
        return False
    if camera.depth is None:
        return True
    to_camera = np.linalg.inv(camera.to_frame)
    p = to_camera[:3, :3] @ np.asarray(position, dtype=np.float64) + to_camera[:3, 3]
    z = float(p[2])
    u, v = camera.intrinsics.project(p)[0]
    r, c = int(v), int(u)
    window = np.asarray(camera.depth[max(r - 2, 0) : r + 3, max(c - 2, 0) : c + 3], dtype=np.float64)
    window = window[np.isfinite(window) & (window > 0)]
    if window.size == 0:
        return False
    return float(np.median(window)) >= z - camera.occlusion_margin
