"""Property tests for :mod:`uvnav.geometry.angles` (wrapping to (-pi, pi], signed angles)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

from uvnav.geometry.angles import (
    heading_vector,
    signed_angle,
    vector_angle,
    wrap_scalar,
    wrap_to_pi,
)

PI = math.pi
angles = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, allow_infinity=False)
coords = st.floats(min_value=-1e3, max_value=1e3, allow_nan=False, allow_infinity=False)


def _mod_2pi_gap(a: float, b: float) -> float:
    """Distance between two angles on the circle [rad]."""
    d = math.remainder(a - b, 2.0 * PI)
    return abs(d)


@settings(max_examples=300, deadline=None)
@given(angles)
@example(PI)
@example(-PI)
@example(3.0 * PI)
@example(-3.0 * PI)
@example(0.0)
@example(math.nextafter(PI, 4.0))  # just above pi: must wrap to ~ -pi + tiny or pi, never below -pi
@example(math.nextafter(-PI, 0.0))
def test_wrap_to_pi_range_and_congruence(a: float) -> None:
    w = float(wrap_to_pi(a))
    ws = wrap_scalar(a)
    for x in (w, ws):
        assert -PI < x <= PI, f"wrap({a!r}) = {x!r} is outside (-pi, pi]"
        assert _mod_2pi_gap(x, a) <= 1e-15 * max(1.0, abs(a)) * 8
    assert w == ws


def test_wrap_to_pi_pi_is_positive_branch() -> None:
    assert float(wrap_to_pi(PI)) == PI
    assert float(wrap_to_pi(-PI)) == PI
    assert wrap_scalar(-PI) == PI


@settings(max_examples=100, deadline=None)
@given(st.lists(angles, min_size=1, max_size=20))
def test_wrap_to_pi_vectorised_matches_scalar(values: list[float]) -> None:
    arr = np.asarray(values)
    out = wrap_to_pi(arr)
    assert out.shape == arr.shape
    assert np.array_equal(out, np.array([wrap_scalar(v) for v in values]))


@settings(max_examples=200, deadline=None)
@given(st.floats(min_value=-PI, max_value=PI, exclude_min=True))
def test_wrap_is_identity_on_range_up_to_rounding(a: float) -> None:
    assert abs(float(wrap_to_pi(a)) - a) <= 4.5e-16


@settings(max_examples=300, deadline=None)
@given(coords, coords, coords, coords)
def test_signed_angle_antisymmetric_and_rotates(ax: float, ay: float, bx: float, by: float) -> None:
    a, b = np.array([ax, ay]), np.array([bx, by])
    ab = float(signed_angle(a, b))
    ba = float(signed_angle(b, a))
    assert -PI < ab <= PI and -PI < ba <= PI
    # antisymmetric modulo 2*pi (the pi case maps onto itself: both +pi)
    assert _mod_2pi_gap(ab, -ba) <= 1e-12
    na, nb = np.hypot(ax, ay), np.hypot(bx, by)
    if na > 1e-6 and nb > 1e-6:
        # rotating a by the signed angle points it along b
        rotated = heading_vector(float(vector_angle(a)) + ab)
        assert np.allclose(rotated, b / nb, atol=1e-9)


def test_signed_angle_zero_vectors_never_nan() -> None:
    z = np.zeros(2)
    assert float(signed_angle(z, z)) == 0.0
    assert float(signed_angle(z, [1.0, 0.0])) == 0.0
    assert float(signed_angle([0.0, 1.0], z)) == 0.0


def test_signed_angle_known_values() -> None:
    assert math.isclose(float(signed_angle([1, 0], [0, 1])), PI / 2)
    assert math.isclose(float(signed_angle([0, 1], [1, 0])), -PI / 2)
    assert float(signed_angle([1, 0], [-1, 0])) == PI
    assert float(signed_angle([-1, 0], [1, 0])) == PI


def test_signed_angle_vectorised() -> None:
    rng = np.random.default_rng(0)
    a = rng.normal(size=(50, 2))
    b = rng.normal(size=(50, 2))
    out = signed_angle(a, b)
    assert out.shape == (50,)
    assert np.allclose(out, [float(signed_angle(x, y)) for x, y in zip(a, b, strict=True)])
