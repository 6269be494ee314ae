"""Coverage on ground truth (thesis Ch. 7 "D is covered completely"), checked apart from planning.

The checks of :mod:`uvnav.recon.coverage` share no sample with the altitude rule: footprint
polygons (shapely), a grid offset from every planning sample, random points.  They must pass for
the cell rule on any flat area, fail for the earlier DEM-node rule, and Stage 1's counts and the
naive baseline must not move.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.affinity import rotate, translate
from shapely.geometry import Polygon

from uvnav.recon import coverage as C  # noqa: N812
from uvnav.recon import lattice as L  # noqa: N812
from uvnav.recon.cells import clipped_cells, sample_polygon
from uvnav.recon.terrain import Terrain, fractal_terrain, square_area
from uvnav.recon.visibility import assign_altitudes, node_altitudes

THETA = math.pi / 2


def flat_under(area: Polygon, pad: float = 120.0, cell: float = 5.0) -> Terrain:
    """A flat DEM at height 3 m covering D padded by ``pad`` [m]."""
    xmin, ymin, xmax, ymax = area.bounds
    nx = math.ceil((xmax - xmin + 2 * pad) / cell) + 1
    ny = math.ceil((ymax - ymin + 2 * pad) / cell) + 1
    return Terrain(np.full((ny, nx), 3.0), xmin - pad, ymin - pad, cell, cell)


@st.composite
def areas(draw: st.DrawFn) -> Polygon:
    """Convex quadrilaterals/pentagons 20–120 m across, anywhere within 10 km, any rotation."""
    k = draw(st.integers(3, 6))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    pts = rng.uniform(0.0, draw(st.floats(20.0, 120.0)), size=(k + 3, 2))
    hull = shapely.convex_hull(shapely.multipoints(pts))
    shift = draw(st.tuples(st.floats(-1e4, 1e4), st.floats(-1e4, 1e4)))
    poly = translate(rotate(hull, draw(st.floats(0.0, 360.0))), *shift)
    return poly if poly.area > 50.0 else square_area(40.0, corner=shift)


@settings(max_examples=12, deadline=None)
@given(
    area=areas(),
    R=st.floats(8.0, 40.0),
    theta=st.floats(math.radians(50.0), math.radians(130.0)),
    lam=st.floats(0.0, L.PI3),
    off=st.tuples(st.floats(0.0, 1.0), st.floats(0.0, 1.0)),
)
def test_cell_rule_covers_any_flat_area_on_every_independent_check(
    area: Polygon, R: float, theta: float, lam: float, off: tuple[float, float]
) -> None:
    a1, a2 = L.lattice_basis(lam, R)
    o = off[0] * a1 + off[1] * a2
    xy = L.lattice_waypoints(area, lam, float(o[0]), float(o[1]), R)
    t = flat_under(area, pad=2 * R)
    z_max = 3.0 + 3.0 * R / math.tan(theta / 2)
    z, _ = assign_altitudes(t, xy, area, theta, 0.0, z_max, 1.0)
    W = np.column_stack([xy, z])
    poly = C.check_coverage_polygons(t, W, area, theta)
    assert poly.uncovered_area == 0.0 and poly.cells_not_seen == 0
    assert C.check_grid(t, W, area, theta, z_max, step=1.0).coverage_all == 1.0
    assert C.check_random(t, W, area, theta, z_max, n=5000, seed=3).coverage_all == 1.0
    # and not higher than the corners need: the farthest corner of each cell, plus the margin
    cells = clipped_cells(xy, area)
    reach = [
        np.hypot(*(shapely.get_coordinates(c) - p).T).max() for c, p in zip(cells, xy, strict=True)
    ]
    tan_h = math.tan(theta / 2)
    expect = np.maximum(3.0 + np.asarray(reach) / tan_h, 4.0) + 0.01 / tan_h
    np.testing.assert_allclose(z, expect, atol=1e-6)


@pytest.fixture(scope="module")
def flat_square() -> tuple[Terrain, Polygon, np.ndarray]:
    area = square_area(150.0, corner=(12.0, -31.0))
    return flat_under(area), area, L.optimal_lattice(area, 20.0, n_lambda=12).xy


def test_node_rule_fails_the_independent_checks(flat_square) -> None:  # type: ignore[no-untyped-def]
    t, area, xy = flat_square
    z_max = 80.0
    z_old, _ = node_altitudes(t, xy, t.nodes_in(area), THETA, 0.0, z_max, 1.0)
    W_old = np.column_stack([xy, z_old])
    assert z_old.max() < 3.0 + 20.0  # below R: the footprints stop short of the hexagon corners
    poly = C.check_coverage_polygons(t, W_old, area, THETA)
    assert poly.uncovered_area > 10.0 and poly.largest_gap > 0.5 and poly.cells_not_seen > 0
    assert C.check_grid(t, W_old, area, THETA, z_max).coverage_all < 0.995
    # the planner's own DEM nodes call it complete: the check it was tuned on cannot fail
    nodes = t.nodes_in(area)
    assert C.check_coverage_points(t, W_old, nodes[:, :2], THETA, z_max).coverage_all == 1.0
    z_new, _ = assign_altitudes(t, xy, area, THETA, 0.0, z_max, 1.0)
    assert C.check_grid(t, np.column_stack([xy, z_new]), area, THETA, z_max).coverage_all == 1.0


def test_checks_see_occlusion() -> None:
    """A wall between camera and ground: the grid check counts it unseen, not uncovered-visible."""
    z = np.zeros((41, 41))
    z[:, 20] = 40.0  # a 40 m wall along x = 100 m
    t = Terrain(z, 0.0, 0.0, 5.0, 5.0)
    area = square_area(60.0, corner=(75.0, 70.0))  # straddles the wall
    W = np.array([[90.0, 100.0, 45.0]])
    cov = C.check_grid(t, W, area, THETA, 45.0, step=1.0)
    assert 0.0 < cov.coverage_all < 0.6  # the far side of the wall is hidden
    assert cov.coverage_visible == 1.0  # ... from every camera there is: not a planning gap
    # a second camera beyond the wall sees it
    W2 = np.vstack([W, [[115.0, 100.0, 45.0]]])
    assert C.check_grid(t, W2, area, THETA, 45.0, step=1.0).coverage_all > cov.coverage_all


def test_cell_rule_on_hills_and_blocks_sees_all_visible_ground() -> None:
    t = fractal_terrain((260.0, 260.0), cell=5.0, seed=5, origin=(-40.0, -40.0), n_blocks=6)
    area = square_area(180.0)
    xy = L.optimal_lattice(area, 30.0, n_lambda=6, refine=0).xy
    z_max = float(t.z.max()) + 70.0
    z, info = assign_altitudes(t, xy, area, THETA, 0.0, z_max, 8.0)
    W = np.column_stack([xy, z])
    assert info["orphans"] > 0 and info["seen"] == info["visible_at_zmax"]
    assert C.check_grid(t, W, area, THETA, z_max, step=1.0).coverage_visible == 1.0
    assert C.check_random(t, W, area, THETA, z_max, n=20_000).coverage_visible == 1.0


def test_footprint_polygon_and_cells() -> None:
    area = square_area(100.0)
    t = flat_under(area)
    foot = C.footprint_polygon(t, np.array([50.0, 50.0, 23.0]), THETA, n_az=720)
    assert foot.area == pytest.approx(math.pi * 20.0**2, rel=1e-4)
    assert foot.area < math.pi * 20.0**2  # inscribed: never claims ground outside the cone
    xy = L.lattice_waypoints(area, 0.2, 3.0, 4.0, 15.0)
    cells = clipped_cells(xy, area)
    assert sum(c.area for c in cells) == pytest.approx(area.area)
    hexes = shapely.polygons([L.hexagon_vertices(p, 0.2, 15.0) for p in xy])
    np.testing.assert_allclose(
        [c.area for c in cells], shapely.area(shapely.intersection(hexes, area)), rtol=1e-9
    )
    s = sample_polygon(cells[0], 0.5)
    assert shapely.covers(cells[0].buffer(1e-9), shapely.points(s)).all()


# Stage 1 is verified optimal: the altitude rule and the checks must not change its counts
@pytest.mark.parametrize(
    "side,R,n,n_naive",
    [
        (300.0, 20.0, 104, 105),
        (300.0, 30.0, 45, 52),
        (300.0, 50.0, 20, 20),
        (600.0, 20.0, 378, 378),
        (600.0, 30.0, 175, 175),
        (600.0, 50.0, 67, 68),
    ],
)
def test_stage1_counts_unchanged(side: float, R: float, n: int, n_naive: int) -> None:
    for centre in [(0.5 * side, 0.5 * side), (0.0, 0.0), (397.3, 494.1)]:
        sol = L.optimal_lattice(square_area(side, center=centre), R)
        assert (sol.n, sol.n_naive) == (n, n_naive)


@settings(max_examples=25, deadline=None)
@given(
    area=areas(),
    R=st.floats(5.0, 60.0),
    shift=st.tuples(st.floats(-5e3, 5e3), st.floats(-5e3, 5e3)),
)
def test_naive_lattice_does_not_depend_on_where_d_sits(
    area: Polygon, R: float, shift: tuple[float, float]
) -> None:
    moved = translate(area, *shift)
    assert L.naive_count(moved, R) == L.naive_count(area, R)
    np.testing.assert_allclose(
        np.sort(L.naive_lattice(moved, R), axis=0),
        np.sort(L.naive_lattice(area, R) + np.asarray(shift), axis=0),
        atol=1e-6,
    )
