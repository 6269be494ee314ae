"""Finite-difference velocity and rotation-rate estimates of a rigid moving polygon."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from uvnav.obstacles import (
    ConstantVelocity,
    FieldTemplate,
    Obstacle,
    ObstacleField,
    ObstacleState,
    PolygonBody,
)
from uvnav.prediction import FiniteDifferenceEstimator
from uvnav.sensors import sense_obstacles

ARROW = np.array([[-0.6, -0.4], [0.7, -0.5], [0.2, 0.1], [0.6, 0.6], [-0.5, 0.5]])
V_TRUE = np.array([0.3, -0.2])
W_TRUE = 0.4


def _track(
    estimator: FiniteDifferenceEstimator,
    n: int,
    dt: float,
    *,
    every: int = 1,
    truth: list | None = None,
) -> list:
    """Estimates every ``every``-th step of a ConstantVelocity polygon; truth goes to ``truth``."""
    truth = [] if truth is None else truth
    body = PolygonBody.from_vertices(ARROW)
    ob = Obstacle(
        body,
        ObstacleState(position=np.array([2.0, 1.0]), heading=0.3),
        ConstantVelocity(V_TRUE, W_TRUE),
    )
    tpl = FieldTemplate.from_bodies([body])
    out = []
    for i in range(n):
        if i % every == 0:
            readings = sense_obstacles(np.zeros(2), ObstacleField.from_obstacles([ob], tpl))
            estimated = estimator.update(i * dt, readings)
            assert len(estimated) == len(readings)
            assert estimated[0].obstacle_id == readings[0].obstacle_id
            out.append(estimated)
            truth.append(readings)
        ob.state = ob.motion.step(ob.state, i * dt, dt)
    return out


def test_first_sighting_gets_zero_rates() -> None:
    (first,) = _track(FiniteDifferenceEstimator(np.random.default_rng(0)), 1, 0.1)[0:1]
    assert first[0].velocity_source == "estimated"
    assert np.array_equal(first[0].velocity, np.zeros(2)) and first[0].angular_velocity == 0.0


@pytest.mark.parametrize(("dt", "every"), [(0.1, 1), (0.05, 4), (0.5, 1)])
def test_recovers_true_rates_without_noise(dt: float, every: int) -> None:
    est = FiniteDifferenceEstimator(np.random.default_rng(0))
    history = _track(est, 60, dt, every=every)
    for readings in history[1:]:
        (r,) = readings
        assert r.velocity == pytest.approx(V_TRUE, abs=1e-9)
        assert r.angular_velocity == pytest.approx(W_TRUE, abs=1e-9)


def test_estimates_with_position_noise() -> None:
    sigma, dt = 0.01, 0.1
    est = FiniteDifferenceEstimator(np.random.default_rng(42), position_noise=sigma)
    truth: list = []
    history = _track(est, 400, dt, truth=truth)
    v = np.array([h[0].velocity for h in history[1:]])
    w = np.array([h[0].angular_velocity for h in history[1:]])
    per_axis_std = math.sqrt(2.0) * sigma / dt  # difference of two independent noisy positions
    # unbiased: the mean over 399 estimates is within 4 standard errors of the truth
    assert np.all(np.abs(v.mean(axis=0) - V_TRUE) < 4 * per_axis_std / math.sqrt(len(v)) * 1.5)
    # spread as predicted (lag-1 correlation of the differences leaves the variance unchanged)
    assert v.std(axis=0) == pytest.approx([per_axis_std, per_axis_std], rel=0.15)
    # the outline is shifted rigidly by the noise, so the rotation estimate is unaffected
    assert w == pytest.approx(np.full(len(w), W_TRUE), abs=1e-9)
    # the reported centre, nearest point and outline carry the same noise offset (rigid shift)
    for est_r, true_r in zip(history, truth, strict=True):
        noise = est_r[0].centre - true_r[0].centre
        assert np.hypot(*noise) > 0
        assert est_r[0].nearest_point - true_r[0].nearest_point == pytest.approx(noise, abs=1e-12)
        assert est_r[0].outline - true_r[0].outline == pytest.approx(
            np.broadcast_to(noise, ARROW.shape), abs=1e-12
        )
    offsets = np.array([e[0].centre - t[0].centre for e, t in zip(history, truth, strict=True)])
    assert offsets.std(axis=0) == pytest.approx([sigma, sigma], rel=0.15)


def test_estimator_is_deterministic_given_seed() -> None:
    a = _track(FiniteDifferenceEstimator(np.random.default_rng(5), position_noise=0.02), 30, 0.1)
    b = _track(FiniteDifferenceEstimator(np.random.default_rng(5), position_noise=0.02), 30, 0.1)
    for ra, rb in zip(a, b, strict=True):
        assert np.array_equal(ra[0].velocity, rb[0].velocity)
        assert np.array_equal(ra[0].centre, rb[0].centre)


def test_discs_get_velocity_but_no_spin_estimate() -> None:
    from uvnav.obstacles import DiscBody

    ob = Obstacle(
        DiscBody(0.5),
        ObstacleState(position=np.array([3.0, 0.0])),
        ConstantVelocity(V_TRUE, W_TRUE),
    )
    est = FiniteDifferenceEstimator(np.random.default_rng(0))
    for i in range(3):
        (r,) = est.update(i * 0.1, sense_obstacles(np.zeros(2), ObstacleField.from_obstacles([ob])))
        ob.state = ob.motion.step(ob.state, i * 0.1, 0.1)
    assert r.velocity == pytest.approx(V_TRUE, abs=1e-9)
    assert r.angular_velocity == 0.0  # a disc's rotation is unobservable


def test_readings_declare_their_centre_noise() -> None:
    """The declared centre noise is the added noise combined with what the reading came with."""
    field = ObstacleField.from_obstacles([Obstacle.moving_disc((2.0, 1.0), 0.3)])
    (reading,) = sense_obstacles(np.zeros(2), field)
    (plain,) = FiniteDifferenceEstimator(np.random.default_rng(0), 0.1).update(0.0, (reading,))
    assert plain.position_std == pytest.approx(0.1)
    fitted = dataclasses.replace(reading, position_std=0.05)
    (both,) = FiniteDifferenceEstimator(np.random.default_rng(0), 0.1).update(0.0, (fitted,))
    assert both.position_std == pytest.approx(math.hypot(0.05, 0.1))
    (exact,) = FiniteDifferenceEstimator(np.random.default_rng(0), 0.0).update(0.0, (reading,))
    assert exact.position_std == 0.0
