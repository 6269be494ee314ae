"""Deforming star bodies (thesis Ch. 4 §4.2): fixed area and mass centre, bounded rate of change,
and the Fig. 4.2(b) trap shape."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.geometry.polygons import polygon_area, polygon_centroid
from uvnav.obstacles.deforming import (
    DeformingStar,
    RigidShape,
    trap_inner_space,
    trap_polygon,
)


def star(seed: int, rate: float, area: float = 2.0) -> DeformingStar:
    return DeformingStar.random(
        np.random.default_rng(seed), (3.0, -1.0), area, max_rate=rate, velocity=(0.0, 0.0)
    )


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    area=st.floats(0.2, 6.0),
    t=st.floats(0.0, 500.0),
)
def test_area_and_mass_centre_are_conserved(seed: int, area: float, t: float) -> None:
    s = star(seed, 0.2, area)
    v = s.outline(t)
    assert abs(polygon_area(v) - area) <= 1e-6
    assert np.allclose(polygon_centroid(v), [3.0, -1.0], atol=1e-9)
    assert shapely.is_valid(shapely.polygons(v))  # a simple polygon at every time


@settings(max_examples=20, deadline=None)
@given(
    seed=st.integers(0, 10_000),
    rate=st.floats(0.01, 0.5),
    t=st.floats(0.0, 200.0),
    dt=st.floats(1e-3, 0.5),
)
def test_boundary_moves_no_faster_than_the_rate_bound(
    seed: int, rate: float, t: float, dt: float
) -> None:
    s = star(seed, rate)
    a, b = s.outline(t), s.outline(t + dt)
    vertex_move = float(np.hypot(*(b - a).T).max())
    assert vertex_move <= rate * dt * (1 + 1e-9)
    # the shapes themselves (Hausdorff) are no farther apart
    haus = shapely.hausdorff_distance(shapely.polygons(a), shapely.polygons(b))
    assert haus <= rate * dt * (1 + 1e-9) + 1e-12


def test_the_shape_really_changes_and_the_bound_is_nearly_attained() -> None:
    s = star(3, 0.2)
    times = np.linspace(0.0, 2 * np.pi / s.omega0, 2001)
    o = s.outlines(times)
    speed = np.hypot(*np.diff(o, axis=0).transpose(2, 0, 1)).max() / (times[1] - times[0])
    assert 0.2 / 1.25 < speed <= 0.2  # calibrated to max_rate / 1.1, not far below it
    assert float(np.abs(o[0] - o[len(o) // 3]).max()) > 0.05


def test_translation_moves_the_mass_centre_only() -> None:
    s = DeformingStar.random(np.random.default_rng(1), (0, 0), 1.0, max_rate=0.1, velocity=(0.3, 0))
    assert np.allclose(polygon_centroid(s.outline(10.0)), [3.0, 0.0])
    assert np.allclose(s.local_outline(10.0), s.outline(10.0) - [3.0, 0.0])


def test_invalid_parameters_are_rejected() -> None:
    with pytest.raises(ValueError, match="amplitudes"):
        DeformingStar.create((0, 0), 1.0, np.full((3, 2), 0.2), max_rate=0.1)
    with pytest.raises(ValueError, match="area"):
        DeformingStar.create((0, 0), -1.0, np.zeros((2, 2)), max_rate=0.1)
    with pytest.raises(ValueError, match="integers"):
        DeformingStar.create(
            (0, 0), 1.0, np.full((1, 2), 0.1), max_rate=0.1, multipliers=np.full((1, 2), 1.5)
        )


def test_trap_has_a_deep_inner_space_behind_a_narrow_mouth() -> None:
    v = trap_polygon((0.0, 0.0), outer=1.5, inner=1.0, mouth=0.2, facing=0.0)
    poly = shapely.polygons(v)
    assert shapely.is_valid(poly)
    inner = shapely.polygons(trap_inner_space((0.0, 0.0), inner=1.0))
    # the inner space is not part of the body, and is reachable only through the mouth
    assert shapely.area(shapely.intersection(poly, inner)) < 0.02 * shapely.area(inner)
    # a disc wider than the mouth cannot pass it: the mouth gap between the lips is 0.2 m
    lips = shapely.points([[1.25, 0.11], [1.25, -0.11]])
    assert all(shapely.distance(poly, p) < 0.02 for p in lips)
    rigid = RigidShape.from_vertices(v)
    assert abs(rigid.area - shapely.area(poly)) < 1e-9
