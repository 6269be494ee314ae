"""Property tests for the edge-soup kernels of :mod:`uvnav.geometry.polygons`, against shapely 2."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from shapely.geometry import LineString, Point, Polygon

from uvnav.geometry.kernels3d import compiled, numba_available
from uvnav.geometry.polygons import (
    angular_extent,
    closed_rings,
    edge_soup,
    nearest_on_polygons,
    points_to_segment,
    points_to_segments,
    polygon_area,
    polygon_centroid,
    polygon_nearest,
    polygons_gap,
    ray_polygon_hit,
    rays_circles_hit,
    rays_rings_hit,
    rays_segments_hit,
    ring_perp,
    rings_nearest,
    segment_intersects_polygon,
    segments_min_distance,
    transform_points,
    transform_rings,
)

small = st.floats(min_value=-4.0, max_value=4.0, allow_nan=False, allow_infinity=False)
heading = st.floats(min_value=-math.pi, max_value=math.pi, allow_nan=False)
SETTINGS = settings(max_examples=120, deadline=None)


@st.composite
def star_polygons(draw: st.DrawFn, max_n: int = 12) -> np.ndarray:
    """Random simple (generally non-convex) polygons: star-shaped about a random centre.

    Vertices at strictly increasing angles with random radii; either orientation.
    """
    n = draw(st.integers(3, max_n))
    gaps = np.array(draw(st.lists(st.floats(0.2, 1.0), min_size=n, max_size=n)))
    radii = np.array(draw(st.lists(st.floats(0.2, 2.5), min_size=n, max_size=n)))
    centre = np.array([draw(st.floats(-1.0, 1.0)), draw(st.floats(-1.0, 1.0))])
    rot = draw(heading)
    ang = rot + 2.0 * math.pi * np.concatenate([[0.0], np.cumsum(gaps)[:-1]]) / gaps.sum()
    verts = centre + radii[:, None] * np.stack([np.cos(ang), np.sin(ang)], axis=-1)
    if draw(st.booleans()):
        verts = verts[::-1].copy()
    poly = Polygon(verts)
    assume(poly.is_valid and poly.area > 1e-3)
    return verts


def _point_far_from_boundary(poly: Polygon, p: np.ndarray, tol: float = 1e-7) -> bool:
    return poly.exterior.distance(Point(p)) > tol


@SETTINGS
@given(star_polygons(), small, small)
def test_polygon_nearest_matches_shapely(verts: np.ndarray, x: float, y: float) -> None:
    p = np.array([x, y])
    poly = Polygon(verts)
    assume(_point_far_from_boundary(poly, p))
    d, nearest, inside = polygon_nearest(p, verts)
    assert d == pytest.approx(poly.exterior.distance(Point(p)), abs=1e-9)
    assert inside == poly.contains(Point(p))
    assert poly.exterior.distance(Point(nearest)) < 1e-9
    assert float(np.hypot(*(nearest - p))) == pytest.approx(d, abs=1e-9)


@SETTINGS
@given(st.lists(star_polygons(max_n=8), min_size=1, max_size=4), small, small)
def test_nearest_on_polygons_matches_shapely_per_polygon(
    polys: list[np.ndarray], x: float, y: float
) -> None:
    p = np.array([x, y])
    shp = [Polygon(v) for v in polys]
    assume(all(_point_far_from_boundary(s, p) for s in shp))
    starts, ends, offsets = edge_soup(polys)
    d, nearest, inside = nearest_on_polygons(p, starts, ends, offsets)
    assert d.shape == (len(polys),) and nearest.shape == (len(polys), 2)
    for j, s in enumerate(shp):
        assert d[j] == pytest.approx(s.exterior.distance(Point(p)), abs=1e-9)
        assert bool(inside[j]) == s.contains(Point(p))
        # the nearest point belongs to polygon j's own boundary
        assert s.exterior.distance(Point(nearest[j])) < 1e-9


def test_nearest_on_polygons_empty_soup() -> None:
    s, e, o = edge_soup([])
    d, n, ins = nearest_on_polygons(np.zeros(2), s, e, o)
    assert d.shape == (0,) and n.shape == (0, 2) and ins.shape == (0,)


@SETTINGS
@given(star_polygons(), small, small, heading)
def test_ray_hit_is_first_boundary_crossing(
    verts: np.ndarray, x: float, y: float, angle: float
) -> None:
    o = np.array([x, y])
    poly = Polygon(verts)
    assume(_point_far_from_boundary(poly, o))
    t, hit = ray_polygon_hit(o, angle, verts)
    far = o + 100.0 * np.array([math.cos(angle), math.sin(angle)])
    crossing = LineString([o, far]).intersection(poly.exterior)
    if crossing.is_empty:
        assert t == math.inf and hit is None
        return
    pts = shapely.get_coordinates(crossing)
    t_ref = float(np.min(np.hypot(*(pts - o).T)))
    assert hit is not None
    assert poly.exterior.distance(Point(hit)) < 1e-9
    assert t == pytest.approx(t_ref, abs=1e-9)
    assert float(np.hypot(*(hit - o))) == pytest.approx(t, abs=1e-9)


@SETTINGS
@given(star_polygons(), small, small, st.integers(1, 16))
def test_rays_segments_hit_matrix_consistent_with_single_rays(
    verts: np.ndarray, x: float, y: float, n_rays: int
) -> None:
    o = np.array([x, y])
    ang = np.linspace(-math.pi, math.pi, n_rays, endpoint=False) + 0.123
    dirs = np.stack([np.cos(ang), np.sin(ang)], axis=-1)
    s, e, _ = edge_soup([verts])
    t = rays_segments_hit(o, dirs, s, e)
    assert t.shape == (n_rays, len(verts))
    assert np.all((t >= 0) | np.isinf(t))
    for r in range(n_rays):
        assert t[r].min() == ray_polygon_hit(o, float(ang[r]), verts)[0]
        # every finite entry is a point on the corresponding edge
        for k in np.nonzero(np.isfinite(t[r]))[0]:
            q = o + t[r, k] * dirs[r]
            assert LineString([s[k], e[k]]).distance(Point(q)) < 1e-9


def test_parallel_ray_never_hits_its_edge() -> None:
    s = np.array([[0.0, 1.0]])
    e = np.array([[5.0, 1.0]])
    t = rays_segments_hit(np.zeros(2), np.array([[1.0, 0.0]]), s, e)
    assert t[0, 0] == math.inf


@SETTINGS
@given(star_polygons())
def test_centroid_and_area_match_shapely(verts: np.ndarray) -> None:
    poly = Polygon(verts)
    c = polygon_centroid(verts)
    ref = poly.centroid
    assert c == pytest.approx([ref.x, ref.y], abs=1e-9)
    a = polygon_area(verts)
    assert abs(a) == pytest.approx(poly.area, rel=1e-12)
    assert (a > 0) == poly.exterior.is_ccw


def test_centroid_of_degenerate_polygon_is_vertex_mean() -> None:
    verts = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]])
    assert polygon_centroid(verts) == pytest.approx([1.0, 1.0])


@settings(max_examples=200, deadline=None)
@given(small, small, heading, small, small, st.floats(0.0, 3.0))
def test_rays_circles_hit_analytic(
    ox: float, oy: float, a: float, cx: float, cy: float, r: float
) -> None:
    o, c = np.array([ox, oy]), np.array([cx, cy])
    u = np.array([math.cos(a), math.sin(a)])
    t = float(rays_circles_hit(o, u[None], c[None], np.array([r]))[0, 0])
    # roots of |o + t u - c|^2 = r^2 with a numerically independent solver
    m = o - c
    roots = np.roots([1.0, 2.0 * float(u @ m), float(m @ m) - r * r])
    real = [float(z.real) for z in roots if abs(z.imag) < 1e-9 and z.real >= -1e-12]
    dist_line = abs(u[0] * (c - o)[1] - u[1] * (c - o)[0])
    if abs(dist_line - r) < 1e-6:  # grazing: hit or miss are both acceptable within rounding
        return
    if abs(float(np.hypot(*m)) - r) < 1e-9:  # starting on the rim: 0 or the far side, both fine
        return
    if not real:
        assert t == math.inf
        return
    assert t == pytest.approx(max(0.0, min(real)), abs=1e-7)
    q = o + t * u
    assert float(np.hypot(*(q - c))) == pytest.approx(r, abs=1e-7)


def test_rays_circles_hit_from_inside_exits() -> None:
    t = rays_circles_hit(
        np.zeros(2), np.array([[1.0, 0.0], [0.0, -1.0]]), np.array([[0.5, 0.0]]), np.array([1.0])
    )
    assert t[:, 0] == pytest.approx([1.5, math.sqrt(0.75)])


def test_rays_circles_hit_shape_and_misses() -> None:
    dirs = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0]])
    centres = np.array([[3.0, 0.0], [0.0, 10.0]])
    t = rays_circles_hit(np.zeros(2), dirs, centres, np.array([1.0, 2.0]))
    assert t.shape == (3, 2)
    assert t[0, 0] == pytest.approx(2.0)
    assert t[1, 0] == math.inf  # circle behind the ray
    assert t[2, 1] == pytest.approx(8.0)
    assert t[0, 1] == math.inf


@SETTINGS
@given(star_polygons(), small, small, small, small, st.floats(0.0, 0.5))
def test_segment_queries_match_shapely(
    verts: np.ndarray, ax: float, ay: float, bx: float, by: float, margin: float
) -> None:
    a, b = np.array([ax, ay]), np.array([bx, by])
    assume(np.hypot(*(b - a)) > 1e-6)
    poly = Polygon(verts)
    seg = LineString([a, b])
    s, e, _ = edge_soup([verts])
    d_ref = seg.distance(poly.exterior)
    assume(abs(d_ref - margin) > 1e-7 and (d_ref > 1e-7 or seg.crosses(poly.exterior)))
    assert segments_min_distance(a, b, s, e) == pytest.approx(d_ref, abs=1e-9)
    assert segment_intersects_polygon(a, b, verts, margin=margin) == (seg.distance(poly) <= margin)


@SETTINGS
@given(star_polygons(), st.floats(6.0, 30.0), heading)
def test_angular_extent_bounds_whole_boundary(
    verts: np.ndarray, dist: float, bearing: float
) -> None:
    p = dist * np.array([math.cos(bearing), math.sin(bearing)])
    c = polygon_centroid(verts)
    ref = math.atan2(*(c - p)[::-1])
    lo, hi = angular_extent(p, verts, ref)
    assert -math.pi / 2 < lo <= hi < math.pi / 2
    # every boundary point (dense along edges) is inside the cone
    s = np.linspace(0, 1, 20)[:, None, None]
    pts = (verts[None] + s * (np.roll(verts, -1, axis=0) - verts)[None]).reshape(-1, 2)
    rel = np.arctan2(pts[:, 1] - p[1], pts[:, 0] - p[0]) - ref
    rel = np.array([math.remainder(v, 2 * math.pi) for v in rel])
    assert np.all(rel >= lo - 1e-12) and np.all(rel <= hi + 1e-12)
    # the silhouette rays graze: they touch the polygon, rays slightly outside miss it
    poly = Polygon(verts)
    for edge_angle, outward in ((lo, -1e-6), (hi, 1e-6)):
        for delta, touches in ((0.0, True), (outward, False)):
            a = ref + edge_angle + delta
            ray = LineString([p, p + 100.0 * np.array([math.cos(a), math.sin(a)])])
            assert (ray.distance(poly) < 1e-9) == touches


@SETTINGS
@given(star_polygons(), small, small, heading)
def test_transform_points_is_rigid_rotation_then_translation(
    verts: np.ndarray, x: float, y: float, th: float
) -> None:
    out = transform_points(verts, np.array([x, y]), th)
    ref = shapely.affinity.translate(
        shapely.affinity.rotate(Polygon(verts), th, origin=(0, 0), use_radians=True), x, y
    )
    assert np.allclose(out, np.asarray(ref.exterior.coords)[:-1], atol=1e-12)


# ------------------------------------------------------------------ padded closed rings


@SETTINGS
@given(st.lists(star_polygons(max_n=9), min_size=1, max_size=5), small, small, heading)
def test_ring_kernels_equal_edge_soup_kernels_bit_for_bit(
    polys: list[np.ndarray], x: float, y: float, angle: float
) -> None:
    """Packing polygons into padded rings changes no number: nearest points, containment and ray
    hits are those of the edge-soup kernels (themselves checked against shapely above)."""
    p = np.array([x, y])
    rings, counts = closed_rings(polys)
    assert rings.shape == (2, len(polys), max(len(v) for v in polys) + 1)
    assert counts.tolist() == [len(v) for v in polys]
    starts, ends, offsets = edge_soup(polys)
    d0, n0, in0 = nearest_on_polygons(p, starts, ends, offsets)
    d1, n1, in1 = rings_nearest(p, rings)
    assert np.array_equal(d0, d1) and np.array_equal(n0, n1.T) and np.array_equal(in0, in1)
    d2, n2, in2 = rings_nearest((x, y), rings, parity=False)
    assert np.array_equal(d1, d2) and np.array_equal(n1, n2) and in2 is None
    dirs = np.array([[math.cos(angle + a), math.sin(angle + a)] for a in (0.0, 1.0, 2.5, -2.0)])
    soup_hits = np.minimum.reduceat(rays_segments_hit(p, dirs, starts, ends), offsets[:-1], axis=1)
    assert np.array_equal(soup_hits, rays_rings_hit(p, dirs, rings))


@pytest.mark.skipif(not numba_available(), reason="needs numba (the fast extra)")
@SETTINGS
@given(st.lists(star_polygons(max_n=9), min_size=1, max_size=6), small, small,
       st.sampled_from([None, 0, 1]))  # fmt: skip
def test_compiled_rings_nearest_equals_the_array_version_bit_for_bit(
    polys: list[np.ndarray], x: float, y: float, on_vertex: int | None
) -> None:
    """The compiled loop of :func:`rings_nearest` gives the array version's numbers exactly, also
    on a vertex and with the zero-length edges of the padding."""
    rings, _ = closed_rings(polys)
    p = (x, y) if on_vertex is None else tuple(polys[0][on_vertex])
    with compiled(False):
        ref = [rings_nearest(p, rings, parity=par) for par in (True, False)]
    with compiled(True):
        got = [rings_nearest(p, rings, parity=par) for par in (True, False)]
    for (d0, n0, i0), (d1, n1, i1) in zip(ref, got, strict=True):
        assert np.array_equal(d0, d1) and np.array_equal(n0, n1)
        assert (i0 is None and i1 is None) or np.array_equal(i0, i1)


@pytest.mark.skipif(not numba_available(), reason="needs numba (the fast extra)")
@SETTINGS
@given(star_polygons(max_n=9), star_polygons(max_n=9), small, small)
def test_compiled_polygons_gap_equals_the_array_version_bit_for_bit(
    a: np.ndarray, b: np.ndarray, dx: float, dy: float
) -> None:
    """The compiled loops of :func:`polygons_gap` give the arrays' numbers exactly (also for a
    shared vertex), and for disjoint polygons the boundaries' distance."""
    for other in (b + np.array((dx, dy)), np.concatenate([a[:1], b[1:]])):
        with compiled(False):
            ref = polygons_gap(a, other)
        with compiled(True):
            got = polygons_gap(a, other)
        assert got == ref
    pa, pb = Polygon(a), Polygon(b + np.array((dx, dy)))
    if not pa.intersects(pb):
        want = pa.exterior.distance(pb.exterior)
        assert polygons_gap(a, b + np.array((dx, dy))) == pytest.approx(want, abs=1e-9)


