"""The whole Ch. 7 pipeline: coverage, δ, curvature, margins, determinism, invalid inputs."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from shapely.geometry import box

from uvnav.recon.plan import ReconConfig, plan_recon
from uvnav.recon.terrain import fractal_terrain, square_area


@pytest.fixture(scope="module")
def terrain():  # type: ignore[no-untyped-def]
    return fractal_terrain((320.0, 320.0), cell=5.0, seed=7, origin=(-60.0, -60.0), n_blocks=6)


CFG = ReconConfig(
    footprint_radius=30.0, uavs=2, n_lambda=8, r_min=12.0, check_step=1.0, check_points=20_000
)


@pytest.fixture(scope="module")
def plan(terrain):  # type: ignore[no-untyped-def]
    return plan_recon(terrain, square_area(200.0), CFG)


def test_plan_meets_every_claim(plan) -> None:  # type: ignore[no-untyped-def]
    s = plan.summary()
    assert s["coverage_visible"] == 1.0
    # on ground truth, apart from the planning samples: 1 m grid, random points, polygons
    assert s["coverage_grid_visible"] == 1.0 and s["grid_unseen_visible"] == 0
    assert s["coverage_random_visible"] == 1.0 and s["check_random_points"] == 20_000
    assert s["polygon_uncovered_m2"] == 0.0
    assert s["n_waypoints"] <= s["n_naive"]
    assert s["n_waypoints"] >= s["bound_disc"]
    assert s["max_waypoint_distance"] <= CFG.delta
    assert s["max_curvature"] <= 1.0 / CFG.r_min
    assert s["max_tangent_jump"] < 1e-5
    assert s["min_waypoint_separation"] >= CFG.c1
    assert s["min_waypoint_terrain"] >= CFG.c2 - 0.3  # sampled terrain distance, quarter-cell grid
    # (7.4): within δ of a waypoint the UAV keeps c2 − δ (triangle inequality); elsewhere the
    # altitude bump keeps ~c2 above the terrain; vertical clearance bounds the 3D distance above
    assert s["min_clearance"] >= CFG.c2 - CFG.delta
    assert np.all(plan.waypoints[:, 2] <= plan.z_max + 1e-9)
    assert len(plan.uavs) == 2
    assert plan.integrated is not None
    assert plan.integrated.check.max_waypoint_distance <= CFG.delta
    assert plan.integrated.check.max_curvature <= 1.0 / CFG.r_min
    visited = np.sort(np.concatenate([u.indices for u in plan.uavs]))
    np.testing.assert_array_equal(visited, np.arange(len(plan.waypoints)))


def test_plan_is_deterministic(terrain, plan) -> None:  # type: ignore[no-untyped-def]
    again = plan_recon(terrain, square_area(200.0), CFG)
    np.testing.assert_array_equal(again.waypoints, plan.waypoints)
    for a, b in zip(again.uavs, plan.uavs, strict=True):
        np.testing.assert_array_equal(a.indices, b.indices)
        np.testing.assert_allclose(a.trajectory.beziers, b.trajectory.beziers)


@pytest.mark.parametrize(
    "change,field",
    [
        ({"theta": 0.0}, "theta"),
        ({"theta": math.pi}, "theta"),
        ({"z_min": 100.0, "z_max": 50.0}, "z_min"),
        ({"c1": 9.0}, "c1"),
        ({"c2": 5.0}, "c2"),
        ({"delta": 0.0}, "delta"),
        ({"r_min": 40.0}, "r_min"),
        ({"footprint_radius": -1.0}, "radius"),
        ({"uavs": 0}, "uavs"),
        ({"z_max": 20.0}, "z_max"),
        ({"check_step": 0.0}, "check_step"),
        ({"check_points": -1}, "check_points"),
    ],
)
def test_invalid_inputs_rejected(terrain, change: dict, field: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ValueError, match=rf"^{field}"):
        plan_recon(terrain, square_area(100.0), replace(CFG, **change))


def test_area_outside_dem_rejected(terrain) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ValueError, match=r"^area"):
        plan_recon(terrain, box(200.0, 200.0, 400.0, 400.0), CFG)
