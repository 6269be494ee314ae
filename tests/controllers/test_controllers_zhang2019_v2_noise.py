"""``zhang2019-v2`` under declared centre noise (``ObstacleReading.position_std``): each body is
grown by ``noise_sigmas`` times its noise on every decision path (the numpy references, the loop
of the ideal vehicle, the rolled-out paths), exact readings are read as before, and a noisy body
beside the way is given the wider berth an exact one is not."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers.zhang2019_limits import RampModel
from uvnav.controllers.zhang2019_v2 import Zhang2019V2Params, plan, plan_limited
from uvnav.controllers.zhang2019_v2_bodies import body_table, boundary_discs, grown_by_noise
from uvnav.geometry.kernels3d import compiled, numba_available
from uvnav.sensors.observation import Observation, ObstacleReading, Readings, read_arrays

GOAL = np.array([0.0, 6.0])
PARAMS = Zhang2019V2Params()
IDEAL = RampModel(1.0, math.pi, math.inf, math.inf, 0.25)
LIMITED = RampModel(1.0, math.pi, 1.0, 2.0, 0.25)


def _disc(k: int, x: float, y: float, vx: float, vy: float, std: float) -> ObstacleReading:
    """A person (disc of 0.3 m) at (x, y) seen from the origin, centre noise ``std`` [m]."""
    c, dist = np.array([x, y]), math.hypot(x, y)
    return ObstacleReading(k, dist - 0.3, c * (1.0 - 0.3 / dist), c, np.array([vx, vy]), 0.0,
                           np.zeros((0, 2)), 0.3, 0.3, "estimated", std)  # fmt: skip


def _square(k: int, x: float, y: float, vx: float, vy: float, std: float) -> ObstacleReading:
    """A 1 m square spinning at 0.2 rad/s centred at (x, y), centre noise ``std`` [m]."""
    c = np.array([x, y])
    outline = c + np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
    dist = max(math.hypot(x, y) - 0.71, 0.0)
    return ObstacleReading(k, dist, c * 0.5, c, np.array([vx, vy]), 0.2, outline, 0.0, 0.71,
                           "estimated", std)  # fmt: skip


def _beside(std: float) -> Observation:
    """A robot at the origin facing GOAL at 1 m/s; one person standing 0.9 m to the right of its
    way, 1.5 m ahead: 0.25 m beyond the radius sum and margin (0.65 m) from the straight path."""
    return Observation(time=0.0, pose=np.array([0.0, 0.0, math.pi / 2]), speed=1.0, goal=GOAL,
                       obstacles=(_disc(0, 0.9, 1.5, 0.0, 0.0, std),))  # fmt: skip


def _decide(obs: Observation, how: str, loop: bool, p: Zhang2019V2Params) -> np.ndarray:
    """The chosen velocity of one decision path: ``plan`` for the holonomic robot and the
    unicycle checked as one turn, ``plan_limited`` on the ideal and the limited vehicle."""
    ahead = np.array([0.0, 1.0])
    if how == "holonomic":
        return plan(obs, GOAL, 1.0, 0.3, 0.25, ahead, p, loop=loop).velocity
    if how == "turn":
        return plan(obs, GOAL, 1.0, 0.3, 0.25, ahead, p, loop=loop, heading=obs.heading,
                    u_max=math.pi).velocity  # fmt: skip
    model = IDEAL if how == "ideal" else LIMITED
    return plan_limited(obs, GOAL, model, 0.3, (1.0, 0.0), ahead, p, loop=loop).velocity


@pytest.mark.parametrize("loop", [False, True])
@pytest.mark.parametrize("how", ["holonomic", "turn", "ideal", "limited"])
def test_a_noisy_body_beside_the_way_gets_a_wider_berth(how: str, loop: bool) -> None:
    """Sensed exactly, a person standing just clear of the way is passed straight at full speed;
    sensed with 0.15 m of noise (grown by 2 sigma: 0.3 m, into the way) the robot does not drive
    the straight line at full speed but bends away from the person (or slows)."""
    p = dataclasses.replace(PARAMS, noise_sigmas=2.0)
    exact = _decide(_beside(0.0), how, loop, p)
    np.testing.assert_allclose(exact, [0.0, 1.0], atol=1e-9)
    noisy = _decide(_beside(0.15), how, loop, p)
    assert noisy[0] < -1e-3 or math.hypot(*noisy) < 0.99  # away from the person, or slower
    assert noisy[0] <= 1e-9  # never toward them
    ignored = _decide(_beside(0.15), how, loop, dataclasses.replace(p, noise_sigmas=0.0))
    np.testing.assert_allclose(ignored, exact, atol=0.0)


def test_exact_readings_are_read_as_before() -> None:
    """Readings that declare no noise give the same arrays (a sensor's own arrays: the same
    objects) whatever ``noise_sigmas``; noisy ones are grown by k sigma, polygons through their
    boundary discs."""
    exact = (_disc(0, 2.0, 0.0, 0.0, 0.0, 0.0), _square(1, 0.0, 3.0, 0.0, 0.0, 0.0))
    plain = body_table(exact, 2.0)
    for a, b in zip(plain, read_arrays(exact), strict=True):
        assert a.tobytes() == b.tobytes()
    own = read_arrays(exact)
    lazy = Readings.lazy(exact, lambda: own, all_known=True)
    assert all(a is b for a, b in zip(body_table(lazy, 2.0), own, strict=True))
    noisy = tuple(dataclasses.replace(rd, position_std=0.1) for rd in exact)
    scal = body_table(noisy, 2.0)[0]
    np.testing.assert_allclose(scal[:, 0], own[0][:, 0] - 0.2)
    np.testing.assert_allclose(scal[:, 2], [0.5, -0.2])
    np.testing.assert_allclose(scal[:, 3], own[0][:, 3] + 0.2)
    r = boundary_discs(noisy, 0.25, body_table(noisy, 2.0))[2]
    np.testing.assert_allclose(r, [0.5] + [0.125 + 0.2] * (len(r) - 1))


def test_growth_is_never_negative_distance() -> None:
    t = (np.array([[0.05, 0.0, 0.3, 0.3]]), np.zeros((1, 2)), np.zeros((1, 2)))
    assert grown_by_noise(t, np.array([0.2]))[0][0, 0] == 0.0


def _noisy_scene(seed: int, n: int, squares: bool) -> tuple[Observation, tuple[float, float]]:
    """Up to ``n`` bodies 1.2-6 m around the origin, each with its own centre noise (0-0.2 m),
    every third a spinning square with ``squares``; the robot's speed and turn rate."""
    rng = np.random.default_rng(seed)
    rows = []
    for k in range(n):
        x, y = rng.uniform(-6.0, 6.0, 2)
        if math.hypot(x, y) > 1.2:
            vx, vy = rng.uniform(-1.2, 1.2, 2)
            make = _square if squares and k % 3 == 0 else _disc
            rows.append(make(k, x, y, vx, vy, float(rng.choice([0.0, 0.05, 0.1, 0.2]))))
    rows.sort(key=lambda rd: rd.distance)
    pose = np.array([0.0, 0.0, rng.uniform(-math.pi, math.pi)])
    obs = Observation(time=0.0, pose=pose, speed=0.0, goal=GOAL, obstacles=tuple(rows))
    return obs, (float(rng.uniform(0.0, 1.0)), float(rng.uniform(-1.0, 1.0)))


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(1, 14), squares=st.booleans(),
       how=st.sampled_from(["holonomic", "turn", "ideal", "limited"]))  # fmt: skip
