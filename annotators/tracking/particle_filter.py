"""A particle filter for one moving target in 3-D: predict, associate the nearest detection, weight, resample.

The state of a particle is position and velocity (metres, metres per second) in one fixed frame. Prediction is
constant velocity with random accelerations (white noise of ``acceleration`` m/s² per axis). Association takes the
detection nearest to the estimate, if it lies within the gate: ``gate`` metres plus three times the estimate's
spread, so the gate widens while the target goes unseen. Weighting multiplies each particle's weight by the
Gaussian likelihood of the associated detection (``measurement_noise`` m per axis); resampling is systematic and
happens when the effective sample size drops below half the particles. Particles drawn around a detection come in
opposite pairs, so the draw adds no offset of its own to the estimate. Pure numpy; deterministic for a seeded
generator.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, slots=True)
class FilterSettings:
    """The filter's noise model and gate (see the module)."""

    particles: int = 400
    acceleration: float = 2.0
    """Random acceleration per axis, m/s² (standard deviation)."""
    measurement_noise: float = 0.06
    """Detection noise per axis, metres (standard deviation)."""
    gate: float = 0.35
    """The largest distance (metres) of an associated detection from a settled estimate."""
    initial_speed: float = 0.5
    """Spread of the velocities at the first sighting, m/s per axis."""
    max_step: float = 1.0
    """The longest prediction step (seconds): a longer gap is predicted as this long (no wild extrapolation)."""

    def __post_init__(self) -> None:
        if isinstance(self.particles, bool) or not isinstance(self.particles, int) or self.particles < 2:
            raise ValueError(f"particles must be a whole number >= 2, not {self.particles!r}")
        for name in ("acceleration", "measurement_noise", "gate", "initial_speed", "max_step"):
            value = getattr(self, name)
            if not np.isfinite(value) or value <= 0:
                raise ValueError(f"{name} must be a positive number, not {value!r}")


@dataclass(frozen=True, slots=True)
class Estimate:
    """The filter's estimate: mean position and velocity and the position spread (metres, RMS over the axes)."""

    position: np.ndarray
    velocity: np.ndarray
    spread: float


