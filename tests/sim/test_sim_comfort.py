"""The comfort metrics (:mod:`uvnav.sim.comfort`): the pure functions against geometry, and the
2D world's numbers on hand-built episodes whose values are known."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from uvnav.dynamics import UnicycleCommand, UnicycleSpec
from uvnav.obstacles import Obstacle
from uvnav.sensors import Observation
from uvnav.sensors.config import SensingConfig
from uvnav.sim import EpisodeSetup, run_episode
from uvnav.sim.comfort import heading_irregularity, mean_jerk, time_to_collision

ROBOT_R, PED_R = 0.2, 0.3
SPEC = UnicycleSpec(v_max=1.0, u_max=1.0, radius=ROBOT_R)

coord = st.floats(-10.0, 10.0, allow_nan=False)
speed = st.floats(-3.0, 3.0, allow_nan=False)
radius = st.floats(0.1, 2.0)


@settings(max_examples=300, deadline=None)
@given(coord, coord, speed, speed, radius)
def test_time_to_collision_is_the_first_contact_of_the_straight_motion(
    px: float, py: float, wx: float, wy: float, r: float
) -> None:
    p, w = np.array([px, py]), np.array([wx, wy])
    (t,) = time_to_collision(p[None], w[None], r)
    if np.hypot(px, py) <= r:
        assert t == 0.0
    elif math.isfinite(t):
        assert t > 0
        assert np.hypot(*(p + w * t)) == pytest.approx(r, abs=1e-6)
        for s in np.linspace(0.0, t, 20, endpoint=False):  # apart until then
            assert np.hypot(*(p + w * s)) > r - 1e-9
    else:  # never within r: the closest approach of the ray s >= 0 stays outside
        s = max(0.0, -float(p @ w) / float(w @ w)) if w @ w > 0 else 0.0
        assert np.hypot(*(p + w * s)) >= r - 1e-9


@settings(max_examples=100, deadline=None)
@given(coord, coord, speed, speed, speed, speed, radius)
def test_time_to_collision_depends_on_relative_motion_only(
    px: float, py: float, ax: float, ay: float, bx: float, by: float, r: float
) -> None:
    # the robot's view of the pedestrian and the pedestrian's view of the robot agree
    here = time_to_collision(np.array([[px, py]]), np.array([[bx - ax, by - ay]]), r)
    there = time_to_collision(np.array([[-px, -py]]), np.array([[ax - bx, ay - by]]), r)
    assert here[0] == pytest.approx(there[0])


@settings(max_examples=100, deadline=None)
@given(
    st.lists(st.tuples(coord, coord, st.floats(-10, 10)), min_size=1, max_size=20),
    coord, coord, st.floats(-math.pi, math.pi),
)  # fmt: skip
def test_heading_irregularity_is_an_angle_blind_to_rotating_the_scene(
    rows: list[tuple[float, float, float]], gx: float, gy: float, alpha: float
) -> None:
    a = np.asarray(rows)
    goal = np.array([gx, gy])
    assume(np.hypot(*(a[:, :2] - goal).T).min() > 1e-6 or np.allclose(a[:, :2], goal))
    got = heading_irregularity(a[:, :2], a[:, 2], goal)
    c, s = math.cos(alpha), math.sin(alpha)
    rot = np.array([[c, -s], [s, c]])
    turned = heading_irregularity(a[:, :2] @ rot.T, a[:, 2] + alpha, rot @ goal)
    if got is None:
        assert turned is None and np.allclose(a[:, :2], goal)
        return
    assert 0.0 <= got <= math.pi
    assert turned == pytest.approx(got, abs=1e-6)


def test_heading_irregularity_is_zero_when_facing_the_goal_and_pi_facing_away() -> None:
    p = np.array([[0.0, float(y)] for y in range(5)])
    assert heading_irregularity(p, np.full(5, math.pi / 2), np.array([0.0, 10.0])) == 0.0
    assert heading_irregularity(p, np.full(5, -math.pi / 2), np.array([0.0, 10.0])) == math.pi


@settings(max_examples=100, deadline=None)
@given(speed, speed, speed, speed, st.floats(0.01, 1.0), st.integers(3, 40))
def test_constant_acceleration_has_no_jerk_and_a_quadratic_velocity_a_constant_one(
    vx: float, vy: float, ax: float, ay: float, dt: float, n: int
) -> None:
    t = np.arange(n)[:, None] * dt
    linear = np.array([vx, vy]) + np.array([ax, ay]) * t
    assert mean_jerk(linear, dt) == pytest.approx(0.0, abs=1e-6)
    quadratic = np.array([ax, ay]) * t**2  # d^2 v / dt^2 = 2 (ax, ay)
    assert mean_jerk(quadratic, dt) == pytest.approx(2 * math.hypot(ax, ay), rel=1e-6, abs=1e-6)


class Constant:
    """Holds one command whatever it sees."""

    name = "constant"
    oracle = False
    mode = ""

    def __init__(self, v: float) -> None:
        self.v = v

    def reset(self, spec: Any, goal: np.ndarray, rng: np.random.Generator) -> None:
        pass

    def act(self, obs: Observation) -> UnicycleCommand:
        return UnicycleCommand(self.v, 0.0)


def _episode(ped: Obstacle, v: float, goal: tuple[float, float], t_max: float) -> Any:
    """The robot from (0, -2.125) heading north at ``v`` [m/s], one pedestrian, 0.25 s steps."""
    setup = EpisodeSetup(
        spec=SPEC, start=np.array([0.0, -2.125, np.pi / 2]), goal=np.array(goal),
        obstacles=[ped], dt=0.25, control_period=0.25, t_max=t_max, goal_tolerance=0.1,
        sensing=SensingConfig(sensing_range=5.0),
    )  # fmt: skip
    return run_episode(setup, Constant(v), np.random.default_rng(0), vehicle="unicycle")


def test_crossing_in_front_of_a_walker() -> None:
    # the walker's centre (t - 3.125, 0), the robot's (0, t - 2.125): centre distance
    # sqrt(2 u^2 + 0.5), u = t - 2.625, so the gap (distance - 0.5) is below 0.5 m for
    # |u| < 0.5: the steps t = 2.25, 2.5, 2.75, 3.0, 1.0 s.  Relative motion (1, -1) along the
    # line x + y = -1, 0.707 m from the robot > 0.5 m: never on a collision course.
    ped = Obstacle.moving_disc((-3.125, 0.0), PED_R, (1.0, 0.0), name="ped")
    m = _episode(ped, 1.0, (0.0, 20.0), 10.0).metrics
    assert m.min_separation == pytest.approx(math.sqrt(0.53125) - 0.5, abs=1e-9)  # u = 0.125
    assert m.personal_space_time == pytest.approx(1.0)
    assert m.min_time_to_collision is None
    assert m.heading_irregularity == 0.0  # straight at the goal all along
    # from rest to 1 m/s in the first step, then steady: one jerk of 1 / 0.25^2 = 16 m/s^3
    # among the 39 second differences of the 41 velocities
    assert m.jerk == pytest.approx(16.0 / 39)


def test_a_walker_on_course_toward_a_robot_at_rest() -> None:
    # the walker's centre (-5 + t, 0.3) reaches the robot's disc (radius sum 0.5) at x = -0.4:
    # time to collision 4.6 - t, smallest at the last step t = 2.0 (the episode ends there)
    ped = Obstacle.moving_disc((-5.0, -2.125 + 0.3), PED_R, (1.0, 0.0), name="ped")
    m = _episode(ped, 0.0, (0.0, -10.0), 2.0).metrics
    assert m.min_time_to_collision == pytest.approx(2.6)
    assert m.personal_space_time == 0.0
    assert m.heading_irregularity == pytest.approx(math.pi)  # facing away from the goal
    assert m.jerk == 0.0  # never moved


def test_touching_is_a_time_to_collision_of_zero() -> None:
    ped = Obstacle.moving_disc((-2.0, -2.125), PED_R, (1.0, 0.0), name="ped")
    res = _episode(ped, 0.0, (0.0, 20.0), 5.0)
    assert res.status == "collision"
    assert res.metrics.min_time_to_collision == 0.0
