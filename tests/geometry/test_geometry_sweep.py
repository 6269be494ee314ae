"""Behaviour of the swept collision kernels of :mod:`uvnav.geometry.sweep`.

The reference is a 100x finer time grid (s = 0, 0.01, ..., 1) under the same motion model (robot
on the chord, body centre and heading linear in s), with shapely's exact point-polygon distance:
the sweep never misses a contact the grid finds, and never reports one it does not, within its
stated conservatism (0 without rotation, twice the rotation bound of the sub-step with it) plus the
grid's own error (the fastest relative body point times half a grid step).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from shapely.geometry import Polygon
from test_geometry_polygons import star_polygons  # type: ignore[import-not-found]

from uvnav.dynamics.unicycle import unicycle_advance
from uvnav.geometry.polygons import polygon_nearest
from uvnav.geometry.sweep import (
    DEPTH_TOL,
    MAX_SUBSTEPS,
    arc_slack,
    body_sweep,
    disc_sweep,
    polygon_sweep,
    rotation_bound,
)

coord = st.floats(min_value=-8.0, max_value=8.0, allow_nan=False, allow_infinity=False)
offset = st.floats(min_value=-3.0, max_value=3.0, allow_nan=False, allow_infinity=False)
heading = st.floats(min_value=-math.pi, max_value=math.pi, allow_nan=False)
robot_r = st.floats(min_value=0.0, max_value=0.5)
SETTINGS = settings(max_examples=60, deadline=None)
FINE = np.linspace(0.0, 1.0, 101)
GRID_HALF_STEP = 0.005
#: floating-point slack [m] of the comparisons
TOL = 1e-8


def _ring(verts: np.ndarray) -> np.ndarray:
    return np.vstack([verts, verts[:1]])


def _signed_distance(points: np.ndarray, verts: np.ndarray) -> np.ndarray:
    """Exact signed distance (negative inside) from each point (S, 2) to the polygon."""
    poly = Polygon(verts)
    d = shapely.distance(poly.exterior, shapely.points(points))
    inside = shapely.contains_xy(poly, points[:, 0], points[:, 1])
    return np.where(inside, -d, d)


def _body_frame(p0, p1, c0, c1, h0, dh, s):  # type: ignore[no-untyped-def]
    """The robot's centre in the body frame at each s, under the module's motion model."""
    p0, p1, c0, c1 = map(np.asarray, (p0, p1, c0, c1))
    rel = p0 - c0 + s[:, None] * ((p1 - c1) - (p0 - c0))
    h = h0 + s * dh
    cs, sn = np.cos(h), np.sin(h)
    return np.stack([cs * rel[:, 0] + sn * rel[:, 1], cs * rel[:, 1] - sn * rel[:, 0]], axis=-1)


def _body_gaps(p0, p1, c0, c1, h0, dh, verts, r, s=FINE):  # type: ignore[no-untyped-def]
    return _signed_distance(_body_frame(p0, p1, c0, c1, h0, dh, np.asarray(s)), verts) - r


def _check_against_grid(
    gap: float, s_hit: float, fine: np.ndarray, conservatism: float, grid_error: float
) -> None:
    """The sweep against the fine grid: a lower bound, tight within the stated error; contacts
    agree; the first contact is never after a grid sample in contact."""
    fine_min = float(fine.min())
    assert gap <= fine_min + 1e-9
    assert gap >= fine_min - (conservatism + grid_error) - TOL
    if fine_min < 0.0:
        assert gap < 0.0
    if gap < -(conservatism + grid_error + TOL):
        assert fine_min < 0.0
    assert math.isnan(s_hit) == (gap > 0.0)
    if not math.isnan(s_hit):
        assert 0.0 <= s_hit <= 1.0
        assert np.all(fine[s_hit > FINE] > -1e-9)


# --------------------------------------------------------------------------------------------
# discs


@SETTINGS
@given(
    st.tuples(coord, coord),
    st.tuples(offset, offset),
    st.lists(st.tuples(coord, coord, offset, offset, st.floats(0.0, 2.0)), min_size=1, max_size=6),
)
def test_disc_sweep_agrees_with_a_fine_grid(
    p0: tuple[float, float], aim: tuple[float, float], discs: list[tuple[float, ...]]
) -> None:
    a = np.array(p0)
    b = -a + np.array(aim)  # a fast robot crossing the scene: up to ~20 m in one step
    arr = np.array(discs)
    c0, c1, radius = arr[:, :2], arr[:, :2] + arr[:, 2:4], arr[:, 4]
    gap, s_min, s_hit = disc_sweep(a, b, c0, c1, radius)
    assert gap.shape == s_min.shape == s_hit.shape == (len(discs),)
    for j in range(len(discs)):
        rel = (a - c0[j]) + FINE[:, None] * ((b - c1[j]) - (a - c0[j]))
        fine = np.hypot(rel[:, 0], rel[:, 1]) - radius[j]
        speed = float(np.hypot(*((b - c1[j]) - (a - c0[j]))))
        _check_against_grid(gap[j], s_hit[j], fine, 0.0, speed * GRID_HALF_STEP)
        at = (a - c0[j]) + s_min[j] * ((b - c1[j]) - (a - c0[j]))
        assert float(np.hypot(*at)) - radius[j] == pytest.approx(gap[j], abs=1e-12)
        if not math.isnan(s_hit[j]) and fine[0] > 0.0:
            at = (a - c0[j]) + s_hit[j] * ((b - c1[j]) - (a - c0[j]))
            assert float(np.hypot(*at)) == pytest.approx(radius[j], abs=1e-9)


def test_disc_sweep_head_on_contact_time() -> None:
    # 10 m apart, closing at 20 m per step, radius sum 1 m: touch at s = 0.45, pass through at 0.5
    gap, s_min, s_hit = disc_sweep([0.0, 0.0], [10.0, 0.0], [[10.0, 0.0]], [[0.0, 0.0]], 1.0)
    assert gap[0] == pytest.approx(-1.0) and s_min[0] == pytest.approx(0.5)
    assert s_hit[0] == pytest.approx(0.45, abs=1e-15)


def test_disc_sweep_already_in_contact_and_receding() -> None:
    gap, s_min, s_hit = disc_sweep([0.0, 0.0], [-3.0, 0.0], [[0.5, 0.0]], [[0.5, 0.0]], 1.0)
    assert gap[0] == pytest.approx(-0.5) and s_min[0] == 0.0 and s_hit[0] == 0.0


def test_disc_sweep_grazing_is_a_contact_at_its_touching_time() -> None:
    gap, s_min, s_hit = disc_sweep([-1.0, 1.0], [1.0, 1.0], [[0.0, 0.0]], [[0.0, 0.0]], 1.0)
    assert gap[0] == 0.0 and s_min[0] == 0.5 and s_hit[0] == 0.5


def test_disc_sweep_zero_motion_is_the_static_distance_without_warnings() -> None:
    c = np.array([[3.0, 4.0], [0.5, 0.0], [0.0, 0.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        gap, s_min, s_hit = disc_sweep([0.0, 0.0], [0.0, 0.0], c, c, np.array([1.0, 1.0, 0.0]))
    assert gap.tolist() == [4.0, -0.5, 0.0]
    assert s_min.tolist() == [0.0, 0.0, 0.0]
    assert math.isnan(s_hit[0]) and s_hit[1:].tolist() == [0.0, 0.0]


def test_disc_sweep_moving_together_is_static() -> None:
    # robot and disc share the same velocity: no relative motion
    gap, s_min, s_hit = disc_sweep([0.0, 0.0], [5.0, 5.0], [[2.0, 0.0]], [[7.0, 5.0]], 0.5)
    assert gap[0] == 1.5 and s_min[0] == 0.0 and math.isnan(s_hit[0])


# --------------------------------------------------------------------------------------------
# polygons and bodies


@SETTINGS
@given(star_polygons(), st.tuples(coord, coord), st.tuples(offset, offset), robot_r,
       st.tuples(offset, offset), st.tuples(offset, offset), heading)  # fmt: skip
def test_translating_body_sweep_is_exact_against_a_fine_grid(
    verts: np.ndarray,
    p0: tuple[float, float],
    aim: tuple[float, float],
    r: float,
    c0: tuple[float, float],
    move: tuple[float, float],
    h0: float,
) -> None:
    a, b = np.array(p0), -np.array(p0) + np.array(aim)
    c_start, c_end = np.array(c0), np.array(c0) + np.array(move)
    gap, s_min, s_hit = body_sweep(a, b, c_start, c_end, h0, 0.0, _ring(verts), r)
    fine = _body_gaps(a, b, c_start, c_end, h0, 0.0, verts, r)
    speed = float(np.hypot(*((b - c_end) - (a - c_start))))
    _check_against_grid(gap, s_hit, fine, 0.0, speed * GRID_HALF_STEP)
    exact = lambda s: float(_body_gaps(a, b, c_start, c_end, h0, 0.0, verts, r, [s])[0])  # noqa: E731
    # exact where it says, within the depth tolerance inside
    assert exact(s_min) == pytest.approx(gap, abs=DEPTH_TOL + 1e-9)
    if not math.isnan(s_hit) and fine[0] > 0.0:
        assert exact(s_hit) == pytest.approx(0.0, abs=1e-7)


@SETTINGS
@given(star_polygons(max_n=8), st.tuples(coord, coord), st.tuples(offset, offset), robot_r,
       st.tuples(offset, offset), st.tuples(offset, offset), heading,
       st.one_of(st.floats(-3.0, 3.0), st.floats(-40.0, 40.0)),
       st.sampled_from([1e-3, 1e-2, 0.1]))  # fmt: skip
def test_rotating_body_sweep_is_conservative_within_its_bound(
    verts: np.ndarray,
    p0: tuple[float, float],
    aim: tuple[float, float],
    r: float,
    c0: tuple[float, float],
    move: tuple[float, float],
    h0: float,
    dh: float,
    rot_tol: float,
) -> None:
    a, b = np.array(p0), -np.array(p0) + np.array(aim)
    c_start, c_end = np.array(c0), np.array(c0) + np.array(move)
    gap, _, s_hit = body_sweep(a, b, c_start, c_end, h0, dh, _ring(verts), r, rot_tol=rot_tol)
    fine = _body_gaps(a, b, c_start, c_end, h0, dh, verts, r)
    rb = float(np.hypot(verts[:, 0], verts[:, 1]).max())
    m, delta = rotation_bound(rb, dh, rot_tol)
    assert delta <= rot_tol or m == MAX_SUBSTEPS
    speed = float(np.hypot(*((b - c_end) - (a - c_start)))) + rb * abs(dh)
    _check_against_grid(gap, s_hit, fine, 2.0 * delta, speed * GRID_HALF_STEP)


@SETTINGS
@given(star_polygons(max_n=8), st.tuples(coord, coord), st.tuples(offset, offset), robot_r,
       st.tuples(offset, offset), st.tuples(offset, offset), heading,
       st.floats(-6.0, 6.0))  # fmt: skip
def test_body_sweep_is_the_least_of_its_sub_steps(
    verts: np.ndarray,
    p0: tuple[float, float],
    aim: tuple[float, float],
    r: float,
    c0: tuple[float, float],
    move: tuple[float, float],
    h0: float,
    dh: float,
) -> None:
    # the sub-steps skipped by their lower bound change nothing: every sub-step swept against the
    # body frozen at its mid heading, the robot's radius grown by the rotation bound
    a, b = np.array(p0), -np.array(p0) + np.array(aim)
    c_start, c_end = np.array(c0), np.array(c0) + np.array(move)
    ring = _ring(verts)
    m, delta = rotation_bound(float(np.hypot(verts[:, 0], verts[:, 1]).max()), dh)
    want_gap, want_hit = math.inf, math.nan
    for j in range(m):
        hm = h0 + dh * (j + 0.5) / m
        q = _body_frame(a, b, c_start, c_end, hm, 0.0, np.array([j / m, (j + 1) / m]))
        g, _, sh = polygon_sweep(q[0], q[1], ring, r + delta)
        want_gap = min(want_gap, g)
        if math.isnan(want_hit) and not math.isnan(sh):
            want_hit = (j + sh) / m
    gap, s_min, s_hit = body_sweep(a, b, c_start, c_end, h0, dh, ring, r)
    assert gap == pytest.approx(want_gap, abs=1e-9) and 0.0 <= s_min <= 1.0
    if math.isnan(want_hit) or math.isnan(s_hit):
        assume(abs(gap) > 1e-9)  # a graze: rounding may tell either way
        assert math.isnan(want_hit) and math.isnan(s_hit)
    else:
        assert s_hit == pytest.approx(want_hit, abs=1e-9)


@SETTINGS
@given(star_polygons(), coord, coord, robot_r)
def test_static_point_is_the_plain_signed_distance(
    verts: np.ndarray, x: float, y: float, r: float
) -> None:
    d, _, inside = polygon_nearest(np.array([x, y]), verts)
    want = (-d if inside else d) - r
    gap, s_min, s_hit = polygon_sweep([x, y], [x, y], _ring(verts), r)
    assert gap == pytest.approx(want, abs=1e-12) and s_min == 0.0
    assert (s_hit == 0.0) if want <= 0.0 else math.isnan(s_hit)


@SETTINGS
@given(star_polygons(), coord, coord, robot_r, heading, st.tuples(offset, offset))
def test_static_body_is_the_plain_signed_distance_in_its_frame(
    verts: np.ndarray, x: float, y: float, r: float, h: float, c: tuple[float, float]
) -> None:
    gap, _, _ = body_sweep([x, y], [x, y], c, c, h, 0.0, _ring(verts), r)
    want = float(_body_gaps([x, y], [x, y], c, c, h, 0.0, verts, r, [0.0])[0])
    assert gap == pytest.approx(want, abs=1e-9)


def test_passing_through_a_thin_wall_between_two_samples() -> None:
    # a wall 5 cm thick; both end points of the step are clear of it by 0.875 m
    wall = _ring(np.array([[-0.025, -1.0], [0.025, -1.0], [0.025, 1.0], [-0.025, 1.0]]))
    gap, s_min, s_hit = polygon_sweep([-1.0, 0.0], [1.0, 0.0], wall, 0.1)
    assert gap == pytest.approx(-0.125) and s_min == pytest.approx(0.5)
    assert s_hit == pytest.approx((1.0 - 0.025 - 0.1) / 2.0, abs=1e-15)
    for q in ([-1.0, 0.0], [1.0, 0.0]):
        assert polygon_sweep(q, q, wall, 0.1)[0] == pytest.approx(0.875)
    # the same wall flying through a static robot
    gap, _, s_hit = body_sweep([0.0, 0.0], [0.0, 0.0], [1.0, 0.0], [-1.0, 0.0], 0.0, 0.0, wall, 0.1)
    assert gap == pytest.approx(-0.125) and s_hit == pytest.approx(0.4375, abs=1e-15)


def test_sweep_through_a_vertex_of_a_diamond_and_a_graze() -> None:
    diamond = _ring(np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]]))
    gap, s_min, s_hit = polygon_sweep([-2.0, 0.0], [2.0, 0.0], diamond, 0.0)
    assert gap == pytest.approx(-math.sqrt(0.5)) and s_min == pytest.approx(0.5)
    assert s_hit == pytest.approx(0.25)
    # passing above the top vertex at 0.5 m with radius 0.5: a graze at the vertex, s = 0.5
    gap, s_min, s_hit = polygon_sweep([-2.0, 1.5], [2.0, 1.5], diamond, 0.5)
    assert gap == pytest.approx(0.0, abs=1e-15) and s_hit == pytest.approx(0.5, abs=1e-7)
    assert math.isnan(polygon_sweep([-2.0, 1.5], [2.0, 1.5], diamond, 0.49)[2])


def test_non_convex_deepest_point_of_a_u_shape() -> None:
    # a U open upwards; a segment across both arms passes in, out through the slot, in again
    u = _ring(np.array([[0, 0], [3, 0], [3, 2], [2, 2], [2, 1], [1, 1], [1, 2], [0, 2]], float))
    gap, _, s_hit = polygon_sweep([-1.0, 1.5], [4.0, 1.5], u, 0.0)
    assert gap == pytest.approx(-0.5, abs=DEPTH_TOL) and s_hit == pytest.approx(0.2)
    gap, _, _ = polygon_sweep([-1.0, 0.5], [4.0, 0.5], u, 0.0)
    assert gap == pytest.approx(-0.5, abs=DEPTH_TOL)


def test_started_inside_is_a_contact_at_zero() -> None:
    sq = _ring(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]))
    gap, s_min, s_hit = polygon_sweep([0.5, 0.5], [3.0, 0.5], sq, 0.0)
    assert gap == pytest.approx(-0.5, abs=DEPTH_TOL) and s_min == pytest.approx(0.0)
    assert s_hit == 0.0


def test_rotating_plank_hits_no_later_than_the_true_contact() -> None:
    # a 2 m x 0.2 m plank turning a quarter turn about its centre under a robot 0.6 m up: the
    # robot's centre sits at 0.6 cos(theta) from the plank's line, so contact (0.2 m) at
    # cos(theta) = 1/3
    plank = _ring(np.array([[-1.0, -0.1], [1.0, -0.1], [1.0, 0.1], [-1.0, 0.1]]))
    true_s = math.acos(1.0 / 3.0) / (math.pi / 2.0)
    for rot_tol in (1e-3, 1e-2, 0.2):
        gap, _, s_hit = body_sweep(
            [0.0, 0.6], [0.0, 0.6], [0.0, 0.0], [0.0, 0.0], 0.0, math.pi / 2, plank, 0.1,
            rot_tol=rot_tol,
        )  # fmt: skip
        _, delta = rotation_bound(math.hypot(1.0, 0.1), math.pi / 2, rot_tol)
        assert gap <= 0.6 * math.cos(math.pi / 2) - 0.2 + 1e-12
        assert s_hit <= true_s
        # the conservative contact: the frozen gap reaches delta no sooner than the true gap
        # reaches 2 delta (|frozen - true| <= delta)
        assert s_hit >= math.acos((0.2 + 2.0 * delta) / 0.6) / (math.pi / 2.0) - 1e-9


def test_rotation_bound_subdivides_to_its_tolerance_and_caps() -> None:
    assert rotation_bound(1.0, 0.0) == (1, 0.0)
    m, delta = rotation_bound(2.0, 0.5, 1e-2)
    assert m == math.ceil(2.0 * 0.5 / 2.0 / 1e-2) == 50 and delta <= 1e-2
    assert delta == pytest.approx(2.0 * 2.0 * math.sin(0.5 / (4 * m)))
    m, delta = rotation_bound(1.0, 1e3)
    assert m == MAX_SUBSTEPS and delta == pytest.approx(2.0)  # half turns and more: 2 R_b


# --------------------------------------------------------------------------------------------
# the unicycle's arc against its chord


@settings(max_examples=80, deadline=None)
@given(st.floats(-3.0, 3.0), st.floats(-4.0, 4.0), st.floats(0.01, 1.5), heading)
def test_a_unicycle_arc_stays_within_arc_slack_of_its_chord(
    v: float, u: float, dt: float, theta: float
) -> None:
    n = 50
    x, y, th = 1.0, -2.0, theta
    arc = [(x, y)]
    for _ in range(n):
        x, y, th = unicycle_advance(x, y, th, v, u, dt / n)
        arc.append((x, y))
    pts = np.array(arc)
    s = np.linspace(0.0, 1.0, n + 1)[:, None]
    chord = pts[0] + s * (pts[-1] - pts[0])
    dev = float(np.hypot(*(pts - chord).T).max())
    slack = arc_slack(v, u, dt)
    assert dev <= slack + 1e-12
    if abs(u * dt) <= 0.5:  # the bound is the sagitta's leading term: tight for small turns
        assert dev >= 0.99 * slack - 1e-12
