"""Nine-sonar array (thesis Ch. 5 §5.2.3): exact cone returns, geometry, adaptive coefficient."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.geometry.mesh3d import Triangles, icosphere
from uvnav.obstacles.deforming3d import DeformingStar
from uvnav.sensors.sonar_array import (
    N_SONARS,
    SonarArray,
    adapted_ranges,
    adaptive_coefficients,
    beam_point,
    cone_nearest,
    nearest_beam,
    sonar_scan,
)

_UNIT_ERR = DeformingStar(centre=np.zeros(3), base_radius=1.0).tessellation_error(0.0)


def _sphere_cone_distance(apex, axis, alpha, centre, radius):  # type: ignore[no-untyped-def]
    """Closed form for a ball: straight to the centre when it is in the cone, else along the
    boundary generator nearest the centre direction."""
    w = centre - apex
    dw = np.linalg.norm(w)
    ang = math.acos(np.clip(w @ axis / dw, -1, 1))
    if ang <= alpha:
        return dw - radius
    perp = w - (w @ axis) * axis
    e = perp / np.linalg.norm(perp)
    g = math.cos(alpha) * axis + math.sin(alpha) * e
    b = g @ w
    disc = b * b - dw * dw + radius * radius
    if disc < 0 or b - math.sqrt(disc) < 0:
        return math.inf
    return b - math.sqrt(disc)


def _brute(apex, axis, alpha, tri: Triangles, n=2500, seed=0):  # type: ignore[no-untyped-def]
    rng = np.random.default_rng(seed)
    u = rng.random((n, 2))
    flip = u.sum(axis=1) > 1
    u[flip] = 1 - u[flip]
    pts = tri.a[:, None] + tri.ab[:, None] * u[None, :, :1] + tri.ac[:, None] * u[None, :, 1:]
    pts = pts.reshape(-1, 3)
    rel = pts - apex
    d = np.linalg.norm(rel, axis=1)
    ins = rel @ axis >= math.cos(alpha) * d
    return float(d[ins].min()) if ins.any() else math.inf


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 100_000),
    alpha=st.floats(math.radians(5), math.radians(60)),
)
def test_cone_return_equals_closed_form_for_a_ball(seed: int, alpha: float) -> None:
    rng = np.random.default_rng(seed)
    radius = float(rng.uniform(0.3, 2.0))
    centre = rng.normal(size=3) * 3
    apex = centre + rng.normal(size=3) * 4
    if np.linalg.norm(apex - centre) < radius + 0.1:
        apex = centre + np.array([radius + 3.0, 0, 0])
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    body = DeformingStar(centre=centre, base_radius=radius, subdivisions=3)
    err = _UNIT_ERR * radius
    got, q = cone_nearest(apex, axis, alpha, body.triangles(0.0))
    want = _sphere_cone_distance(apex, axis, alpha, centre, radius)
    if math.isinf(want):
        # a miss of the ball can only be a hit of the (inscribed) mesh if it is a miss too
        assert math.isinf(got)
        return
    if math.isinf(got):
        # the beam grazes the ball within the tessellation gap
        assert _sphere_cone_distance(apex, axis, alpha, centre, radius - 2 * err) == math.inf
        return
    # the mesh lies inside the ball, within err of its surface; a grazing generator can move the
    # first contact by up to sqrt(2 r err) along the beam
    assert got >= want - 1e-9
    assert got <= want + math.sqrt(2 * radius * err) + err
    rel = q - apex
    assert rel @ axis >= math.cos(alpha) * np.linalg.norm(rel) - 1e-7


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 100_000), alpha=st.floats(math.radians(5), math.radians(50)))
def test_cone_return_matches_dense_sampling_of_the_mesh(seed: int, alpha: float) -> None:
    rng = np.random.default_rng(seed)
    v, f = icosphere(1)
    v = v * rng.uniform(0.5, 1.5, 3) + rng.normal(size=3) * 0.3  # a random ellipsoid-ish mesh
    tri = Triangles.from_mesh(v, f)
    apex = rng.normal(size=3)
    apex = 3.0 * apex / np.linalg.norm(apex)
    axis = -apex / np.linalg.norm(apex) + rng.normal(size=3) * 0.5
    axis /= np.linalg.norm(axis)
    got, q = cone_nearest(apex, axis, alpha, tri)
    brute = _brute(apex, axis, alpha, tri)
    if math.isinf(brute):
        assert math.isinf(got) or got > 0  # sampling may miss a sliver the kernel finds
        return
    assert got <= brute + 1e-9  # never further than a sampled in-cone point
    assert got >= brute - 0.03  # sampling resolution of ~0.5 m triangles with 4000 points
    assert q is not None


def test_max_range_and_empty_scene() -> None:
    body = DeformingStar(centre=np.array([10.0, 0, 0]), base_radius=1.0)
    tri = body.triangles(0.0)
    d, _ = cone_nearest(np.zeros(3), np.array([1.0, 0, 0]), 0.3, tri, max_range=5.0)
    assert math.isinf(d)
    d, _ = cone_nearest(np.zeros(3), np.array([1.0, 0, 0]), 0.3, tri, max_range=20.0)
    assert d == pytest.approx(9.0, abs=1e-2)
    d, _ = cone_nearest(np.zeros(3), np.array([-1.0, 0, 0]), 0.3, tri)
    assert math.isinf(d)


def test_array_geometry_is_on_the_front_cap_and_not_coplanar() -> None:
    arr = SonarArray(hull_radius=0.5)
    heading = np.array([0.0, 1.0, 0.0])
    s, n = arr.placement(np.array([1.0, 2.0, 3.0]), heading)
    assert s.shape == (9, 3) and n.shape == (9, 3)
    np.testing.assert_allclose(np.linalg.norm(s - [1, 2, 3], axis=1), 0.5)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0)
    np.testing.assert_allclose(n[0], heading)
    np.testing.assert_allclose(n[1:] @ heading, math.cos(arr.ring_angle))
    # the ring is evenly spread: 45 degrees between neighbours around the heading
    ring = n[1:] - np.outer(n[1:] @ heading, heading)
    ring /= np.linalg.norm(ring, axis=1)[:, None]
    np.testing.assert_allclose(
        np.einsum("ij,ij->i", ring, np.roll(ring, -1, axis=0)), math.cos(math.pi / 4), atol=1e-12
    )
    assert ring[0][2] == pytest.approx(1.0)  # S2 is up
    # S1 leads; the others are set back (not in one plane with S1)
    assert np.all((s[1:] - s[0]) @ heading < -1e-3)


def test_scan_sees_a_ball_ahead_with_centre_beam_nearest() -> None:
    arr = SonarArray(hull_radius=0.5, max_range=8.0)
    body = DeformingStar(centre=np.array([5.0, 0, 0]), base_radius=2.0, subdivisions=3)
    scan = sonar_scan(arr, np.zeros(3), np.array([1.0, 0, 0]), body.triangles(0.0))
    assert scan.ranges.shape == (N_SONARS,)
    assert int(np.argmin(scan.ranges)) == 0
    assert scan.ranges[0] == pytest.approx(2.5, abs=1e-2)
    assert np.all(scan.ranges >= scan.ranges[0] - 1e-9)
    assert np.all(scan.echo)  # the ball fills all nine beams
    # true distance hull-to-obstacle never exceeds any reading
    assert np.all(scan.ranges >= 5.0 - 2.0 - 0.5 - 1e-2)
    # a small ball straight ahead is seen by S1 only (the ring beams look 15..55 deg off-axis)
    small = DeformingStar(centre=np.array([5.0, 0, 0]), base_radius=1.0)
    scan = sonar_scan(arr, np.zeros(3), np.array([1.0, 0, 0]), small.triangles(0.0))
    assert scan.echo.tolist() == [True] + [False] * 8


def test_noise_and_dropout_are_seeded_and_bounded() -> None:
    arr = SonarArray(noise_std=0.05, dropout=0.3)
    body = DeformingStar(centre=np.array([4.0, 0, 0]), base_radius=1.5)
    tri = body.triangles(0.0)
    a = sonar_scan(arr, np.zeros(3), np.array([1.0, 0, 0]), tri, np.random.default_rng(7))
    b = sonar_scan(arr, np.zeros(3), np.array([1.0, 0, 0]), tri, np.random.default_rng(7))
    np.testing.assert_array_equal(a.ranges, b.ranges)
    assert np.all((a.ranges >= 0) & (a.ranges <= arr.max_range))
    assert np.all(a.ranges[~a.echo] == arr.max_range)
    with pytest.raises(ValueError, match="Generator"):
        sonar_scan(arr, np.zeros(3), np.array([1.0, 0, 0]), tri)
    drops = [
        (
            ~sonar_scan(arr, np.zeros(3), np.array([1.0, 0, 0]), tri, np.random.default_rng(s)).echo
        ).mean()
        for s in range(40)
    ]
    assert 0.15 < float(np.mean(drops)) < 0.45


def test_adaptive_coefficient_gives_distance_from_s1() -> None:
    arr = SonarArray(hull_radius=0.5)
    r = np.linspace(0.5, 5.0, 9)
    k = adaptive_coefficients(arr, r)
    assert k[0] == pytest.approx(1.0)
    pos, head = np.zeros(3), np.array([0.0, 0.0, 1.0])
    s, n = arr.placement(pos, head)
    echo = s + r[:, None] * n
    np.testing.assert_allclose(k * r, np.linalg.norm(echo - s[0], axis=1))
    np.testing.assert_allclose(adapted_ranges(arr, r), k * r)
    np.testing.assert_allclose(adapted_ranges(arr, np.stack([r, r]))[1], k * r)
    assert np.all(k[1:] > 1.0)  # off-centre sensors sit behind and beside S1


def test_nearest_beam_and_beam_point_round_trip() -> None:
    arr = SonarArray()
    pos, head = np.array([1.0, 1.0, 1.0]), np.array([1.0, 0.0, 0.0])
    for k in range(1, 10):
        p = beam_point(arr, pos, head, k, 3.0)
        assert nearest_beam(arr, pos, head, p) == k
    assert np.allclose(beam_point(arr, pos, head, 42, 1.0), beam_point(arr, pos, head, 9, 1.0))
