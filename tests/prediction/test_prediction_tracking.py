"""The constant-velocity tracker of sensed bodies (:mod:`uvnav.prediction.tracking`)."""

from __future__ import annotations

import dataclasses

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.prediction.finite_difference import FiniteDifferenceEstimator
from uvnav.prediction.tracking import CentreTracker, cv_predict, cv_update
from uvnav.sensors.observation import ObstacleReading

ROBOT = np.zeros(2)


def disc(
    k: int, centre: np.ndarray, velocity: np.ndarray, source: str = "known"
) -> ObstacleReading:
    c = np.asarray(centre, dtype=float)
    d = max(float(np.hypot(*c)) - 0.3, 0.0)
    near = c - 0.3 * c / max(float(np.hypot(*c)), 1e-12)
    return ObstacleReading(k, d, near, c, np.asarray(velocity, float), 0.0, np.zeros((0, 2)),
                           0.3, 0.3, source)  # fmt: skip


def test_known_rates_pass_through_untouched() -> None:
    tracker = CentreTracker()
    readings = (disc(0, np.array([3.0, 1.0]), np.array([0.5, 0.0])),)
    assert tracker.update(0.0, readings, ROBOT)[0] is readings[0]
    assert tracker.update(0.25, readings, ROBOT)[0] is readings[0]


def _walk(noise: float, seed: int, steps: int = 80, dt: float = 0.25) -> tuple[float, float]:
    """RMS velocity error of finite differences and of the tracker on a body walking at
    (1.0, -0.4) m/s, centres sensed with ``noise`` [m] (after the first 2 s)."""
    fd = FiniteDifferenceEstimator(np.random.default_rng(seed), position_noise=noise)
    tracker = CentreTracker(position_std=0.1, accel_std=1.0)
    true_v = np.array([1.0, -0.4])
    e_fd, e_kf = [], []
    for i in range(steps):
        t = i * dt
        (est,) = fd.update(t, (disc(7, np.array([2.0, 5.0]) + t * true_v, true_v),))
        (trk,) = tracker.update(t, (est,), ROBOT)
        if t >= 2.0:
            e_fd.append(np.sum((est.velocity - true_v) ** 2))
            e_kf.append(np.sum((trk.velocity - true_v) ** 2))
    return float(np.sqrt(np.mean(e_fd))), float(np.sqrt(np.mean(e_kf)))


def test_tracking_cuts_the_velocity_noise_of_finite_differences() -> None:
    for seed in range(3):
        fd, kf = _walk(0.1, seed)
        assert fd > 0.4  # about 0.1 sqrt(2) / 0.25 per axis
        assert kf < 0.35 * fd


@settings(max_examples=40, deadline=None)
@given(vx=st.floats(-2.0, 2.0), vy=st.floats(-2.0, 2.0), dt=st.floats(0.05, 0.5))
def test_noise_free_constant_velocity_is_tracked(vx: float, vy: float, dt: float) -> None:
    """Without noise and acceleration the filtered velocity converges to the true one, and the
    moved reading keeps its shape (nearest point shifted with the centre)."""
    tracker = CentreTracker(position_std=0.05, accel_std=0.5)
    v = np.array([vx, vy])
    for i in range(int(12.0 / dt)):
        t = i * dt
        c = np.array([4.0, -3.0]) + t * v
        seen = dataclasses.replace(disc(1, c, np.zeros(2)), velocity_source="estimated")
        (rd,) = tracker.update(t, (seen,), ROBOT)
    assert np.allclose(rd.velocity, v, atol=0.02 * (1 + np.hypot(vx, vy)))
    assert np.allclose(rd.centre - rd.nearest_point, c - disc(1, c, v).nearest_point)


