"""The intrusion ratio (:mod:`uvnav.sim.social`) on hand-built scenes whose counts are known:
a robot crossing a walking pedestrian's path in front of or behind them, and a pedestrian the
robot cannot see."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from uvnav.dynamics import UnicycleCommand, UnicycleSpec
from uvnav.obstacles import Obstacle
from uvnav.sensors import Observation
from uvnav.sensors.config import SensingConfig
from uvnav.sim import EpisodeSetup, run_episode
from uvnav.sim.social import INTRUSION_HORIZON

ROBOT_R, PED_R = 0.2, 0.3
SPEC = UnicycleSpec(v_max=1.0, u_max=1.0, radius=ROBOT_R)


class Northward:
    """Drives north at 1 m/s whatever it sees."""

    name = "northward"
    oracle = False
    mode = ""

    def reset(self, spec: Any, goal: np.ndarray, rng: np.random.Generator) -> None:
        pass

    def act(self, obs: Observation) -> UnicycleCommand:
        return UnicycleCommand(1.0, 0.0)


def _crossing(ahead: float, sensing_range: float = 5.0) -> Any:
    """The robot drives north along x = 0 from y = -2.125 and crosses the x axis at t = 2.125 s;
    a pedestrian walks east along it at 1 m/s, its centre ``ahead`` m short of the crossing point
    then (negative: past it).  40 steps of 0.25 s."""
    ped = Obstacle.moving_disc((-ahead - 2.125, 0.0), PED_R, (1.0, 0.0), name="ped")
    setup = EpisodeSetup(
        spec=SPEC, start=np.array([0.0, -2.125, np.pi / 2]), goal=np.array([0.0, 20.0]),
        obstacles=[ped], dt=0.25, control_period=0.25, t_max=10.0, goal_tolerance=0.1,
        sensing=SensingConfig(sensing_range=sensing_range),
    )  # fmt: skip
    return run_episode(setup, Northward(), np.random.default_rng(0), vehicle="unicycle")


def test_passing_half_a_metre_in_front_of_a_walker_intrudes() -> None:
    # centre 1.0 m ahead at the crossing: a gap of 1.0 - 0.3 - 0.2 = 0.5 m.  The forecast
    # (t - 3.125 + s, 0), s = 0.25 .. 1.25, comes within 0.5 m of the robot (0, t - 2.125) at
    # t = 1.75, 2.0, 2.25, 2.5 (|t - 2.125| < 0.5 with a forecast on it): 4 of 40 steps
    res = _crossing(1.0)
    m = res.metrics
    assert res.status == "timeout"  # no contact: the closest approach is sqrt(0.5) > 0.5
    assert m.intrusion_ratio == pytest.approx(4 / 40)


def test_passing_a_metre_behind_a_walker_does_not() -> None:
    # centre 1.0 m past the crossing: the mirror image of the scene above in time (the same
    # distances now), but the walker moves away: its forecast is never within 0.5 m
    behind, front = _crossing(-1.0).metrics, _crossing(1.0).metrics
    assert behind.min_separation == pytest.approx(front.min_separation, abs=1e-12)
    assert behind.intrusion_ratio == 0.0


@pytest.mark.parametrize(("reach", "steps"), [(0.4, 0), (0.8, 2), (1.2, 4)])
def test_a_walker_outside_the_sensing_range_never_counts(reach: float, steps: int) -> None:
    # at the intruding steps t = 1.75, 2.0, 2.25, 2.5 the walker's disc is 1.125, 0.832, 0.584,
    # 0.429 m from the robot's centre: only the steps with it within range count
    m = _crossing(1.0, sensing_range=reach).metrics
    assert m.intrusion_ratio == pytest.approx(steps / 40)


def test_horizon_is_crowdnavs_five_steps() -> None:
    assert INTRUSION_HORIZON == 1.25
