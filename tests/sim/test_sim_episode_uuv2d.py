"""The Chapter-4 loop: exact collision checks, determinism with a noisy sonar, limit accounting."""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
import shapely

from uvnav.controllers.base import make_law
from uvnav.dynamics.holonomic import HolonomicCommand, HolonomicSpec
from uvnav.scenarios.uuv2d import load_uuv2d_scenario, random_ch4_scenario
from uvnav.sensors.sonar2d import SonarObservation
from uvnav.sim.metrics import METRIC_NAMES
from uvnav.sim.run import run_episode


class Straight:
    """Straight at E at the box's speed, ignoring the sonar."""

    name: ClassVar[str] = "straight-test"
    oracle = False
    mode = "M1"

    def reset(self, spec: HolonomicSpec, goal: np.ndarray, rng: np.random.Generator) -> None:
        self.goal = goal

    def act(self, obs: SonarObservation) -> HolonomicCommand:
        d = self.goal - obs.position
        return HolonomicCommand(*(d / np.abs(d).max()))


class TooFast(Straight):
    def act(self, obs: SonarObservation) -> HolonomicCommand:
        return HolonomicCommand(3.0, -3.0)


def test_straight_run_collides_exactly_when_the_disc_touches_the_body() -> None:
    sc = load_uuv2d_scenario("thesis-ch4-fig4-9-whole-run")
    res = run_episode(sc.to_setup(), Straight(), np.random.default_rng(0))
    assert res.status == "collision" and res.metrics.collision
    tr = res.trajectory
    assert tr is not None
    shape = sc.shapes()[0]
    # shapely agrees with the recorded clearance at every step, and it first goes negative last
    for t, p, c in zip(tr.times[::7], tr.poses[::7], tr.clearance[::7], strict=True):
        poly = shapely.polygons(shape.outline(float(t)))
        gap = shapely.distance(poly, shapely.points(p[:2])) - 0.2
        if shapely.contains_xy(poly, p[0], p[1]):
            gap = -shapely.distance(poly.exterior, shapely.points(p[:2])) - 0.2
        assert math.isclose(gap, c, abs_tol=1e-9)
    assert tr.clearance[-1] < 0 and np.all(tr.clearance[:-1] >= 0)


def test_same_seed_same_run_with_a_noisy_sonar() -> None:
    sc = random_ch4_scenario(5, noise_std=0.05, dropout=0.1)
    a = run_episode(
        sc.to_setup(), make_law("zhang2022-uuv2d-v1", vehicle="uuv2d"), np.random.default_rng(9)
    )
    b = run_episode(
        sc.to_setup(), make_law("zhang2022-uuv2d-v1", vehicle="uuv2d"), np.random.default_rng(9)
    )
    assert a.trajectory is not None and b.trajectory is not None
    assert np.array_equal(a.trajectory.poses, b.trajectory.poses)
    assert a.metrics.to_dict().keys() == set(METRIC_NAMES)


def test_commands_outside_the_limits_are_counted_and_saturated() -> None:
    sc = load_uuv2d_scenario("thesis-ch4-fig4-7-approach")
    setup = sc.to_setup()
    setup.t_max = 1.0
    res = run_episode(setup, TooFast(), np.random.default_rng(0))
    assert res.metrics.limit_violations == 5  # every decision (T = 0.2 s)
    tr = res.trajectory
    assert tr is not None
    step = np.diff(tr.poses[:, :2], axis=0) / setup.dt
    assert np.all(np.abs(step) <= setup.spec.v_max + 1e-9)