class ParticleFilter:
    """One target's particle filter (see the module). Call :meth:`start` with the first detection, then per frame
    :meth:`predict`, :meth:`associate` and, when a detection was associated, :meth:`update`."""

    def __init__(self, settings: FilterSettings | None = None, rng: np.random.Generator | None = None) -> None:
        self.settings = settings or FilterSettings()
        self.rng = rng if rng is not None else np.random.default_rng(0)
        self.states = np.zeros((0, 6))
        self.weights = np.zeros(0)
        self.time = 0.0
        self.last_step = 0.0

    @property
    def started(self) -> bool:
        """True once :meth:`start` was called."""
        return self.states.shape[0] > 0

    def start(self, position: np.ndarray, time: float) -> None:
        """Place the particles around a first detection at ``time`` (seconds)."""
        position = _point(position)
        count = self.settings.particles
        self.states = np.empty((count, 6))
        self.states[:, :3] = position + _symmetric_normal(self.rng, self.settings.measurement_noise, count)
        self.states[:, 3:] = _symmetric_normal(self.rng, self.settings.initial_speed, count)
        self.weights = np.full(count, 1.0 / count)
        self.time = float(time)

    def predict(self, time: float) -> None:
        """Move the particles to ``time`` (seconds; an earlier time moves nothing)."""
        self._require_started()
        dt = min(float(time) - self.time, self.settings.max_step)
        self.time = max(self.time, float(time))
        self.last_step = max(dt, 0.0)
        if dt <= 0:
            return
        accel = self.rng.normal(0.0, self.settings.acceleration, (self.states.shape[0], 3))
        self.states[:, :3] += self.states[:, 3:] * dt + 0.5 * accel * dt * dt
        self.states[:, 3:] += accel * dt

    def estimate(self) -> Estimate:
        """The weighted mean position and velocity and the position spread."""
        self._require_started()
        w = self.weights
        mean = w @ self.states
        offsets = self.states[:, :3] - mean[:3]
        spread = float(np.sqrt(w @ np.sum(offsets * offsets, axis=1) / 3.0))
        return Estimate(position=mean[:3].copy(), velocity=mean[3:].copy(), spread=spread)

    def gate(self) -> float:
        """The current association gate in metres (widens with the spread)."""
        return self.settings.gate + 3.0 * self.estimate().spread

    def associate(self, detections: np.ndarray) -> int | None:
        """The index of the detection (Nx3) nearest to the estimate within the gate, or None."""
        self._require_started()
        found = np.asarray(detections, dtype=np.float64).reshape(-1, 3)
        if found.shape[0] == 0:
            return None
        valid = np.all(np.isfinite(found), axis=1)
        if not valid.any():
            return None
        distances = np.linalg.norm(found - self.estimate().position, axis=1)
        distances[~valid] = np.inf
        best = int(np.argmin(distances))
        return best if distances[best] <= self.gate() else None

    def update(self, detection: np.ndarray) -> None:
        """Weight the particles by a detection's likelihood and resample when the weights degenerate.

        When the predicted particles hardly cover the detection (a long step spread them far wider than the
        detection noise), a share of them is drawn afresh around the detection, keeping the velocities of the
        particles nearest to it: otherwise the few particles that happen to lie near the detection decide the
        estimate and a still target's estimate wanders by centimetres. After a step long enough for the random
        accelerations to have changed the velocities by more than the initial speed spread (a stalled tree, a
        target unseen for a while), those velocities say nothing any more, and the drawn particles get velocities
        as on a first sighting; kept, the few of them would carry a still target's estimate away in the frames
        that follow.
        """
        self._require_started()
        point = _point(detection)
        squared = np.sum((self.states[:, :3] - point) ** 2, axis=1)
        log_likelihood = -0.5 * squared / self.settings.measurement_noise**2
        coverage = float(self.weights @ np.exp(log_likelihood))
        log_w = np.log(np.maximum(self.weights, 1e-300)) + log_likelihood
        log_w -= log_w.max()
        weights = np.exp(log_w)
        self.weights = weights / weights.sum()
        if coverage < _WELL_COVERED:
            self._reset_around(point, share=1.0 - coverage / _WELL_COVERED)
        elif 1.0 / float(self.weights @ self.weights) < 0.5 * self.weights.size:
            self.resample()

    def _reset_around(self, detection: np.ndarray, share: float) -> None:
        """Resample, then move ``share`` of the particles to draws around ``detection`` (velocities kept)."""
        self.resample()
        count = self.weights.size
        fresh = self.rng.random(count) < share
        drawn = int(fresh.sum())
        self.states[fresh, :3] = detection + _symmetric_normal(self.rng, self.settings.measurement_noise, drawn)
        if self.last_step * self.settings.acceleration > self.settings.initial_speed:
            self.states[fresh, 3:] = _symmetric_normal(self.rng, self.settings.initial_speed, drawn)

    def resample(self) -> None:
        """Systematic resampling: particles drawn in proportion to their weights, weights made equal."""
        count = self.weights.size
        positions = (self.rng.random() + np.arange(count)) / count
        cumulative = np.cumsum(self.weights)
        cumulative[-1] = 1.0
        chosen = np.searchsorted(cumulative, positions)
        self.states = self.states[chosen]
        self.weights = np.full(count, 1.0 / count)

    def _require_started(self) -> None:
        if not self.started:
            raise RuntimeError("the particle filter has no target yet: call start() with a first detection")


_WELL_COVERED = 0.2
"""The mean likelihood of the predicted particles (1 at the detection, e^-0.5 one noise sigma away per axis) below
which particles are drawn afresh around the detection."""


def _symmetric_normal(rng: np.random.Generator, scale: float, count: int) -> np.ndarray:
    """``count`` normal 3-vectors (standard deviation ``scale``) in opposite pairs, so their mean is exactly zero:
    drawn particles then centre on what they are drawn around instead of on a random offset of the draw."""
    half = rng.normal(0.0, scale, (count // 2, 3))
    return np.concatenate([half, -half, np.zeros((count % 2, 3))])


def _point(value: np.ndarray) -> np.ndarray:
    point = np.asarray(value, dtype=np.float64).reshape(-1)
    if point.shape != (3,) or not np.all(np.isfinite(point)):
        raise ValueError(f"a position is three finite numbers, not {value!r}")
    return point