def test_every_path_chooses_what_its_reference_chooses_under_noise(
    seed: int, n: int, squares: bool, how: str
) -> None:
    """Under declared noise the one-call loops (plain Python and compiled) pick what the numpy
    references pick: the same velocity, first contact and M1 flag."""
    obs, now = _noisy_scene(seed, n, squares)
    p = dataclasses.replace(PARAMS, noise_sigmas=1.5)
    v_prev = np.array([0.3, 0.4])
    kw = {"heading": obs.heading, "u_max": math.pi} if how == "turn" else {}
    model = IDEAL if how == "ideal" else LIMITED

    def decide(loop: bool) -> tuple[np.ndarray, float, bool]:
        if how in ("holonomic", "turn"):
            c = plan(obs, GOAL, 1.0, 0.3, 0.25, v_prev, p, loop=loop, **kw)  # type: ignore[arg-type]
        else:
            c = plan_limited(obs, GOAL, model, 0.3, now, v_prev, p, loop=loop)
        return c.velocity, c.ttc, c.preferred

    with compiled(False):
        ref, plain = decide(False), decide(True)
    for got in (plain, decide(True)) if numba_available() else (plain,):
        np.testing.assert_allclose(got[0], ref[0], atol=1e-9)
        assert got[1] == pytest.approx(ref[1], abs=1e-9) or got[1] == ref[1]
        assert got[2] == ref[2]
