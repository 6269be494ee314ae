"""3D rotations, sphere integration and the on-line frame (thesis Ch. 3 §3.2-§3.3)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from uvnav.geometry.frames3d import (
    arc_displacement,
    online_frame,
    rotate_on_sphere,
    rotation_from_vector,
    rotation_to_vector,
    turn_toward,
)

vec = st.lists(st.floats(-3.0, 3.0, allow_nan=False), min_size=3, max_size=3).map(np.array)


@settings(max_examples=60, deadline=None)
@given(r=vec)
def test_rodrigues_matches_scipy_and_log_inverts_it(r: np.ndarray) -> None:
    rot = rotation_from_vector(r)
    assert np.allclose(rot, Rotation.from_rotvec(r).as_matrix(), atol=1e-12)
    assert np.allclose(rot @ rot.T, np.eye(3), atol=1e-12)
    back = rotation_from_vector(rotation_to_vector(rot))
    assert np.allclose(back, rot, atol=1e-9)


@settings(max_examples=40, deadline=None)
@given(a=vec, u=vec, dt=st.floats(0.0, 2.0))
def test_rotate_on_sphere_keeps_unit_norm_orthogonality_and_matches_fine_integration(
    a: np.ndarray, u: np.ndarray, dt: float
) -> None:
    if np.linalg.norm(a) < 1e-3:
        return
    a = a / np.linalg.norm(a)
    u = u - (u @ a) * a
    a1, u1 = rotate_on_sphere(a, u, dt)
    assert abs(np.linalg.norm(a1) - 1.0) < 1e-12
    assert abs(a1 @ u1) < 1e-9 * max(1.0, np.linalg.norm(u))
    assert abs(np.linalg.norm(u1) - np.linalg.norm(u)) < 1e-9
    # reference: a(s) = exp(s [a x u]x) a (scipy), position by composite Simpson over s
    w = np.cross(a, u)
    assert np.allclose(a1, Rotation.from_rotvec(w * dt).apply(a), atol=1e-12)
    s_grid = np.linspace(0.0, dt, 401)
    a_s = Rotation.from_rotvec(np.outer(s_grid, w)).apply(a)
    h = dt / 400
    weights = np.ones(401)
    weights[1:-1:2] = 4
    weights[2:-1:2] = 2
    pos = (weights[:, None] * a_s).sum(axis=0) * h / 3
    assert np.allclose(arc_displacement(a, u, 1.0, dt), pos, atol=1e-8)


@settings(max_examples=60, deadline=None)
@given(p=vec, g=vec)
def test_online_frame_is_orthonormal_with_horizontal_x_and_y_toward_goal(
    p: np.ndarray, g: np.ndarray
) -> None:
    if np.linalg.norm(g - p) < 1e-3:
        return
    f = online_frame(p, g)
    assert np.allclose(f.basis @ f.basis.T, np.eye(3), atol=1e-9)
    # X' horizontal; with Y' within 1e-6 of vertical the frame keeps world +x projected off Y'
    # (horizontal_perpendicular), which tilts it by at most Y''s horizontal part
    tilt = 1e-12 if math.hypot(*f.y_axis[:2]) > 1e-6 else 1e-6
    assert abs(f.x_axis[2]) < tilt
    assert np.allclose(f.y_axis, (g - p) / np.linalg.norm(g - p))
    assert f.z_axis[2] >= -tilt  # Z' points up (right-handed, X' to the right of Y')
    assert np.allclose(f.to_plane(g), [0.0, np.linalg.norm(g - p)], atol=1e-9)


def test_online_frame_with_goal_straight_above_keeps_previous_x() -> None:
    f = online_frame(np.zeros(3), np.array([0.0, 0.0, 5.0]), previous_x=np.array([0.0, 1.0, 0.0]))
    assert np.allclose(f.x_axis, [0.0, 1.0, 0.0])
    assert np.allclose(f.y_axis, [0.0, 0.0, 1.0])


def test_turn_toward_is_orthogonal_bounded_and_turns_the_right_way() -> None:
    a = np.array([1.0, 0.0, 0.0])
    u = turn_toward(a, np.array([0.0, 1.0, 0.0]), 0.8, 0.1)
    assert abs(u @ a) < 1e-15 and np.isclose(np.linalg.norm(u), 0.8) and u[1] > 0
    small = turn_toward(a, np.array([1.0, 0.01, 0.0]), 0.8, 0.1)
    assert np.linalg.norm(small) < 0.8  # boundary layer: closes the small angle in one period
    assert np.allclose(turn_toward(a, a, 0.8, 0.1), 0.0)
    back = turn_toward(a, -a, 0.8, 0.1)
    assert abs(back @ a) < 1e-12 and np.isclose(np.linalg.norm(back), 0.8)
