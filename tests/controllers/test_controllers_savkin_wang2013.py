"""The Savkin-Wang 2013 baseline: cone geometry, fixed side, and behaviour on the thesis scenes."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers import make_controller
from uvnav.controllers.savkin_wang2013 import SavkinWang2013Controller, in_cone, widened_cone
from uvnav.dynamics import UnicycleSpec
from uvnav.obstacles import Obstacle, ObstacleField
from uvnav.scenarios import build_episode, load_scenario
from uvnav.sensors import Observation, sense_obstacles
from uvnav.sim import EpisodeSetup, run_episode, run_rng

SPEC = UnicycleSpec(v_max=0.707, u_max=1.414, radius=0.1)
GOAL = np.array([10.0, 0.0])


def disc(x: float, y: float, r: float, v: tuple[float, float] = (0.0, 0.0)) -> Obstacle:
    return Obstacle.moving_disc((x, y), r, v)


def test_widened_cone_contains_the_disc_with_margin() -> None:
    b1, b2 = widened_cone(np.zeros(2), np.array([2.0, 0.0]), 1.0, 0.2)
    half = math.asin(0.5) + 0.2
    assert b1 == pytest.approx(-half) and b2 == pytest.approx(half)
    assert in_cone(np.array([1.0, 0.0]), b1, b2)
    assert not in_cone(np.array([math.cos(half + 0.01), math.sin(half + 0.01)]), b1, b2)
    assert not in_cone(np.array([-1.0, 0.0]), b1, b2)


def test_cone_across_the_pi_cut_is_handled() -> None:
    b1, b2 = widened_cone(np.zeros(2), np.array([-2.0, 0.0]), 1.0, 0.1)
    assert in_cone(np.array([-1.0, 0.01]), b1, b2) and in_cone(np.array([-1.0, -0.01]), b1, b2)
    assert not in_cone(np.array([1.0, 0.0]), b1, b2)


@settings(max_examples=80, deadline=None)
@given(
    vx=st.floats(-0.6, 0.6),
    vy=st.floats(-0.6, 0.6),
    beta=st.floats(-math.pi, math.pi),
)
def test_desired_speed_never_exceeds_v_max(vx: float, vy: float, beta: float) -> None:
    ctrl = make_controller("savkin-wang2013-v1")
    assert isinstance(ctrl, SavkinWang2013Controller)
    ctrl.reset(SPEC, GOAL, np.random.default_rng(0))
    obs = Observation(
        time=0.0,
        pose=np.zeros(3),
        speed=0.0,
        goal=GOAL,
        obstacles=sense_obstacles(
            np.zeros(2), ObstacleField.from_obstacles([disc(1.0, 0.0, 0.3, (vx, vy))])
        ),
    )
    if math.hypot(vx, vy) < SPEC.v_max:
        v = ctrl.desired_velocity(obs.obstacles[0], beta)
        assert math.hypot(*v) <= SPEC.v_max + 1e-9


def test_head_on_disc_is_avoided_and_side_is_kept() -> None:
    setup = EpisodeSetup(
        spec=SPEC, start=np.zeros(3), goal=GOAL, obstacles=[disc(5.0, 0.05, 0.8, (-0.2, 0.0))]
    )
    ctrl = make_controller("savkin-wang2013-v1")
    sides = []
    original = ctrl.act

    def spy(obs: Observation):  # type: ignore[no-untyped-def]
        cmd = original(obs)
        if ctrl.mode == "M2":
            sides.append(ctrl._side)  # type: ignore[attr-defined]
        return cmd

    ctrl.act = spy  # type: ignore[method-assign]
    res = run_episode(setup, ctrl, run_rng(0))
    assert res.status == "success"
    assert res.metrics.min_clearance > 0.1
    assert sides and len(set(sides)) == 1  # h is chosen once, when avoidance starts


def test_reaches_target_on_the_fig_2_10_scene() -> None:
    scenario = load_scenario("thesis-ch2-fig2-10-comparison")
    res = run_episode(
        build_episode(scenario, 0), make_controller("savkin-wang2013-v1"), run_rng(0), record=False
    )
    assert res.status == "success"
    assert res.metrics.min_clearance > 0.0


def test_no_obstacle_means_pure_pursuit_at_v_max() -> None:
    ctrl = make_controller("savkin-wang2013-v1")
    ctrl.reset(SPEC, GOAL, np.random.default_rng(0))
    cmd = ctrl.act(Observation(time=0.0, pose=np.array([0.0, 0.0, 0.5]), speed=0.0, goal=GOAL))
    assert cmd.v == SPEC.v_max and cmd.u < 0 and ctrl.mode == "M1"
