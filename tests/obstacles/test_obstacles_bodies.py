"""Obstacle bodies: centring, orientation, radial profile and Delta-distance (thesis Fig. 2.2)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import Polygon

from uvnav.geometry.kernels3d import compiled, numba_available
from uvnav.obstacles.bodies import DiscBody, PolygonBody, radial_profile, rotation_boundary_growth

# the non-convex pentagon of the Chapter-2 scenario (DESIGN §3)
ARROW = np.array([[-0.6, -0.4], [0.7, -0.5], [0.2, 0.1], [0.6, 0.6], [-0.5, 0.5]])
SQUARE = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])


def test_from_vertices_centres_on_centroid_and_orients_ccw() -> None:
    cw = (ARROW + np.array([3.0, -2.0]))[::-1]
    body = PolygonBody.from_vertices(cw)
    poly = Polygon(body.vertices)
    assert poly.exterior.is_ccw
    assert [poly.centroid.x, poly.centroid.y] == pytest.approx([0.0, 0.0], abs=1e-12)
    assert body.offset == pytest.approx([Polygon(cw).centroid.x, Polygon(cw).centroid.y], abs=1e-12)
    assert body.bounding_radius == pytest.approx(float(np.max(np.hypot(*body.vertices.T))))


@pytest.mark.parametrize(
    "bad", [np.zeros((2, 2)), np.zeros((3, 3)), np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]])]
)
def test_from_vertices_rejects_degenerate(bad: np.ndarray) -> None:
    with pytest.raises(ValueError):
        PolygonBody.from_vertices(bad)


def test_from_vertices_rejects_self_intersecting_polygon() -> None:
    """A crossed ring with non-zero signed area is not a simple polygon: containment (even-odd),
    centroid and the outline would silently disagree with the body a scenario meant."""
    crossed = np.array([[0.0, 0.0], [3.0, 2.0], [3.0, 0.0], [0.0, 1.0]])
    assert not Polygon(crossed).is_valid
    with pytest.raises(ValueError):
        PolygonBody.from_vertices(crossed)


def test_radial_profile_of_square_is_analytic() -> None:
    body = PolygonBody.from_vertices(SQUARE)
    ang, rho = radial_profile(body, 720)
    expect = 1.0 / np.maximum(np.abs(np.cos(ang)), np.abs(np.sin(ang)))
    assert rho == pytest.approx(expect, abs=1e-12)
    _, rho_disc = radial_profile(DiscBody(0.7), 10)
    assert rho_disc == pytest.approx(np.full(10, 0.7))


@pytest.mark.parametrize("rotation", [0.0, 0.1, 1.0, math.pi, -2.0])
def test_growth_is_zero_for_discs(rotation: float) -> None:
    assert rotation_boundary_growth(DiscBody(0.5), rotation) == 0.0


def test_growth_is_zero_without_rotation() -> None:
    assert rotation_boundary_growth(PolygonBody.from_vertices(ARROW), 0.0) == 0.0


def test_growth_positive_for_non_convex_polygon_and_symmetric() -> None:
    body = PolygonBody.from_vertices(ARROW)
    g = rotation_boundary_growth(body, 0.3)
    assert g > 0.0
    assert rotation_boundary_growth(body, -0.3) == g


def _square_growth_reference(rotation: float) -> float:
    """max over phi and 0 < a <= |rotation| of rho(phi -+ a) - rho(phi); dense and analytic."""
    phi = np.linspace(-math.pi, math.pi, 4000, endpoint=False)

    def rho(x: np.ndarray) -> np.ndarray:
        return 1.0 / np.maximum(np.abs(np.cos(x)), np.abs(np.sin(x)))

    best = 0.0
    for a in np.linspace(0.0, abs(rotation), 200)[1:]:
        best = max(
            best, float(np.max(rho(phi - a) - rho(phi))), float(np.max(rho(phi + a) - rho(phi)))
        )
    return best


@pytest.mark.parametrize("rotation", [0.05, 0.2, math.pi / 4, 1.0, math.pi])
def test_growth_of_square_matches_analytic_radial_function(rotation: float) -> None:
    body = PolygonBody.from_vertices(SQUARE)
    g = rotation_boundary_growth(body, rotation, n_directions=720)
    ref = _square_growth_reference(rotation)
    # discretisation: 0.5 degree directions, and the rotation rounded up to the next 0.5 degree
    assert g == pytest.approx(ref, abs=0.02)
    assert g <= math.sqrt(2.0) - 1.0 + 1e-12


def test_growth_for_half_turn_is_radial_spread() -> None:
    """A rotation of pi or more (either sense) reaches every shift: growth = max rho - min rho."""
    body = PolygonBody.from_vertices(ARROW)
    _, rho = radial_profile(body)
    assert rotation_boundary_growth(body, math.pi) == pytest.approx(float(rho.max() - rho.min()))
    assert rotation_boundary_growth(body, 10.0) == pytest.approx(float(rho.max() - rho.min()))


@settings(max_examples=40, deadline=None)
@given(st.floats(0.0, 4.0), st.floats(0.0, 4.0))
def test_growth_is_monotone_in_rotation(a: float, b: float) -> None:
    body = PolygonBody.from_vertices(ARROW)
    lo, hi = sorted((a, b))
    assert rotation_boundary_growth(body, lo) <= rotation_boundary_growth(body, hi)


@pytest.mark.skipif(not numba_available(), reason="needs numba (the fast extra)")
@settings(max_examples=80, deadline=None)
@given(
    st.lists(st.tuples(st.floats(0.0, 6.28), st.floats(0.2, 2.0)), min_size=3, max_size=9),
    st.tuples(st.floats(-1.5, 1.5), st.floats(-1.5, 1.5)),
    st.floats(0.01, 7.0),
)
def test_compiled_growth_equals_the_array_version(
    polar: list[tuple[float, float]], shift: tuple[float, float], rotation: float
) -> None:
    """The compiled loops give the arrays' growth exactly, also for bodies whose centroid lies
    outside them (rays that miss: NaN differences, which the arrays' max keeps and the builtin
    max skips)."""
    a, r = np.array(sorted(polar)).T
    verts = np.stack([r * np.cos(a), r * np.sin(a)], axis=-1) + np.array(shift)
    try:
        body = PolygonBody.from_vertices(verts)
    except ValueError:
        return
    with compiled(False), np.errstate(invalid="ignore"):
        want = rotation_boundary_growth(body, rotation)
    with compiled(True):
        got = rotation_boundary_growth(body, rotation)
    assert got == want
