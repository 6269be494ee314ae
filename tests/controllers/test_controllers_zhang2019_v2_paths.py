"""``zhang2019-v2`` on the unicycle checked along rolled-out paths: the one-loop choice
(:mod:`uvnav.controllers.zhang2019_v2_paths`, compiled and plain Python) is the numpy
reference's, with and without acceleration limits, and the ideal unicycle crosses
CrowdNav cases where checking a turn and then a straight line lets it be walked into."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers.zhang2019_limits import RampModel, ramp_turns
from uvnav.controllers.zhang2019_v2 import Zhang2019V2Params, plan_limited
from uvnav.controllers.zhang2019_v2_paths import _ramp_turn
from uvnav.dynamics.unicycle import ramp_turn
from uvnav.geometry.kernels3d import compiled, numba_available
from uvnav.scenarios.catalog import resolve
from uvnav.scenarios.episodes import run_scene
from uvnav.sensors.observation import Observation, ObstacleReading

GOAL = np.array([0.0, 6.0])
MODELS = {
    "ideal": RampModel(1.0, math.pi, math.inf, math.inf, 0.25),
    "limited": RampModel(1.0, math.pi, 1.0, 2.0, 0.25),
    "limited-turn-first": RampModel(1.0, math.pi, 1.0, 2.0, 0.25, turn_first=True),
    "ideal-turn-first": RampModel(1.0, math.pi, math.inf, math.inf, 0.25, turn_first=True),
}


def _reading(k: int, x: float, y: float, vx: float, vy: float, square: bool) -> ObstacleReading:
    """A pedestrian (disc of 0.3 m) or a 1 m square, centred at (x, y), seen from the origin."""
    c, v = np.array([x, y]), np.array([vx, vy])
    dist = float(np.hypot(x, y))
    if square:
        outline = c + np.array([[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]])
        return ObstacleReading(k, max(dist - 0.71, 0.0), c * 0.5, c, v, 0.2, outline, 0.0, 0.71)
    near = c * (1.0 - 0.3 / dist)
    return ObstacleReading(k, dist - 0.3, near, c, v, 0.0, np.zeros((0, 2)), 0.3, 0.3)


def _scene(seed: int, n: int, squares: bool) -> tuple[Observation, tuple[float, float], np.ndarray]:
    """Bodies 0.9-6 m around a robot at the origin (nearest first), its speed and turn rate, and
    its previous choice."""
    rng = np.random.default_rng(seed)
    rows = []
    for k in range(n):
        x, y = rng.uniform(-6.0, 6.0, 2)
        if math.hypot(x, y) > 0.9:
            rows.append((math.hypot(x, y), k, x, y, *rng.uniform(-1.2, 1.2, 2)))
    readings = tuple(_reading(k, x, y, vx, vy, squares and k % 3 == 0)
                     for _, k, x, y, vx, vy in sorted(rows))  # fmt: skip
    pose = np.array([0.0, 0.0, rng.uniform(-math.pi, math.pi)])
    obs = Observation(time=0.0, pose=pose, speed=0.0, goal=GOAL, obstacles=readings)
    now = (float(rng.uniform(0.0, 1.0)), float(rng.uniform(-1.0, 1.0)))
    return obs, now, rng.uniform(-1.0, 1.0, 2)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(0, 14), squares=st.booleans(),
       model=st.sampled_from(sorted(MODELS)))  # fmt: skip
def test_loop_chooses_what_the_numpy_reference_chooses(
    seed: int, n: int, squares: bool, model: str
) -> None:
    """Branch-and-bound, the culls and the early stops leave the choice as the exhaustive
    reference makes it: the same velocity, first contact and M1 flag (to rounding: the loop's
    sines and cosines are the C library's, the reference's numpy's)."""
    obs, now, v_prev = _scene(seed, n, squares)
    p = Zhang2019V2Params()
    ref = plan_limited(obs, GOAL, MODELS[model], 0.3, now, v_prev, p, loop=False)
    with compiled(False):
        plain = plan_limited(obs, GOAL, MODELS[model], 0.3, now, v_prev, p, loop=True)
    for got in (plain,) + (
        (plan_limited(obs, GOAL, MODELS[model], 0.3, now, v_prev, p, loop=True),)
        if numba_available()
        else ()
    ):
        np.testing.assert_allclose(got.velocity, ref.velocity, atol=1e-9)
        assert got.ttc == pytest.approx(ref.ttc, abs=1e-9) or got.ttc == ref.ttc
        assert got.preferred == ref.preferred


def test_a_boxed_in_robot_gets_the_reference_fallback() -> None:
    """No candidate is safe (pedestrians on a ring walking at the robot): the loop checks every
    candidate to the end and picks as the reference does (one that can still stop first)."""
    ring = [(1.2 * math.cos(a), 1.2 * math.sin(a)) for a in np.linspace(0, 2 * math.pi, 9)[:-1]]
    readings = tuple(_reading(k, x, y, -0.8 * x / 1.2, -0.8 * y / 1.2, False)
                     for k, (x, y) in enumerate(ring))  # fmt: skip
    obs = Observation(time=0.0, pose=np.zeros(3), speed=0.0, goal=GOAL, obstacles=readings)
    p = Zhang2019V2Params()
    for model in MODELS.values():
        ref = plan_limited(obs, GOAL, model, 0.3, (0.5, 0.0), np.zeros(2), p, loop=False)
        got = plan_limited(obs, GOAL, model, 0.3, (0.5, 0.0), np.zeros(2), p, loop=True)
        assert ref.ttc <= p.min_ttc  # nothing safe
        np.testing.assert_allclose(got.velocity, ref.velocity, atol=1e-9)
        assert got.ttc == pytest.approx(ref.ttc, abs=1e-9)


@pytest.mark.parametrize("case", [44, 63, 71])
def test_rolled_out_paths_cross_where_the_straight_line_check_is_walked_into(case: int) -> None:
    """CrowdNav circle crossing (the turn-then-move unicycle): checked as one turn and then a
    straight line, the robot flips between directions it never reaches and a human walks into
    it; checked along the paths its steering drives, it gets across (the local law alone: the
    route off)."""
    scene = resolve(f"crowdnav-circle:{case}")
    before = run_scene(scene, "zhang2019-v2", {"rollout_paths": False, "route_weight": 0.0})
    assert before.status == "collision"
    assert run_scene(scene, "zhang2019-v2", {"route_weight": 0.0}).status == "success"


def _gate(speed: float) -> Observation:
    """A robot at the origin at 1 m/s toward GOAL, two people 0.2 m either side of its way
    (0.7 m ahead) walking along it at ``speed``."""
    people = tuple(_reading(k, x, 0.7, 0.0, speed, False) for k, x in enumerate((-0.8, 0.8)))
    return Observation(time=0.0, pose=np.array([0.0, 0.0, math.pi / 2]), speed=1.0, goal=GOAL,
                       obstacles=people)  # fmt: skip


@pytest.mark.parametrize("loop", [False, True])
def test_people_standing_beside_the_way_are_passed_walking_ones_kept_at_comfort(
    loop: bool,
) -> None:
    """People standing still are kept clear of but not at the comfort distance (with it, two
    people standing at either side of the way stop the robot for good); people walking there
    still slow it down."""
    ideal, ahead = MODELS["ideal"], np.array([0.0, 1.0])
    for min_speed, expected in ((0.1, ahead), (0.0, np.zeros(2))):  # 0: the comfort for all
        p = Zhang2019V2Params(comfort_min_speed=min_speed)
        got = plan_limited(_gate(0.0), GOAL, ideal, 0.3, (1.0, 0.0), ahead, p, loop=loop)
        np.testing.assert_allclose(got.velocity, expected, atol=1e-9)
    walking = plan_limited(_gate(0.5), GOAL, ideal, 0.3, (1.0, 0.0), ahead, Zhang2019V2Params(),
                           loop=loop)  # fmt: skip
    assert 0.0 < math.hypot(*walking.velocity) < 0.5


@given(st.lists(st.tuples(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0)), min_size=1, max_size=8),
       st.sampled_from([0.5, 2.0, 7.3, math.inf]), st.sampled_from([0.1, 0.25]))  # fmt: skip
def test_the_period_turn_is_the_vehicles_to_the_bit_in_every_copy(
    pairs: list[tuple[float, float]], rate: float, period: float
) -> None:
    """The vehicle's period turn, the numpy rollout's and the compiled loop's are one number:
    the oracle's replays and the law's paths depend on it."""
    u_now = np.array([p[0] for p in pairs])
    target = np.array([p[1] for p in pairs])
    vehicle = [ramp_turn(a, b, rate, period) for a, b in pairs]
    assert ramp_turns(u_now, target, rate, period).tolist() == vehicle
    assert [_ramp_turn(a, b, rate, period) for a, b in pairs] == vehicle
