"""zhang2022-uuv3d-v1 (thesis Ch. 5 §5.3 with the Ch. 4 forecast circle): geometry and switching."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers.zhang_uuv3d import (
    GeometricLocator,
    ModelLocator,
    OracleLocator,
    SonarObservation3D,
    ZhangUUV3D,
    ZhangUUV3DParams,
    fixed_tag_direction,
    tangent_direction,
)
from uvnav.dynamics.vehicle3d import Vehicle3DSpec
from uvnav.sensors.sonar_array import SonarArray, beam_point

ARR = SonarArray()


def _obs(ranges, *, pos=(0.0, 0, 0), head=(1.0, 0, 0), goal=(20.0, 0, 0), truth=None, t=0.0):  # type: ignore[no-untyped-def]
    r = np.asarray(ranges, dtype=float)
    return SonarObservation3D(
        time=t,
        position=np.asarray(pos, float),
        heading=np.asarray(head, float),
        speed=1.0,
        goal=np.asarray(goal, float),
        ranges=r,
        echo=r < ARR.max_range,
        array=ARR,
        truth_point=None if truth is None else np.asarray(truth, float),
    )


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_tangent_direction_touches_the_forecast_circle_on_the_goal_side(seed: int) -> None:
    rng = np.random.default_rng(seed)
    c, b, p = rng.normal(size=(3, 3)) * 5
    dist = float(np.linalg.norm(p - c))
    radius = float(rng.uniform(0.1, 0.9)) * dist
    d, nrm, inside = tangent_direction(c, b, p, radius, np.array([0, 0, 1.0]), 2.0)
    assert not inside
    assert np.linalg.norm(d) == pytest.approx(1.0)
    x = (p - c) / dist
    assert math.acos(np.clip(d @ x, -1, 1)) == pytest.approx(math.asin(radius / dist), abs=1e-9)
    # in the plane through c, B and p, on B's side of the line c -> p
    assert abs(d @ nrm) < 1e-9 and abs((b - c) @ nrm) < 1e-6 * np.linalg.norm(b - c)
    yb = (b - c) - ((b - c) @ x) * x
    assert (d - (d @ x) * x) @ yb > 0
    # the fixed-tag form with the same plane gives the same heading
    np.testing.assert_allclose(fixed_tag_direction(c, p, radius, nrm, 2.0), d, atol=1e-9)


def test_inside_the_sphere_it_escapes_away_from_the_point() -> None:
    d, _, inside = tangent_direction(
        np.zeros(3),
        np.array([10.0, 1, 0]),
        np.array([0.5, 0, 0]),
        1.0,
        np.array([0, 0, 1.0]),
        math.radians(120),
    )
    assert inside and d @ np.array([1.0, 0, 0]) < 0


def test_geometric_locator_is_min_argmin_and_model_locator_uses_the_model() -> None:
    r = np.full(9, ARR.max_range)
    r[3] = 2.0
    loc = GeometricLocator().locate(_obs(r))
    assert loc is not None and (loc.distance, loc.index) == (2.0, 4)
    np.testing.assert_allclose(loc.point, beam_point(ARR, np.zeros(3), np.array([1.0, 0, 0]), 4, 2))
    assert GeometricLocator().locate(_obs(np.full(9, ARR.max_range))) is None

    class Fixed:
        def predict(self, inputs, offset=None):  # type: ignore[no-untyped-def]
            assert inputs.shape == (1, 9) and offset is not None
            return np.array([[1.5, 6.7]])

    m = ModelLocator(Fixed()).locate(_obs(r))
    assert m is not None and (m.distance, m.index) == (1.5, 7)


def test_modes_switch_on_L_and_the_oracle_is_flagged() -> None:
    spec = Vehicle3DSpec(1.0, 1.0, 0.5)
    ctrl = ZhangUUV3D(ZhangUUV3DParams(switch_distance=3.0))
    ctrl.reset(spec, np.array([20.0, 0, 0]), np.random.default_rng(0))
    far = np.full(9, 5.0)
    cmd = ctrl.act(_obs(far))
    assert ctrl.mode == "M1" and cmd.v == pytest.approx(1.0)
    near = np.full(9, ARR.max_range)
    near[0] = 1.0
    cmd = ctrl.act(_obs(near, t=0.2))
    assert ctrl.mode == "M2"
    assert np.linalg.norm(cmd.u) > 0.5  # turning away, at the bounded rate
    assert not cmd.violates(spec, np.array([1.0, 0, 0]))
    # the point slips out of the beams: the remembered point is still evaded
    ctrl.act(_obs(np.full(9, ARR.max_range), t=0.4))
    assert ctrl.mode == "M2"
    # once the vehicle is past it (the point behind w.r.t. B), back to M1
    ctrl.act(_obs(np.full(9, ARR.max_range), pos=(3.0, 0, 0), t=0.6))
    assert ctrl.mode == "M1"
    assert not ctrl.oracle and ZhangUUV3D(None, OracleLocator()).oracle
    with pytest.raises(ValueError, match="switch_distance"):
        ZhangUUV3DParams(switch_distance=0.0)
