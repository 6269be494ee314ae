"""Behaviour of the artificial potential field baseline (``apf-v1``)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

import uvnav.controllers.apf  # noqa: F401  (registers apf-v1)
from uvnav.controllers import ControllerParamsError, make_controller
from uvnav.controllers.apf import ApfController, attractive_force
from uvnav.dynamics import UnicycleSpec
from uvnav.obstacles import (
    ConstantVelocity,
    Obstacle,
    ObstacleState,
    PolygonBody,
)
from uvnav.scenarios import build_episode, load_scenario
from uvnav.sim import EpisodeSetup, run_episode, run_rng

SPEC = UnicycleSpec(v_max=0.707, u_max=1.414, radius=0.1)
GOAL = np.array([10.0, 0.0])


def disc(x: float, y: float, r: float, v: tuple[float, float] = (0.0, 0.0)) -> Obstacle:
    return Obstacle.moving_disc((x, y), r, v)


def u_trap() -> Obstacle:
    """A U open toward the robot, its bottom between the robot and T: a classic APF trap."""
    world = np.array(
        [[4, 1.0], [6, 1.0], [6, -1.0], [4, -1.0], [4, -1.3], [6.3, -1.3], [6.3, 1.3], [4, 1.3]],
        dtype=float,
    )
    body = PolygonBody.from_vertices(world)
    return Obstacle(body, ObstacleState(body.offset.copy()), ConstantVelocity(np.zeros(2)))


def trap_setup() -> EpisodeSetup:
    return EpisodeSetup(spec=SPEC, start=np.zeros(3), goal=GOAL, obstacles=[u_trap()], t_max=60.0)


def test_attraction_is_quadratic_near_and_conic_far() -> None:
    near = attractive_force(np.array([9.5, 0.0]), GOAL, 1.0, 1.0)
    far = attractive_force(np.array([0.0, 0.0]), GOAL, 1.0, 1.0)
    assert near == pytest.approx([0.5, 0.0])
    assert far == pytest.approx([1.0, 0.0])


def test_reaches_target_without_collision_on_the_thesis_scene() -> None:
    setup = build_episode(load_scenario("thesis-ch2-one-obstacle"), 0)
    res = run_episode(setup, make_controller("apf-v1"), run_rng(0), record=False)
    assert res.status == "success"
    assert (res.metrics.min_clearance or -1.0) > 0.0
    assert res.metrics.limit_violations == 0


def test_static_disc_head_on_is_avoided() -> None:
    setup = EpisodeSetup(spec=SPEC, start=np.zeros(3), goal=GOAL, obstacles=[disc(5.0, 0.0, 0.8)])
    res = run_episode(setup, make_controller("apf-v1"), run_rng(2), record=False)
    assert res.status == "success"
    assert (res.metrics.min_clearance or -1.0) > 0.1


def test_escape_gets_out_of_a_u_trap_where_plain_apf_stalls() -> None:
    plain = run_episode(trap_setup(), make_controller("apf-v1", escape=False), run_rng(3))
    assert plain.status == "timeout"
    assert plain.trajectory is not None
    final = plain.trajectory.robot[-1, :2]  # stuck inside the cup, short of its bottom
    assert 3.5 < final[0] < 6.0 and abs(final[1]) < 1.0
    ctrl = make_controller("apf-v1")
    assert isinstance(ctrl, ApfController)
    escaped = run_episode(trap_setup(), ctrl, run_rng(3), record=False)
    assert escaped.status == "success"
    assert (escaped.metrics.min_clearance or -1.0) > 0.0
    assert ctrl.stalls >= 1


def test_escape_is_deterministic_per_seed() -> None:
    a = run_episode(trap_setup(), make_controller("apf-v1"), run_rng(5), record=False)
    b = run_episode(trap_setup(), make_controller("apf-v1"), run_rng(5), record=False)
    assert a.status == b.status
    assert a.metrics.path_length == b.metrics.path_length


@pytest.mark.parametrize(
    ("bad", "message"),
    [
        ({"influence": 0.0}, "influence"),
        ({"repulse_gain": -1.0}, "repulse_gain"),
        ({"min_distance": 2.0}, "min_distance"),
        ({"escape": "yes"}, "escape"),
        ({"nope": 1}, "unknown"),
    ],
)
def test_bad_parameters_are_rejected_with_the_field_name(bad: dict[str, Any], message: str) -> None:
    with pytest.raises(ControllerParamsError, match=message):
        make_controller("apf-v1", **bad)