def test_first_sighting_and_reset() -> None:
    tracker = CentreTracker()
    est = dataclasses.replace(disc(3, np.array([1.0, 2.0]), np.array([9.0, 9.0])),
                              velocity_source="estimated")  # fmt: skip
    (first,) = tracker.update(1.0, (est,), ROBOT)
    assert np.array_equal(first.centre, est.centre) and np.array_equal(first.velocity, [0, 0])
    tracker.update(1.5, (dataclasses.replace(est, centre=np.array([1.5, 2.0])),), ROBOT)
    tracker.reset()
    (again,) = tracker.update(2.0, (est,), ROBOT)
    assert np.array_equal(again.velocity, [0, 0])


def test_predict_and_update_are_the_textbook_steps() -> None:
    p, v, cov = cv_predict(np.array([1.0, 0.0]), np.array([0.5, 0.0]), np.eye(2) * 0.01, 0.5, 2.0)
    assert p.tolist() == [1.25, 0.0]
    q = 4.0 * np.array([[0.5**4 / 4, 0.5**3 / 2], [0.5**3 / 2, 0.25]])
    f = np.array([[1.0, 0.5], [0.0, 1.0]])
    assert np.allclose(cov, f @ (np.eye(2) * 0.01) @ f.T + q)
    p2, _, cov2 = cv_update(p, v, cov, np.array([1.35, 0.1]), 0.1)
    gain = cov[0, 0] / (cov[0, 0] + 0.01)
    assert np.allclose(p2, p + gain * (np.array([1.35, 0.1]) - p))
    assert cov2[0, 0] < cov[0, 0] and np.allclose(cov2, cov2.T)


def _second_centre(tracker: CentreTracker, declared: float) -> np.ndarray:
    """The filtered centre after a body seen at the origin is seen 1 m away 0.25 s later,
    both sightings declaring ``declared`` [m] of centre noise."""
    seen = dataclasses.replace(disc(0, np.zeros(2), np.zeros(2)), velocity_source="estimated",
                               position_std=declared)  # fmt: skip
    tracker.update(0.0, (seen,), ROBOT)
    moved = dataclasses.replace(seen, centre=np.array([1.0, 0.0]))
    return tracker.update(0.25, (moved,), ROBOT)[0].centre


def test_the_readings_declared_noise_sets_the_filter() -> None:
    """A precise reading moves the filtered centre further toward what was seen than a noisy
    one; a reading that declares none is filtered with the tracker's own ``position_std``."""
    precise = _second_centre(CentreTracker(position_std=0.3, accel_std=0.5), 0.01)
    noisy = _second_centre(CentreTracker(position_std=0.01, accel_std=0.5), 0.3)
    assert precise[0] > 0.99 and 0.0 < noisy[0] < 0.7
    undeclared = _second_centre(CentreTracker(position_std=0.3, accel_std=0.5), 0.0)
    assert np.array_equal(undeclared, _second_centre(CentreTracker(0.01, 0.5), 0.3))


def _after_a_turn(turn_std: float, speed: float) -> float:
    """Velocity error [m/s] 0.75 s after a body walking at ``speed`` along x for 5 s turns to
    walk along y (exact centres, declared 0.1 m noise)."""
    tracker = CentreTracker(position_std=0.1, accel_std=0.2, turn_std=turn_std)
    c, v = np.array([1.0, 2.0]), np.array([speed, 0.0])
    for i in range(24):
        if i == 20:
            v = np.array([0.0, speed])
        c = c + 0.25 * v
        seen = dataclasses.replace(disc(5, c, np.zeros(2)), velocity_source="estimated",
                                   position_std=0.1)  # fmt: skip
        (rd,) = tracker.update(0.25 * i, (seen,), ROBOT)
    return float(np.hypot(*(rd.velocity - v)))


def test_fast_bodies_are_followed_sooner_when_the_noise_grows_with_speed() -> None:
    """``turn_std`` makes a fast walker's track follow its turn sooner; a body standing still
    is filtered as with ``accel_std`` alone."""
    assert _after_a_turn(0.5, 1.5) < 0.8 * _after_a_turn(0.0, 1.5)
    assert _after_a_turn(0.5, 0.0) == _after_a_turn(0.0, 0.0)
