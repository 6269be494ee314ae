"""``zhang2019-v2``'s social term: the forecast gap against brute-force sampling, the three
implementations of the term (numpy, plain Python, compiled) and the rolled-out paths' version
equal, the term off changing nothing, and a crossing pedestrian passed behind when it is on."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers.zhang2019_limits import path_social
from uvnav.controllers.zhang2019_v2 import Zhang2019V2Params, plan
from uvnav.geometry.contact import (
    forecast_gap,
    social_risk,
    social_risk_compiled,
    social_risk_py,
)
from uvnav.geometry.kernels3d import compiled
from uvnav.sensors.observation import Observation, ObstacleReading

GOAL = np.array([10.0, 0.0])
vec = st.tuples(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0))


def pedestrian(k: int, x: float, y: float, vx: float, vy: float) -> ObstacleReading:
    """A disc of radius 0.3 m seen from the origin."""
    c = np.array([x, y])
    d = float(np.hypot(x, y))
    return ObstacleReading(k, max(d - 0.3, 0.0), c * (1.0 - 0.3 / max(d, 1e-9)), c,
                           np.array([vx, vy]), 0.0, np.zeros((0, 2)), 0.3, 0.3)  # fmt: skip


def observe(*readings: ObstacleReading) -> Observation:
    order = tuple(sorted(readings, key=lambda rd: rd.distance))
    return Observation(time=1.0, pose=np.zeros(3), speed=0.0, goal=GOAL, obstacles=order)


@settings(max_examples=200, deadline=None)
@given(d=vec, u=vec, e=vec)
def test_forecast_gap_is_the_sampled_distance_to_the_parallelogram(
    d: tuple[float, float], u: tuple[float, float], e: tuple[float, float]
) -> None:
    dd, uu, ee = np.array(d), np.array(u), np.array(e)
    g = float(forecast_gap(dd, uu, ee))
    grid = np.linspace(0.0, 1.0, 201)
    pts = dd + grid[:, None, None] * uu + grid[None, :, None] * ee
    sampled = float(np.hypot(pts[..., 0], pts[..., 1]).min())
    step = (np.hypot(*uu) + np.hypot(*ee)) / 200.0
    assert g <= sampled + 1e-9
    assert g >= sampled - step - 1e-9


Discs = tuple[np.ndarray, np.ndarray, np.ndarray]


def _scene(seed: int, n: int, k: int = 30) -> tuple[Discs, np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    q = rng.uniform(-5.0, 5.0, (n, 2))
    w = rng.uniform(-1.2, 1.2, (n, 2)) * (rng.uniform(size=(n, 1)) > 0.2)  # some stand still
    reach = rng.uniform(0.5, 0.9, n)
    ang, spd = rng.uniform(-np.pi, np.pi, k), rng.uniform(0.0, 1.0, k)
    cand = spd[:, None] * np.column_stack([np.cos(ang), np.sin(ang)])
    turn = cand * rng.uniform(0.3, 1.0, (k, 1))
    tau = rng.uniform(0.0, 2.5, k) * (rng.uniform(size=k) > 0.5)
    return (q, w, reach), cand, turn, tau


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(0, 10))
def test_social_term_numpy_plain_and_compiled_agree(seed: int, n: int) -> None:
    discs, cand, turn, tau = _scene(seed, n)
    social = (2.0, 1.25, 0.1)
    ref = social_risk(np.zeros(2), cand, turn, tau, discs, social)
    slow = np.empty(len(cand))
    social_risk_py(np.zeros(2), cand, turn, tau, *discs, *social, slow)
    fast = social_risk_compiled(np.zeros(2), cand, turn, tau, discs, social)
    np.testing.assert_allclose(slow, ref, rtol=0, atol=1e-12)
    np.testing.assert_allclose(fast, ref, rtol=0, atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(1, 6))
def test_social_term_is_the_sampled_depth_into_the_forecasts(seed: int, n: int) -> None:
    """``reach + band`` less the smallest distance, over the robot's first T_s seconds (turn,
    then straight) and each moving body's forecast over S seconds from then, sampled finely."""
    (q, w, reach), cand, turn, tau = _scene(seed, n, k=8)
    span, forecast, band = 2.0, 1.25, 0.1
    soc = social_risk(np.zeros(2), cand, turn, tau, (q, w, reach), (span, forecast, band))
    t = np.linspace(0.0, span, 401)[:, None, None]
    s = np.linspace(0.0, forecast, 251)[None, :, None]
    for k in range(len(cand)):
        t1 = np.minimum(t, tau[k])
        robot = turn[k] * t1 + cand[k] * (t - t1)
        want = 0.0
        for j in range(n):
            if not np.any(w[j]):
                continue
            gap = np.hypot(*np.moveaxis(q[j] + w[j] * (t + s) - robot, -1, 0)).min()
            want = max(want, reach[j] + band - gap)
        tol = (float(np.hypot(w[:, 0], w[:, 1]).max()) + 1.0) * (span / 400 + forecast / 250)
        assert soc[k] == pytest.approx(want, abs=tol)


