"""3D vehicle (3.1)-(3.7): exact sphere integration, limits and clear input errors."""

from __future__ import annotations

import numpy as np
import pytest

from uvnav.dynamics.vehicle3d import (
    Vehicle3DCommand,
    Vehicle3DSpec,
    Vehicle3DState,
    vehicle3d_advance,
    vehicle3d_step,
)


def test_heading_norm_stays_one_to_1e12_over_1e5_steps() -> None:
    a = np.array([0.3, -0.4, 0.5])
    a /= np.linalg.norm(a)
    u = np.cross(a, [0.1, 0.7, -0.2])
    u = 0.9 * u / np.linalg.norm(u)
    pos = np.zeros(3)
    worst = 0.0
    for _ in range(100_000):
        pos, a, u = vehicle3d_advance(pos, a, 1.0, u, 0.01)
        worst = max(worst, abs(float(np.linalg.norm(a)) - 1.0))
    assert worst < 1e-12
    assert abs(float(a @ u)) < 1e-12


def test_constant_turn_is_a_circle_of_radius_v_over_u() -> None:
    v, w = 0.8, 0.4
    st = Vehicle3DState(np.zeros(3), np.array([1.0, 0.0, 0.0]))
    cmd = Vehicle3DCommand(v, np.array([0.0, 0.0, w]))  # orthogonal to a: turn in a tilted plane
    pos, a, u = st.position, st.heading, cmd.u
    pts = []
    for _ in range(int(2 * np.pi / w / 0.05)):
        pos, a, u = vehicle3d_advance(pos, a, v, u, 0.05)
        pts.append(pos)
    pts = np.array(pts)
    centre = np.array([0.0, 0.0, v / w])  # centre of curvature along u
    assert np.allclose(np.linalg.norm(pts - centre, axis=1), v / w, atol=1e-9)
    # one step equals many small steps (exactness for held commands)
    big = vehicle3d_step(st, cmd, 1.0)
    p, h, uu = st.position, st.heading, cmd.u
    for _ in range(100):
        p, h, uu = vehicle3d_advance(p, h, v, uu, 0.01)
    assert np.allclose(big.position, p, atol=1e-12) and np.allclose(big.heading, h, atol=1e-12)


def test_bad_inputs_get_clear_errors() -> None:
    cmd = Vehicle3DCommand(1.0, np.zeros(3))
    with pytest.raises(ValueError, match="heading must be a unit vector"):
        vehicle3d_step(Vehicle3DState(np.zeros(3), np.array([1.0, 1.0, 0.0])), cmd, 0.1)
    with pytest.raises(ValueError, match="orthogonal"):
        vehicle3d_step(
            Vehicle3DState(np.zeros(3), np.array([1.0, 0.0, 0.0])),
            Vehicle3DCommand(1.0, np.array([0.5, 0.1, 0.0])),
            0.1,
        )
    with pytest.raises(ValueError, match="v_max"):
        Vehicle3DSpec(0.0, 1.0)


def test_violations_and_clipping() -> None:
    spec = Vehicle3DSpec(1.0, 0.5)
    a = np.array([0.0, 1.0, 0.0])
    ok = Vehicle3DCommand(0.5, np.array([0.3, 0.0, 0.0]))
    assert not ok.violates(spec, a)
    bad = Vehicle3DCommand(2.0, np.array([1.0, 0.3, 0.0]))
    assert bad.violates(spec, a)
    c = bad.clipped(spec, a)
    assert c.v == 1.0 and abs(c.u @ a) < 1e-15 and np.isclose(np.linalg.norm(c.u), 0.5)
    assert not c.violates(spec, a)
    nan = Vehicle3DCommand(float("nan"), np.array([np.nan, 0, 0])).clipped(spec, a)
    assert nan.v == 0.0 and np.all(nan.u == 0.0)
