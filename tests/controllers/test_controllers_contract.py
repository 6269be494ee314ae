"""The controller contract, for every registered law: finite commands within the limits (2.4) on
degenerate observations — robot on an obstacle's boundary, at its centre or on the goal, zero-size
and zero-speed obstacles, obstacles faster than the robot, a polygon with a repeated vertex."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers import available_controllers, make_controller
from uvnav.dynamics import UnicycleSpec
from uvnav.obstacles import (
    ConstantVelocity,
    Obstacle,
    ObstacleField,
    ObstacleState,
    PolygonBody,
)
from uvnav.sensors import Observation, sense_obstacles

SPEC = UnicycleSpec(v_max=0.707, u_max=1.414, radius=0.1)
GOAL = np.array([10.0, 0.0])
LAWS = sorted(available_controllers())
coords = st.floats(-2.0, 2.0, allow_nan=False)


@pytest.mark.parametrize("name", LAWS)
@settings(max_examples=25, deadline=None)
@given(
    rx=coords,
    ry=coords,
    th=st.floats(-math.pi, math.pi),
    vx=st.floats(-1.0, 1.0),
    vy=st.floats(-1.0, 1.0),
    radius=st.floats(0.0, 1.0),
    where=st.sampled_from(["boundary", "centre", "origin", "goal"]),
    speed=st.floats(0.0, SPEC.v_max),
)
def test_commands_are_finite_and_within_limits_for_degenerate_geometry(
    name: str,
    rx: float,
    ry: float,
    th: float,
    vx: float,
    vy: float,
    radius: float,
    where: str,
    speed: float,
) -> None:
    r = max(radius, 1e-6)
    pose = np.array(
        {
            "boundary": [rx + r, ry, th],
            "centre": [rx, ry, th],
            "origin": [0.0, 0.0, th],
            "goal": [GOAL[0], GOAL[1], th],
        }[where]
    )
    square = PolygonBody.from_vertices(
        np.array([[0, 0], [1, 0], [1, 0], [1, 1], [0, 1]], dtype=float) * max(radius, 0.01)
    )
    obstacles = [
        Obstacle.moving_disc((rx, ry), r, (vx, vy)),
        Obstacle.moving_disc((rx, ry), r),
        Obstacle(square, ObstacleState(np.array([rx, ry])), ConstantVelocity(np.zeros(2))),
    ]
    readings = sense_obstacles(pose[:2], ObstacleField.from_obstacles(obstacles))
    ctrl = make_controller(name)
    ctrl.reset(SPEC, GOAL, np.random.default_rng(0))
    for k in range(3):
        obs = Observation(time=0.1 * k, pose=pose, speed=speed, goal=GOAL, obstacles=readings)
        cmd = ctrl.act(obs)
        assert math.isfinite(cmd.v) and math.isfinite(cmd.u)
        assert not cmd.violates(SPEC)
        assert isinstance(ctrl.mode, str) and ctrl.mode
