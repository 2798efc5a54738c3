"""The particle filter follows one target through noisy detections and clutter, and associates the nearest one."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from annotators.tracking.particle_filter import FilterSettings, ParticleFilter


def walk(seed: int, steps: int = 150, rate: float = 15.0) -> tuple[np.ndarray, np.ndarray]:
    """A person's path on the floor: straight legs with turns, 0.3-1.2 m/s, at ``rate`` frames per second."""
    rng = np.random.default_rng(seed)
    times = np.arange(steps) / rate
    position = np.array([rng.uniform(-1, 1), 0.9, rng.uniform(2, 4)])
    heading, speed = rng.uniform(0, 2 * np.pi), rng.uniform(0.3, 1.2)
    path = []
    for step in range(steps):
        if step % 30 == 0:
            heading += rng.normal(0, 1.0)
            speed = rng.uniform(0.3, 1.2)
        position = position + speed / rate * np.array([np.cos(heading), 0.0, np.sin(heading)])
        path.append(position.copy())
    return times, np.array(path)


@pytest.mark.parametrize("seed", range(6))
def test_it_follows_a_walk_through_noise_clutter_and_missed_frames(seed: int) -> None:
    times, path = walk(seed)
    rng = np.random.default_rng(100 + seed)
    pf = ParticleFilter(FilterSettings(), np.random.default_rng(seed))
    errors, raw, lost = [], [], 0
    for t, truth in zip(times, path, strict=True):
        seen = rng.random() > 0.15  # the detector misses 15 % of the frames
        measured = truth + rng.normal(0, 0.04, 3)
        clutter = truth + rng.uniform(1.2, 2.5, (2, 3)) * rng.choice([-1, 1], (2, 3))  # another person >= 1.2 m away
        detections = np.vstack([measured[None] if seen else np.empty((0, 3)), clutter])
        if not pf.started:
            pf.start(measured, t)
            continue
        pf.predict(t)
        chosen = pf.associate(detections)
        if seen:
            lost += chosen != 0  # the true detection must be the one associated
            raw.append(np.linalg.norm(measured - truth))
        else:
            lost += chosen is not None
        if chosen is not None:
            pf.update(detections[chosen])
        errors.append(np.linalg.norm(pf.estimate().position - truth))
    assert lost == 0
    assert np.median(errors) < 0.06, np.median(errors)  # better than 10 cm, near the raw detection noise
    assert np.median(errors) < 1.2 * np.median(raw)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.tuples(*(st.floats(-5, 5, allow_nan=False) for _ in range(3))), min_size=1, max_size=8),
    st.integers(0, 1000),
)
def test_association_takes_the_nearest_detection_within_the_gate(points: list[tuple[float, ...]], seed: int) -> None:
    pf = ParticleFilter(FilterSettings(particles=50), np.random.default_rng(seed))
    pf.start(np.zeros(3), 0.0)
    detections = np.array(points)
    chosen = pf.associate(detections)
    distances = np.linalg.norm(detections - pf.estimate().position, axis=1)
    if distances.min() > pf.gate():
        assert chosen is None
    else:
        assert chosen is not None and distances[chosen] == distances.min()


def test_the_gate_widens_while_the_target_is_unseen_and_no_gap_predicts_wildly() -> None:
    pf = ParticleFilter(FilterSettings(), np.random.default_rng(1))
    pf.start(np.array([0.0, 0.0, 3.0]), 0.0)
    narrow = pf.gate()
    pf.predict(0.5)
    assert pf.gate() > narrow
    pf.predict(100.0)  # a long gap is predicted as max_step at most
    assert np.linalg.norm(pf.estimate().position - [0.0, 0.0, 3.0]) < 3.0


@pytest.mark.parametrize("seed", range(8))
def test_a_still_target_seen_once_a_second_stays_put(seed: int) -> None:
    """Frames a second apart (a loaded machine, a slow tree) spread the predicted particles far wider than the
    detection noise; the estimate still follows the detections of a target that does not move."""
    rng = np.random.default_rng(100 + seed)
    target = np.array([0.4, -0.2, 1.1])
    pf = ParticleFilter(FilterSettings(), np.random.default_rng(seed))
    pf.start(target + rng.normal(0.0, 0.005, 3), 0.0)
    errors = []
    for step in range(1, 30):
        pf.predict(step * 1.0 + rng.uniform(-0.2, 0.2))
        pf.update(target + rng.normal(0.0, 0.005, 3))
        errors.append(float(np.linalg.norm(pf.estimate().position - target)))
    assert max(errors) < 0.02, errors


@pytest.mark.parametrize("seed", range(8))
def test_a_still_target_stays_put_in_the_frames_after_a_stall(seed: int) -> None:
    """A one-second stall between frames at 30 Hz (a tree that compiled a kernel, a busy machine): the estimate of
    a target that does not move stays within 2 cm of it in the frames that follow, not carried off by the
    velocities of the few particles the long step left near it."""
    rng = np.random.default_rng(1000 + seed)
    target = np.array([1.0, 0.5, 0.8])
    pf = ParticleFilter(FilterSettings(), np.random.default_rng(seed))
    pf.start(target + rng.normal(0.0, 0.003, 3), 0.0)
    errors, now = [], 0.0
    for gap in (1 / 30, 1.0, 1 / 30, 1 / 30, 1 / 30, 1 / 30):
        now += gap
        pf.predict(now)
        pf.update(target + rng.normal(0.0, 0.003, 3))
        errors.append(float(np.linalg.norm(pf.estimate().position - target)))
    assert max(errors) < 0.02, errors


def test_resampling_keeps_the_particle_count_and_equal_weights() -> None:
    pf = ParticleFilter(FilterSettings(particles=100), np.random.default_rng(2))
    pf.start(np.zeros(3), 0.0)
    pf.predict(0.1)
    pf.update(np.array([0.05, 0.0, 0.0]))
    pf.resample()
    assert pf.states.shape == (100, 6) and np.allclose(pf.weights, 0.01)


@pytest.mark.parametrize(
    "bad", [{"particles": 1}, {"acceleration": 0.0}, {"measurement_noise": float("nan")}, {"gate": -1.0}]
)
def test_bad_settings_and_use_before_start_are_refused(bad: dict[str, float]) -> None:
    with pytest.raises(ValueError):
        FilterSettings(**bad)  # type: ignore[arg-type]
    with pytest.raises(RuntimeError, match="no target yet"):
        ParticleFilter().predict(1.0)
    with pytest.raises(ValueError, match="three finite numbers"):
        ParticleFilter().start(np.array([0.0, np.nan, 1.0]), 0.0)