def test_rolled_out_straight_paths_read_the_same_term() -> None:
    """On paths of straight segments at constant velocity (what a rollout is on a vehicle that
    keeps its speed), the term equals the closed form's."""
    discs, cand, _, _ = _scene(7, 6)
    p = Zhang2019V2Params(w_social=1.0, social_horizon=2.0)
    times = 0.125 * np.arange(33, dtype=float)  # 4 s
    xy = times[None, :, None] * cand[:, None, :]
    want = social_risk(np.zeros(2), cand, cand, np.zeros(len(cand)), discs,
                       (p.social_horizon, p.social_forecast, p.social_band))  # fmt: skip
    np.testing.assert_allclose(
        path_social(times, xy, discs, p.social_horizon, p.social_forecast, p.social_band),
        want,
        rtol=0,
        atol=1e-9,
    )


def test_term_off_ignores_its_other_parameters() -> None:
    obs = observe(pedestrian(0, 2.5, -2.0, 0.0, 1.0), pedestrian(1, 4.0, 1.0, -0.5, 0.2))
    base = Zhang2019V2Params()
    other = Zhang2019V2Params(social_horizon=4.0, social_forecast=3.0, social_band=0.5)
    for loop in (True, False):
        for heading, u_max in ((None, math.inf), (0.0, math.pi)):
            a, b = (plan(obs, GOAL, 1.0, 0.3, 0.25, np.zeros(2), p, loop=loop, heading=heading,
                         u_max=u_max) for p in (base, other))  # fmt: skip
            assert a.velocity.tolist() == b.velocity.tolist() and a.ttc == b.ttc


@pytest.mark.parametrize("enabled", [True, False])
def test_crossing_pedestrian_is_passed_behind_with_the_term(enabled: bool) -> None:
    """A pedestrian 2.5 m ahead and 3.5 m to the right, walking left across the robot's way at
    1 m/s: without the term the robot keeps its line at full speed and crosses a second ahead of
    them, deep in their forecast; with it, it slows and bears right, behind them, clear of it."""
    obs = observe(pedestrian(0, 2.5, -3.5, 0.0, 1.0))
    off = Zhang2019V2Params()
    on = Zhang2019V2Params(w_social=2.0, social_horizon=3.0)
    social = (on.social_horizon, on.social_forecast, on.social_band)
    with compiled(enabled):
        v_off = plan(obs, GOAL, 1.0, 0.3, 0.25, np.zeros(2), off).velocity
        v_on = plan(obs, GOAL, 1.0, 0.3, 0.25, np.zeros(2), on).velocity
    discs = (np.array([[2.5, -3.5]]), np.array([[0.0, 1.0]]), np.array([0.65]))

    def soc(v: np.ndarray) -> float:
        return float(social_risk(np.zeros(2), v[None], v[None], np.zeros(1), discs, social)[0])

    assert v_off.tolist() == [1.0, 0.0] and soc(v_off) > 0.5
    assert v_on[1] < 0.0 and v_on[0] < 1.0 and soc(v_on) == 0.0
