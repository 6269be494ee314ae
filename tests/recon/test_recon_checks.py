"""The plan checks measure what they claim: a known circle, a kinked curve, flat-ground coverage."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvnav.recon.bezier import DubinsPath, Trajectory, dubins_beziers_xy
from uvnav.recon.checks import check_coverage, check_margins_measured, check_trajectory
from uvnav.recon.terrain import Terrain


def circle_trajectory(r: float, z: float) -> Trajectory:
    path = DubinsPath(
        np.array([r, 0.0, math.pi / 2]), "LSL", np.array([2 * math.pi * r, 0.0, 0.0]), r
    )
    xy = np.asarray(dubins_beziers_xy(path))
    B = np.concatenate([xy, np.full((len(xy), 4, 1), z)], axis=2)
    return Trajectory(B, B[:1, 0], np.zeros(1), np.zeros(1), r)


def test_circle_length_curvature_and_distances() -> None:
    r = 20.0
    traj = circle_trajectory(r, 50.0)
    flat = Terrain(np.zeros((11, 11)), -50.0, -50.0, 10.0, 10.0)
    wp = np.array([[0.0, 0.0, 50.0], [r + 3.0, 0.0, 50.0]])
    c = check_trajectory(traj, wp, flat)
    assert c.length == pytest.approx(2 * math.pi * r, rel=1e-3)
    assert c.max_curvature == pytest.approx(1 / r, rel=2e-3)
    assert c.max_tangent_jump < 1e-9
    assert c.max_waypoint_distance == pytest.approx(r, rel=1e-3)  # the centre is r away
    assert c.min_clearance == pytest.approx(50.0)


def test_kink_is_reported() -> None:
    traj = circle_trajectory(10.0, 30.0)
    B = traj.beziers.copy()
    B[1, 1, :2] = B[1, 0, :2] + (B[1, 0, :2] - B[0, 2, :2]) * np.array([1.0, -1.0])  # break G1
    c = check_trajectory(Trajectory(B, traj.pass_points, traj.headings, traj.order, 10.0), B[:, 0])
    assert c.max_tangent_jump > 0.1


def test_flat_coverage_and_margins() -> None:
    flat = Terrain(np.zeros((21, 21)), 0.0, 0.0, 5.0, 5.0)
    X, Y = np.meshgrid(flat.xs, flat.ys)
    nodes = np.column_stack([X.ravel(), Y.ravel(), np.zeros(X.size)])
    wp = np.array([[50.0, 50.0, 80.0]])  # θ = 90°: footprint 80 m covers the 100 m square's nodes
    cov = check_coverage(flat, nodes, wp, math.pi / 2, 80.0)
    assert cov.coverage_all == 1.0 and cov.coverage_visible == 1.0
    low = check_coverage(flat, nodes, np.array([[50.0, 50.0, 20.0]]), math.pi / 2, 80.0)
    assert low.coverage_all == pytest.approx(np.mean(np.hypot(X - 50, Y - 50) <= 20.0))
    qij, qi = check_margins_measured(
        flat, np.array([[0.0, 0.0, 30.0], [30.0, 40.0, 30.0]]), search=20.0
    )
    assert qij == pytest.approx(50.0)
    assert qi == pytest.approx(30.0, abs=1e-6)
