"""Baselines on the Chapter-4 sonar: apf-v1 on the sweep, zhang2019-v1 on AMAPS."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvnav.controllers.base import make_law
from uvnav.controllers.uuv2d_baselines import reading_from_points
from uvnav.scenarios.uuv2d import load_uuv2d_scenario
from uvnav.sim.run import run_episode


@pytest.mark.parametrize("name", ["apf-uuv2d-v1", "zhang2019-uuv2d-v1"])
def test_baseline_runs_within_the_limits_and_avoids_the_fig_4_7_obstacle(name: str) -> None:
    sc = load_uuv2d_scenario("thesis-ch4-fig4-7-approach")
    res = run_episode(
        sc.to_setup(), make_law(name, vehicle="uuv2d"), np.random.default_rng(0), record=False
    )
    assert res.metrics.limit_violations == 0
    assert res.status == "success"
    assert res.metrics.min_clearance is not None and res.metrics.min_clearance > 0


def test_amaps_outline_contains_every_sensed_point() -> None:
    pts = np.array([[math.cos(a), math.sin(a)] for a in np.linspace(0, 6, 40)]) * 1.2 + 3.0
    r = reading_from_points(0, np.zeros(2), pts[0], 3.0, np.array([3.0, 3.0]), pts, outline=True)
    assert len(r.outline) >= 3
    rad = np.hypot(*(r.outline - 3.0).T)
    assert np.allclose(rad, 1.2)
    assert r.bounding_radius >= 1.2 and np.allclose(r.velocity, 0)
