"""ObstacleField: the vectorised world snapshot, checked against shapely (discs + polygons)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from shapely.geometry import LineString, Point, Polygon

from uvnav.geometry.polygons import transform_points
from uvnav.obstacles import (
    ConstantVelocity,
    DiscBody,
    FieldTemplate,
    Obstacle,
    ObstacleField,
    ObstacleState,
    PolygonBody,
)


def _star(rng: np.random.Generator, n: int, r_lo: float = 0.3, r_hi: float = 1.5) -> np.ndarray:
    """Random simple, generally non-convex polygon (star-shaped about the origin)."""
    gaps = rng.uniform(0.3, 1.0, n)
    ang = 2.0 * math.pi * np.concatenate([[0.0], np.cumsum(gaps)[:-1]]) / gaps.sum()
    r = rng.uniform(r_lo, r_hi, n)
    return r[:, None] * np.stack([np.cos(ang), np.sin(ang)], axis=-1)


def _world(seed: int, k: int) -> list[Obstacle]:
    rng = np.random.default_rng(seed)
    obs = []
    for j in range(k):
        body = (
            DiscBody(float(rng.uniform(0.2, 1.0)))
            if rng.random() < 0.4
            else PolygonBody.from_vertices(_star(rng, int(rng.integers(3, 10))))
        )
        state = ObstacleState(
            position=rng.uniform(-6, 6, 2),
            heading=float(rng.uniform(-math.pi, math.pi)),
            velocity=rng.normal(size=2),
            angular_velocity=float(rng.normal()),
        )
        obs.append(
            Obstacle(
                body, state, ConstantVelocity(state.velocity, state.angular_velocity), name=f"o{j}"
            )
        )
    return obs


def _shapes(obstacles: list[Obstacle]) -> list[tuple[str, object]]:
    out: list[tuple[str, object]] = []
    for o in obstacles:
        if isinstance(o.body, DiscBody):
            out.append(("disc", (o.state.position, o.body.radius)))
        else:
            out.append(
                (
                    "poly",
                    Polygon(transform_points(o.body.vertices, o.state.position, o.state.heading)),
                )
            )
    return out


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 8), st.floats(-8, 8), st.floats(-8, 8))
def test_nearest_matches_shapely_and_analytic(seed: int, k: int, x: float, y: float) -> None:
    obstacles = _world(seed, k)
    fld = ObstacleField.from_obstacles(obstacles)
    p = np.array([x, y])
    shapes = _shapes(obstacles)
    for kind, shp in shapes:
        if kind == "poly":
            assume(shp.exterior.distance(Point(p)) > 1e-7)  # type: ignore[attr-defined]
        else:
            c, r = shp  # type: ignore[misc]
            assume(abs(np.hypot(*(p - c)) - r) > 1e-7)
    dist, near, inside = fld.nearest(p)
    assert dist.shape == (k,) and near.shape == (k, 2) and inside.shape == (k,)
    for j, (kind, shp) in enumerate(shapes):
        if kind == "poly":
            ins = shp.contains(Point(p))  # type: ignore[attr-defined]
            assert bool(inside[j]) == ins
            assert dist[j] == pytest.approx(
                0.0 if ins else shp.exterior.distance(Point(p)), abs=1e-9
            )  # type: ignore[attr-defined]
            assert shp.exterior.distance(Point(near[j])) < 1e-9  # type: ignore[attr-defined]
        else:
            c, r = shp  # type: ignore[misc]
            gap = float(np.hypot(*(p - c))) - r
            assert bool(inside[j]) == (gap < 0)
            assert dist[j] == pytest.approx(max(gap, 0.0), abs=1e-12)
            assert float(np.hypot(*(near[j] - c))) == pytest.approx(r, abs=1e-12)
            # the nearest boundary point is on the ray from the centre through p
            if np.hypot(*(p - c)) > 1e-9:
                assert abs(abs(gap) - float(np.hypot(*(near[j] - p)))) < 1e-9


def test_nearest_point_at_disc_centre_is_finite() -> None:
    ob = Obstacle(
        DiscBody(1.0), ObstacleState(position=np.array([2.0, 3.0])), ConstantVelocity(np.zeros(2))
    )
    dist, near, inside = ObstacleField.from_obstacles([ob]).nearest(np.array([2.0, 3.0]))
    assert dist[0] == 0.0 and bool(inside[0])
    assert np.all(np.isfinite(near)) and float(np.hypot(*(near[0] - [2.0, 3.0]))) == pytest.approx(
        1.0
    )


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 8), st.floats(-8, 8), st.floats(-8, 8))
def test_ray_hits_match_shapely_and_analytic(seed: int, k: int, x: float, y: float) -> None:
    obstacles = _world(seed, k)
    fld = ObstacleField.from_obstacles(obstacles)
    o = np.array([x, y])
    ang = np.linspace(-math.pi, math.pi, 24, endpoint=False) + 0.0137
    dirs = np.stack([np.cos(ang), np.sin(ang)], axis=-1)
    hits = fld.ray_hits(o, dirs)
    assert hits.shape == (24, k)
    for j, (kind, shp) in enumerate(_shapes(obstacles)):
        for r in range(24):
            far = o + 100.0 * dirs[r]
            if kind == "poly":
                assume(shp.exterior.distance(Point(o)) > 1e-7)  # type: ignore[attr-defined]
                inter = LineString([o, far]).intersection(shp.exterior)  # type: ignore[attr-defined]
                if inter.is_empty:
                    assert hits[r, j] == math.inf
                else:
                    pts = shapely.get_coordinates(inter)
                    assert hits[r, j] == pytest.approx(
                        float(np.min(np.hypot(*(pts - o).T))), abs=1e-9
                    )
            else:
                c, rad = shp  # type: ignore[misc]
                m = c - o
                b = float(dirs[r] @ m)
                disc = b * b - (float(m @ m) - rad * rad)
                if disc < -1e-9 or (b + math.sqrt(max(disc, 0.0))) < 0:
                    assert hits[r, j] == math.inf
                elif disc > 1e-9:
                    t = b - math.sqrt(disc) if b - math.sqrt(disc) >= 0 else b + math.sqrt(disc)
                    assert hits[r, j] == pytest.approx(t, abs=1e-9)


def test_template_and_direct_snapshot_agree() -> None:
    obstacles = _world(11, 7)
    tpl = FieldTemplate.from_bodies([o.body for o in obstacles])
    a = ObstacleField.from_obstacles(obstacles, tpl)
    b = ObstacleField.from_obstacles(obstacles)
    for name in (
        "centres",
        "velocities",
        "angular_velocities",
        "headings",
        "radii",
        "bounding_radii",
    ):
        assert np.array_equal(getattr(a, name), getattr(b, name))
    for o, pa, pb in zip(obstacles, a.polygons, b.polygons, strict=True):
        if isinstance(o.body, DiscBody):
            assert pa is None and pb is None
        else:
            assert pa is not None and pb is not None
            assert np.array_equal(pa, pb)
            assert np.allclose(
                pa, transform_points(o.body.vertices, o.state.position, o.state.heading), atol=1e-12
            )
    assert np.array_equal(a.is_disc, [isinstance(o.body, DiscBody) for o in obstacles])


def test_empty_field() -> None:
    fld = ObstacleField.from_obstacles([])
    assert len(fld) == 0
    d, n, ins = fld.nearest(np.zeros(2))
    assert d.shape == (0,) and n.shape == (0, 2) and ins.shape == (0,)
    assert fld.ray_hits(np.zeros(2), np.array([[1.0, 0.0]])).shape == (1, 0)


def test_field_follows_obstacle_motion() -> None:
    """Rebuilding from a moved obstacle moves and rotates its outline rigidly."""
    body = PolygonBody.from_vertices(
        np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 0.3], [0.0, 1.0]])
    )
    ob = Obstacle(
        body, ObstacleState(position=np.zeros(2)), ConstantVelocity(np.array([1.0, 0.0]), 0.5)
    )
    tpl = FieldTemplate.from_bodies([body])
    for i in range(10):
        ob.state = ob.motion.step(ob.state, i * 0.1, 0.1)
    fld = ObstacleField.from_obstacles([ob], tpl)
    expect = transform_points(body.vertices, np.array([1.0, 0.0]), 0.5)
    assert fld.polygons[0] == pytest.approx(expect, abs=1e-12)
    assert Polygon(fld.polygons[0]).area == pytest.approx(Polygon(body.vertices).area)


def _polygon_world(seed: int, k: int) -> list[Obstacle]:
    """Polygons only (the query's fast path)."""
    rng = np.random.default_rng(seed)
    return [
        Obstacle(
            PolygonBody.from_vertices(_star(rng, int(rng.integers(3, 10)))),
            ObstacleState(position=rng.uniform(-12, 12, 2), heading=float(rng.uniform(-4, 4))),
            ConstantVelocity(np.zeros(2)),
        )
        for _ in range(k)
    ]


@settings(max_examples=80, deadline=None)
@given(
    st.integers(0, 2**32 - 1),
    st.integers(1, 30),
    st.booleans(),
    st.floats(-14, 14),
    st.floats(-14, 14),
    st.sampled_from([0.0, 0.5, 2.0, 5.0, math.inf]),
    st.booleans(),
)
def test_culled_query_equals_unculled(
    seed: int, k: int, polygons_only: bool, x: float, y: float, radius: float, with_nearest: bool
) -> None:
    """The bounding-disc cull changes nothing: same numbers for what it keeps, and what it drops
    is farther than the radius (and than the nearest obstacle)."""
    obstacles = _polygon_world(seed, k) if polygons_only else _world(seed, k)
    fld = ObstacleField.from_obstacles(obstacles)
    p = np.array([x, y])
    dist, near, inside = ObstacleField.from_obstacles(obstacles).nearest(p)  # unculled
    q = fld.query(p, radius, nearest=with_nearest)
    ids = q.ids
    assert np.all(np.diff(ids) > 0)
    assert np.array_equal(q.distance, dist[ids])
    assert np.array_equal(q.nearest, near[ids])
    assert np.array_equal(q.inside, inside[ids])
    dropped = np.setdiff1d(np.arange(k), ids)
    assert np.all(dist[dropped] > radius)
    # the signed distance orders obstacles like the simulator's clearance
    depth = np.hypot(near[:, 0] - x, near[:, 1] - y)
    signed = np.where(inside, -depth, dist)
    assert np.array_equal(q.signed, signed[ids])
    if with_nearest:
        assert len(ids) >= 1
        assert int(ids[np.argmin(q.signed)]) == int(np.argmin(signed))
        assert np.all(signed[dropped] > signed.min())
    for i, j in enumerate(ids.tolist()):
        outline = q.outline(i)
        if fld.polygons[j] is None:
            assert outline is None
        else:
            assert outline is not None and np.array_equal(outline, fld.polygons[j])


def test_query_keeps_its_last_answer() -> None:
    fld = ObstacleField.from_obstacles(_world(3, 6))
    p = np.array([0.5, -0.25])
    q = fld.query(p, 3.0, nearest=True)
    assert fld.query(p, 2.0, nearest=False) is q  # no more than asked before: cached
    assert fld.query((0.5, -0.25), 3.0) is q
    assert fld.query(p, 4.0) is not q  # a larger radius is a new question
    assert fld.query(p + 1e-9, 1.0) is not fld.query(p, 1.0)


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 12), st.floats(0.5, 6.0))
def test_ray_hits_cull_keeps_every_hit_within_range(seed: int, k: int, max_range: float) -> None:
    obstacles = _world(seed, k)
    fld = ObstacleField.from_obstacles(obstacles)
    o = np.array([0.3, -0.2])
    ang = np.linspace(-math.pi, math.pi, 36, endpoint=False)
    dirs = np.stack([np.cos(ang), np.sin(ang)], axis=-1)
    full = fld.ray_hits(o, dirs)
    culled = fld.ray_hits(o, dirs, max_range=max_range)
    assert np.array_equal(np.minimum(full, max_range), np.minimum(culled, max_range))
    assert np.all((culled == full) | np.isinf(culled))


def test_polygons_are_built_lazily_and_match_the_bodies() -> None:
    obstacles = _world(4, 9)
    fld = ObstacleField.from_obstacles(obstacles)
    polys = fld.polygons
    assert fld.polygons is polys  # built once
    for o, poly in zip(obstacles, polys, strict=True):
        if isinstance(o.body, DiscBody):
            assert poly is None
        else:
            assert poly is not None and poly.flags.c_contiguous
            expect = transform_points(o.body.vertices, o.state.position, o.state.heading)
            assert np.array_equal(poly, expect)
