"""Property tests for circle tangents (thesis Ch. 2 eqs. (2.11)-(2.13), Fig. 2.6)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from uvnav.geometry.tangents import circle_tangents, disc_silhouette_angles

coord = st.floats(min_value=-50.0, max_value=50.0, allow_nan=False, allow_infinity=False)
radius = st.floats(min_value=0.0, max_value=20.0, allow_nan=False, allow_infinity=False)


@settings(max_examples=300, deadline=None)
@given(coord, coord, coord, coord, radius)
def test_tangent_points_lie_on_circle_and_are_perpendicular(
    px: float, py: float, cx: float, cy: float, r: float
) -> None:
    p, c = np.array([px, py]), np.array([cx, cy])
    d = float(np.hypot(*(c - p)))
    assume(d > r * (1.0 + 1e-9) + 1e-9)
    t = circle_tangents(p, c, r)
    scale = max(1.0, d)
    assert not t.inside
    assert math.isclose(t.gamma, math.asin(r / d), rel_tol=1e-12, abs_tol=1e-12)
    assert math.isclose(t.length, math.sqrt(d * d - r * r), rel_tol=1e-9, abs_tol=1e-9 * scale)
    for k in range(2):
        q = t.points[k]
        # on the circle
        assert abs(float(np.hypot(*(q - c))) - r) <= 1e-9 * scale
        # radius to the tangent point is perpendicular to the tangent line p -> q
        assert abs(float(np.dot(q - c, q - p))) <= 1e-9 * scale * scale
        # the stored angle is the direction p -> q
        if t.length > 1e-6:
            ang = math.atan2(q[1] - p[1], q[0] - p[0])
            assert abs(math.remainder(ang - t.angles[k], 2 * math.pi)) <= 1e-9
        assert math.isclose(float(np.hypot(*(q - p))), t.length, rel_tol=1e-9, abs_tol=1e-9 * scale)
    # p1 is the counter-clockwise one: angle(centre) + gamma
    base = math.atan2(cy - py, cx - px)
    assert abs(math.remainder(t.angles[0] - (base + t.gamma), 2 * math.pi)) <= 1e-12
    assert abs(math.remainder(t.angles[1] - (base - t.gamma), 2 * math.pi)) <= 1e-12


@settings(max_examples=200, deadline=None)
@given(coord, coord, coord, coord, radius)
def test_tangents_never_nan(px: float, py: float, cx: float, cy: float, r: float) -> None:
    t = circle_tangents(np.array([px, py]), np.array([cx, cy]), r)
    for arr in (t.points, t.angles, np.array([t.length, t.gamma])):
        assert np.all(np.isfinite(arr))
    assert 0.0 <= t.gamma <= math.pi / 2
    d = math.hypot(cx - px, cy - py)
    assert t.inside == (d <= r)


@pytest.mark.parametrize(
    ("point", "centre", "r"),
    [
        ([0.0, 0.0], [0.0, 0.0], 1.0),  # at the centre
        ([0.0, 0.0], [0.0, 0.0], 0.0),  # at the centre, zero radius
        ([1.0, 0.0], [0.0, 0.0], 1.0),  # on the circle
        ([0.3, 0.2], [0.0, 0.0], 1.0),  # inside
        ([3.0, 4.0], [0.0, 0.0], 0.0),  # zero radius
        ([3.0, 4.0], [0.0, 0.0], -1.0),  # negative radius is treated as zero
    ],
)
def test_degenerate_inputs(point: list[float], centre: list[float], r: float) -> None:
    t = circle_tangents(np.array(point), np.array(centre), r)
    assert np.all(np.isfinite(t.points)) and np.all(np.isfinite(t.angles))
    assert math.isfinite(t.gamma) and math.isfinite(t.length)
    if r > 0:
        assert t.inside
        assert t.gamma == pytest.approx(math.pi / 2)
        assert t.length == 0.0
        # the two lines are perpendicular to the radius through the point (opposite directions)
        assert abs(math.remainder(t.angles[0] - t.angles[1], 2 * math.pi)) == pytest.approx(math.pi)
    else:
        if np.hypot(*(np.array(point) - centre)) > 0:
            assert not t.inside
            assert t.gamma == 0.0
            assert np.allclose(t.points, [centre, centre])


def test_tangent_half_angle_converges_to_inside_limit() -> None:
    """Approaching the circle from outside, gamma -> pi/2 and length -> 0 (the documented limit)."""
    c, r = np.zeros(2), 1.0
    for eps in (1e-3, 1e-6, 1e-9):
        t = circle_tangents(np.array([r + eps, 0.0]), c, r)
        assert not t.inside
        assert t.gamma == pytest.approx(math.pi / 2, abs=2 * math.sqrt(2 * eps))
        assert t.length == pytest.approx(0.0, abs=2 * math.sqrt(2 * eps))


@settings(max_examples=200, deadline=None)
@given(coord, coord, coord, coord, st.floats(min_value=0.01, max_value=20.0))
def test_silhouette_rays_graze_the_disc(
    px: float, py: float, cx: float, cy: float, r: float
) -> None:
    p, c = np.array([px, py]), np.array([cx, cy])
    d = float(np.hypot(*(c - p)))
    assume(d > r * 1.001)
    cw, ccw = disc_silhouette_angles(p, c, r)
    for a in (cw, ccw):
        u = np.array([math.cos(a), math.sin(a)])
        m = c - p
        # perpendicular distance from the centre to the ray's line equals the radius
        assert abs(abs(u[0] * m[1] - u[1] * m[0]) - r) <= 1e-9 * max(1.0, d)
        assert float(np.dot(u, m)) > 0  # the ray points toward the disc
    # clockwise one is to the right of the centre direction
    base = math.atan2(m[1], m[0])
    assert math.remainder(cw - base, 2 * math.pi) < 0 < math.remainder(ccw - base, 2 * math.pi)