@SETTINGS
@given(
    st.lists(star_polygons(max_n=9), min_size=1, max_size=4),
    st.lists(st.tuples(small, small, heading), min_size=4, max_size=4),
)
def test_transform_rings_equals_transform_points(
    polys: list[np.ndarray], poses: list[tuple[float, float, float]]
) -> None:
    rings, counts = closed_rings(polys)
    poses = poses[: len(polys)]
    centres = np.array([[px, py] for px, py, _ in poses])
    headings = np.array([h for _, _, h in poses])
    world = transform_rings(rings, centres, headings)
    assert np.array_equal(world, transform_rings(rings, centres, headings, perp=ring_perp(rings)))
    for i, (v, n) in enumerate(zip(polys, counts.tolist(), strict=True)):
        expect = transform_points(v, centres[i], float(headings[i]))
        assert np.array_equal(world[:, i, :n].T, expect)
        # the padding repeats the first vertex
        assert np.array_equal(world[:, i, n:], np.repeat(expect[0][:, None], world.shape[2] - n, 1))


def test_closed_rings_empty() -> None:
    rings, counts = closed_rings([])
    assert rings.shape == (2, 0, 1) and counts.shape == (0,)


@given(
    pts=st.lists(st.tuples(small, small), min_size=1, max_size=12),
    a=st.tuples(small, small),
    b=st.tuples(small, small),
)
def test_points_to_one_segment_is_the_general_distance(
    pts: list[tuple[float, float]], a: tuple[float, float], b: tuple[float, float]
) -> None:
    """The one-segment helper equals :func:`points_to_segments` (a degenerate segment included)
    and shapely's point-to-line distance."""
    p = np.array(pts)
    got = points_to_segment(p, a, b)
    ref = points_to_segments(p, np.broadcast_to(a, p.shape), np.broadcast_to(b, p.shape))
    assert np.allclose(got, ref, atol=1e-9)
    # shapely measures a subnormal-length line as infinitely far: take such a segment as a point
    line = LineString([a, b]) if math.dist(a, b) > 1e-6 else Point(a)
    assert np.allclose(got, [line.distance(Point(q)) for q in pts], atol=2e-6)
