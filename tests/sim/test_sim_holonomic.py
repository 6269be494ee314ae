"""The holonomic disc robot in any 2D scene (``World2D`` with ``vehicle="holonomic"``): exact
straight motion, the V_max disc counted and enforced, and ORCA's velocity taken as it is."""

from __future__ import annotations

import math
from typing import Any, ClassVar

import numpy as np
import pytest

from uvnav.controllers.base import make_law
from uvnav.dynamics.omni import OmniSpec, VelocityCommand
from uvnav.scenarios import build_episode, load_scenario
from uvnav.scenarios.catalog import resolve
from uvnav.scenarios.episodes import run_scene
from uvnav.sim import run_rng
from uvnav.sim.run import run_episode


class TooFast:
    """Asks for twice V_max along +x: the world must count and scale it."""

    name: ClassVar[str] = "too-fast"
    oracle = False
    mode = "M1"

    def reset(self, spec: Any, goal: np.ndarray, rng: np.random.Generator) -> None:
        assert isinstance(spec, OmniSpec) and spec.u_max == math.inf
        self.spec = spec

    def act(self, obs: Any) -> VelocityCommand:
        return VelocityCommand(2.0 * self.spec.v_max, 0.0)


def test_a_command_outside_the_disc_is_counted_and_scaled() -> None:
    setup = build_episode(load_scenario("open-field"), 0)
    res = run_episode(setup, TooFast(), run_rng(0), vehicle="holonomic")
    v_max = setup.spec.v_max
    tr = res.trajectory
    assert tr is not None
    speeds = np.hypot(tr.commands[:, 0], tr.commands[:, 1])
    assert np.all(speeds <= v_max + 1e-12) and res.metrics.limit_violations > 0
    step = np.diff(tr.robot[:, 0])  # straight along +x at V_max
    assert np.allclose(step, v_max * setup.dt) and np.allclose(tr.robot[:, 1], tr.robot[0, 1])


def test_straight_holonomic_runs_the_straight_line_time() -> None:
    out = run_scene(resolve("open-field"), "straight-holonomic-v1")
    assert out.status == "success"
    # straight at V_max from the first step, no turning: the physical limit (up to the last
    # step's overshoot into the goal disc)
    assert 1.0 <= out.metrics["detour_ratio"] < 1.01
    assert 1.0 <= out.metrics["time_ratio"] < 1.01


@pytest.mark.parametrize("scene", ["thesis-ch2-one-obstacle", "random-ch2:3"])
def test_orca_holonomic_avoids_what_straight_line_hits(scene: str) -> None:
    res = resolve(scene)
    straight = run_scene(res, "straight-holonomic-v1")
    orca = run_scene(res, "orca-holonomic-v1")
    assert orca.status == "success" and orca.metrics["min_clearance"] > 0.0
    assert orca.metrics["limit_violations"] == 0
    assert straight.metrics["min_clearance"] <= orca.metrics["min_clearance"]


def test_unicycle_law_cannot_drive_the_holonomic_world() -> None:
    law = make_law("straight-holonomic-v1")
    setup = build_episode(load_scenario("open-field"), 0)
    with pytest.raises(ValueError, match="no 2D world for vehicle 'boat'"):
        run_episode(setup, law, run_rng(0), vehicle="boat")
