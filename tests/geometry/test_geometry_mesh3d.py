"""Triangle kernels: exact nearest points, Möller–Trumbore, winding numbers, mesh validation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from uvnav.geometry.mesh3d import (
    MeshError,
    PseudoNormals,
    Triangles,
    box_mesh,
    closest_barycentric,
    closest_barycentric_scalar,
    closest_points_on_triangles,
    contains_points,
    icosphere,
    mesh_volume_centroid,
    nearest_on_mesh,
    ray_cast,
    signed_nearest,
    validate_mesh,
)

coord = st.floats(-5.0, 5.0, allow_nan=False)
point = st.tuples(coord, coord, coord).map(np.array)


def _area(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
    return float(np.linalg.norm(np.cross(b - a, c - a)))


@settings(max_examples=200, deadline=None)
@given(a=point, b=point, c=point, p=point)
def test_nearest_point_lies_on_the_triangle_and_is_optimal(
    a: np.ndarray, b: np.ndarray, c: np.ndarray, p: np.ndarray
) -> None:
    assume(_area(a, b, c) > 1e-3)
    tri = Triangles.from_corners(a[None], b[None], c[None])
    q, d2 = closest_points_on_triangles(p, tri)
    q = q[0]
    # q is in the triangle: barycentric weights >= 0
    m = np.stack([b - a, c - a], axis=1)
    vw, *_ = np.linalg.lstsq(m, q - a, rcond=None)
    assert vw.min() >= -1e-7 and vw.sum() <= 1 + 1e-7
    assert np.allclose(a + m @ vw, q, atol=1e-7)
    # optimality (projection onto a convex set): (p - q) . (x - q) <= 0 for every x in it
    rng = np.random.default_rng(0)
    w = rng.dirichlet(np.ones(3), 300)
    xs = w[:, :1] * a + w[:, 1:2] * b + w[:, 2:] * c
    assert np.all((xs - q) @ (p - q) <= 1e-7 * (1 + np.abs(p).max() ** 2))
    assert np.sqrt(d2[0]) <= np.linalg.norm(xs - p, axis=1).min() + 1e-9
    # the scalar form of the kernel gives the same weights
    v, w = closest_barycentric(p, tri)
    vs, ws = closest_barycentric_scalar(tuple(p), tuple(a), tuple(b - a), tuple(c - a))
    assert (vs, ws) == pytest.approx((float(v[0]), float(w[0])), abs=1e-9)


def _box_signed(p: np.ndarray, h: np.ndarray) -> float:
    q = np.abs(p) - h
    return float(np.linalg.norm(np.maximum(q, 0.0)) + min(q.max(), 0.0))


@settings(max_examples=200, deadline=None)
@given(p=point, hx=st.floats(0.2, 3), hy=st.floats(0.2, 3), hz=st.floats(0.2, 3))
def test_signed_distance_to_a_box_mesh_is_exact(
    p: np.ndarray, hx: float, hy: float, hz: float
) -> None:
    h = np.array([hx, hy, hz])
    v, f = box_mesh(h)
    tri = Triangles.from_mesh(v, f)
    q, d, _ = signed_nearest(p, tri, PseudoNormals.from_mesh(v, f))
    assert d == pytest.approx(_box_signed(p, h), abs=1e-9)
    assert abs(_box_signed(q, h)) < 1e-9  # on the surface
    assert bool(contains_points(p[None], tri)[0]) == (_box_signed(p, h) < 0) or abs(d) < 1e-9


@settings(max_examples=200, deadline=None)
@given(o=point, d=point, a=point, b=point, c=point)
def test_ray_hits_are_on_the_triangle_and_misses_are_real(
    o: np.ndarray, d: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray
) -> None:
    assume(_area(a, b, c) > 1e-2 and np.linalg.norm(d) > 1e-2)
    tri = Triangles.from_corners(a[None], b[None], c[None])
    t, j = ray_cast(o, d, tri)
    n = np.cross(b - a, c - a)
    denom = float(d @ n)
    if np.isfinite(t[0]):
        hit = o + t[0] * d
        _, d2 = closest_points_on_triangles(hit, tri)
        assert np.sqrt(d2[0]) < 1e-6 * (1 + np.abs(hit).max())
        assert j[0] == 0 and t[0] >= 0
    elif abs(denom) > 1e-3 * np.linalg.norm(n) * np.linalg.norm(d):
        # the ray meets the plane at s; if s >= 0 the point must be outside the triangle
        s = float((a - o) @ n) / denom
        if s >= 0:
            _, d2 = closest_points_on_triangles(o + s * d, tri)
            assert d2[0] > 0


def test_icosphere_winding_and_volume() -> None:
    v, f = icosphere(2)
    assert len(f) == 320
    v, f = validate_mesh(v, f)
    vol, centroid = mesh_volume_centroid(v, f)
    assert 0.95 * 4 / 3 * np.pi < vol < 4 / 3 * np.pi
    assert np.allclose(centroid, 0.0, atol=1e-12)
    tri = Triangles.from_mesh(v, f)
    pts = np.random.default_rng(1).uniform(-1.5, 1.5, (400, 3))
    r = np.linalg.norm(pts, axis=1)
    inside = contains_points(pts, tri)
    assert np.all(inside[r < 0.9]) and not np.any(inside[r > 1.0])
    _, dist, _ = nearest_on_mesh(np.array([3.0, 0.0, 0.0]), tri)
    assert 2.0 <= dist <= 2.1


def test_validate_mesh_rejects_bad_meshes_with_clear_errors() -> None:
    v, f = box_mesh([1, 1, 1])
    with pytest.raises(MeshError, match="not closed"):
        validate_mesh(v, f[:-1])
    bad = f.copy()
    bad[0] = [0, 0, 1]
    with pytest.raises(MeshError, match="degenerate"):
        validate_mesh(v, bad)
    flipped = f.copy()
    flipped[0] = flipped[0][::-1]
    with pytest.raises(MeshError, match="oriented"):
        validate_mesh(v, flipped)
    with pytest.raises(MeshError, match="out of range"):
        validate_mesh(v, f + 100)
    with pytest.raises(MeshError, match="finite"):
        validate_mesh(np.full((8, 3), np.nan), f)
    # an inward-oriented mesh is flipped, not rejected
    _, out = validate_mesh(v, f[:, ::-1])
    assert mesh_volume_centroid(v, out)[0] > 0
