"""The smooth closed trajectory (thesis Ch. 7 (7.3)): Dubins words, Béziers, curvature, δ."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.recon import bezier as Bz  # noqa: N812
from uvnav.recon.checks import check_trajectory

coord = st.floats(min_value=-80.0, max_value=80.0)
ang = st.floats(min_value=-math.pi, max_value=math.pi)


@settings(max_examples=80, deadline=None)
@given(x0=coord, y0=coord, h0=ang, x1=coord, y1=coord, h1=ang, r=st.floats(2.0, 40.0))
def test_shortest_dubins_reaches_the_goal(
    x0: float, y0: float, h0: float, x1: float, y1: float, h1: float, r: float
) -> None:
    s = np.array([x0, y0, h0])
    e = np.array([x1, y1, h1])
    path = Bz.shortest_dubins(s, e, r)
    x, y, _ = Bz._integrate(path)
    assert math.hypot(x - x1, y - y1) < 1e-6 * max(1.0, r)
    assert path.length >= math.hypot(x1 - x0, y1 - y0) - 1e-9
    # no word of any type is shorter than the chosen one
    assert path.length <= float(Bz.dubins_length(s[None], e[None], r)[0]) + 1e-9
    # the Bézier pieces join end to start and end at the goal
    pieces = Bz.dubins_beziers_xy(path)
    if pieces:
        ends = np.array([b[3] for b in pieces[:-1]])
        starts = np.array([b[0] for b in pieces[1:]])
        np.testing.assert_allclose(ends, starts, atol=1e-9)
        np.testing.assert_allclose(pieces[-1][3], [x1, y1], atol=1e-6 * max(1.0, r))


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 10_000), n=st.integers(3, 14), r_min=st.floats(3.0, 30.0))
def test_trajectory_respects_curvature_delta_and_is_smooth(seed: int, n: int, r_min: float) -> None:
    rng = np.random.default_rng(seed)
    P = np.column_stack([rng.uniform(0, 200, (n, 2)), rng.uniform(30, 60, n)])
    delta = 5.0
    traj = Bz.build_trajectory(P, np.arange(n), r_min=r_min, delta=delta)
    chk = check_trajectory(traj, P)
    assert chk.max_curvature <= 1.0 / r_min
    assert chk.max_waypoint_distance <= delta
    assert chk.max_tangent_jump < 1e-5
    # closed: the last piece ends where the first begins
    np.testing.assert_allclose(traj.beziers[-1, 3], traj.beziers[0, 0], atol=1e-6)


def test_turn_radius_rule() -> None:
    Bz.check_turn_radius(32.0, 5.0)
    with pytest.raises(ValueError, match=r"^r_min"):
        Bz.check_turn_radius(33.0, 5.0)
    with pytest.raises(ValueError, match=r"^r_min"):
        Bz.check_turn_radius(0.0, 5.0)


def test_altitude_bump_clears_a_ridge() -> None:
    """Between two waypoints at 30 m, a 40 m ridge: the profile rises over it (c2 = 10 m)."""

    def ridge(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return np.where((np.abs(np.asarray(x) - 100.0) < 10.0) & (np.asarray(y) < 60.0), 40.0, 0.0)

    P = np.array([[0.0, 0.0, 30.0], [200.0, 0.0, 30.0], [100.0, 150.0, 30.0]])
    traj = Bz.build_trajectory(
        P, np.arange(3), r_min=10.0, delta=5.0, terrain_height=ridge, c2=10.0
    )
    pts = traj.sample(64)
    over = (np.abs(pts[:, 0] - 100.0) < 10.0) & (pts[:, 1] < 60.0)
    assert over.any()
    assert np.all(pts[over, 2] >= 50.0 - 1e-6)


def test_single_waypoint_is_a_loiter_circle() -> None:
    P = np.array([[10.0, 20.0, 40.0]])
    traj = Bz.build_trajectory(P, np.array([0]), r_min=8.0, delta=5.0)
    chk = check_trajectory(traj, P)
    assert chk.max_waypoint_distance < 1e-9
    assert chk.length == pytest.approx(2 * math.pi * 8.0 * (1 + Bz.ARC_MARGIN), rel=1e-3)
    assert chk.max_curvature <= 1 / 8.0
    assert chk.max_tangent_jump < 1e-6
