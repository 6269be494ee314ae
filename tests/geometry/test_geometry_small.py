"""The pure-Python small-ring kernels agree with the vectorised numpy kernels and with shapely."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.geometry.kernels3d import compiled, numba_available
from uvnav.geometry.polygons import rays_circles_hit, rays_segments_hit
from uvnav.geometry.small import (
    ray_circle_distance,
    ray_polygon_distance,
    segment_polygon_distance,
    segment_ring_distance,
    wrap,
)

coord = st.floats(-5.0, 5.0, allow_nan=False, allow_infinity=False)


@st.composite
def star_polygons(draw: st.DrawFn) -> np.ndarray:
    n = draw(st.integers(3, 9))
    angles = np.sort(
        np.array(draw(st.lists(st.floats(0.0, 2 * math.pi), min_size=n, max_size=n, unique=True)))
    )
    radii = np.array(draw(st.lists(st.floats(0.2, 2.0), min_size=n, max_size=n)))
    cx, cy = draw(coord), draw(coord)
    pts = np.stack([cx + radii * np.cos(angles), cy + radii * np.sin(angles)], axis=-1)
    return pts


@settings(max_examples=150, deadline=None)
@given(ring=star_polygons(), ax=coord, ay=coord, bx=coord, by=coord)
def test_segment_polygon_distance_matches_shapely(
    ring: np.ndarray, ax: float, ay: float, bx: float, by: float
) -> None:
    poly = shapely.Polygon(ring)
    if not poly.is_valid or poly.area < 1e-3:
        return
    seg = (
        shapely.LineString([(ax, ay), (bx, by)]) if (ax, ay) != (bx, by) else shapely.Point(ax, ay)
    )
    expected = shapely.distance(seg, poly.exterior)
    assert abs(segment_polygon_distance((ax, ay), (bx, by), ring.tolist()) - expected) < 1e-7


@pytest.mark.skipif(not numba_available(), reason="needs numba (the fast extra)")
@settings(max_examples=150, deadline=None)
@given(ring=star_polygons(), ax=coord, ay=coord, bx=coord, by=coord)
def test_compiled_segment_ring_distance_is_segment_polygon_distance(
    ring: np.ndarray, ax: float, ay: float, bx: float, by: float
) -> None:
    """The compiled copy (pyhypot for math.hypot) gives the Python function's numbers exactly,
    also from a vertex."""
    want = segment_polygon_distance((ax, ay), (bx, by), ring.tolist())
    with compiled(True):
        assert segment_ring_distance(ax, ay, bx, by, ring) == want
        vx, vy = float(ring[0, 0]), float(ring[0, 1])
        at_vertex = segment_ring_distance(vx, vy, bx, by, ring)
    assert at_vertex == segment_polygon_distance((vx, vy), (bx, by), ring.tolist())
    with compiled(False):
        assert segment_ring_distance(ax, ay, bx, by, ring) == want


@settings(max_examples=150, deadline=None)
@given(ring=star_polygons(), ox=coord, oy=coord, angle=st.floats(-math.pi, math.pi))
def test_ray_polygon_distance_matches_the_vectorised_kernel(
    ring: np.ndarray, ox: float, oy: float, angle: float
) -> None:
    direction = np.array([[math.cos(angle), math.sin(angle)]])
    expected = float(
        rays_segments_hit(np.array([ox, oy]), direction, ring, np.roll(ring, -1, axis=0)).min()
    )
    got = ray_polygon_distance(ox, oy, angle, ring.tolist())
    assert (math.isinf(got) and math.isinf(expected)) or abs(got - expected) < 1e-9


@settings(max_examples=150, deadline=None)
@given(
    ox=coord,
    oy=coord,
    angle=st.floats(-math.pi, math.pi),
    cx=coord,
    cy=coord,
    r=st.floats(0.0, 3.0),
)
def test_ray_circle_distance_matches_the_vectorised_kernel(
    ox: float, oy: float, angle: float, cx: float, cy: float, r: float
) -> None:
    direction = np.array([[math.cos(angle), math.sin(angle)]])
    expected = float(
        rays_circles_hit(np.array([ox, oy]), direction, np.array([[cx, cy]]), np.array([r]))[0, 0]
    )
    got = ray_circle_distance(ox, oy, angle, cx, cy, r)
    assert (math.isinf(got) and math.isinf(expected)) or abs(got - expected) < 1e-7


@given(st.floats(-100.0, 100.0))
def test_wrap_range_and_congruence(a: float) -> None:
    w = wrap(a)
    assert -math.pi < w <= math.pi
    assert abs(math.remainder(w - a, 2 * math.pi)) < 1e-9
