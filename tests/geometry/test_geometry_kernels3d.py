"""Compiled 3D kernels (numba) against the brute-force exact computation and the numpy fallback."""

from __future__ import annotations

import math
import types
from functools import cache

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers.zhang2020_3d import shadow_of
from uvnav.geometry.frames3d import online_frame, rotation_from_vector
from uvnav.geometry.kernels3d import (
    ATAN2_BOUND_ERROR,
    atan2_bound,
    compile_family,
    family_stamp,
    nearest_triangle_py,
    numba_available,
    numba_enabled,
    plane_shadow,
    plane_shadow_py,
    use_compiled,
)
from uvnav.geometry.mesh3d import (
    box_mesh,
    closest_points_on_triangles,
    contains_points,
    signed_nearest,
    signed_nearest_numpy,
)
from uvnav.obstacles.bodies3d import MeshBody, StarBody

needs_numba = pytest.mark.skipif(not numba_available(), reason="numba (the 'fast' extra) absent")

coord = st.floats(-4.0, 4.0, allow_nan=False)
vec = st.tuples(coord, coord, coord).map(np.array)
rotvec = st.tuples(*(st.floats(-3.0, 3.0),) * 3).map(np.array)


@cache
def _bodies() -> tuple[MeshBody, ...]:
    """A non-convex star body (bumps and dents), a box (exact ties on its edges) and a coarse
    star body."""
    rng = np.random.default_rng(7)
    star = StarBody(0.8, rng.normal(size=(4, 3)), np.array([0.5, -0.3, 0.4, -0.2]),
                    np.array([4.0, 5.0, 3.0, 6.0]))  # fmt: skip
    coarse = StarBody(1.2, rng.normal(size=(2, 3)), np.array([0.6, -0.4]), np.array([3.0, 3.0]))
    v, f = box_mesh(np.array([0.5, 1.0, 0.25]))
    return star.to_mesh(2), MeshBody.from_mesh(v, f), coarse.to_mesh(1)


def _brute(body: MeshBody, p: np.ndarray) -> tuple[np.ndarray, float]:
    """Every triangle, no culling; the sign from the winding number."""
    q, d2 = closest_points_on_triangles(p, body.tri)
    k = int(np.argmin(d2))
    d = math.sqrt(float(d2[k]))
    inside = bool(contains_points(p[None], body.tri)[0])
    return q[k], (-d if inside else d)


@settings(max_examples=150, deadline=None)
@given(which=st.integers(0, 2), p=vec, centre=vec, r=rotvec)
def test_fast_nearest_equals_brute_force_and_numpy(
    which: int, p: np.ndarray, centre: np.ndarray, r: np.ndarray
) -> None:
    body = _bodies()[which]
    rot = rotation_from_vector(r)
    pb = rot.T @ (p - centre)
    q_ref, d_ref = _brute(body, pb)
    # the default path (compiled with numba, numpy without), in the body frame and posed
    q, d, _ = signed_nearest(pb, body.tri, body.normals)
    qw, dw = body.nearest_world(p, centre, rot)
    q_np, d_np, _ = signed_nearest_numpy(pb, body.tri, body.normals)
    for qq, dd in ((q, d), (q_np, d_np), (rot.T @ (qw - centre), dw)):
        # (a point within 1e-9 of the surface may take either sign)
        assert abs(abs(dd) - abs(d_ref)) <= 1e-9
        assert dd == pytest.approx(d_ref, abs=1e-9) or abs(d_ref) < 1e-9
        # the nearest point is unique unless two surface points are equally near (then any)
        assert np.linalg.norm(pb - qq) == pytest.approx(abs(d_ref), abs=1e-9)
    assert np.allclose(q, q_np, atol=1e-9) or abs(np.linalg.norm(pb - q_np) - abs(d)) <= 1e-9
    assert np.allclose(q_ref, q, atol=1e-9) or abs(np.linalg.norm(pb - q_ref) - abs(d)) <= 1e-9


@needs_numba
def test_compiled_and_numpy_paths_agree_to_1e_9(monkeypatch: pytest.MonkeyPatch) -> None:
    assert numba_enabled()
    rng = np.random.default_rng(3)
    body = _bodies()[0]
    pts = rng.normal(size=(300, 3)) * 1.5
    for p in pts:
        q, d, j = signed_nearest(p, body.tri, body.normals)
        q2, d2, j2 = signed_nearest_numpy(p, body.tri, body.normals)
        assert abs(d - d2) <= 1e-9 and np.allclose(q, q2, atol=1e-9)
        assert j == j2  # same triangle (ties keep the lowest index on both paths)
    monkeypatch.setattr("uvnav.geometry.kernels3d._ENABLED", True)
    assert use_compiled(False) is True
    assert not numba_enabled()
    _, d3, _ = signed_nearest(pts[0], body.tri, body.normals)  # now the numpy path
    assert abs(d3 - signed_nearest_numpy(pts[0], body.tri, body.normals)[1]) == 0.0


def test_cull_keeps_the_nearest_triangle_and_ties_the_lowest_index() -> None:
    """The pure-Python form of the compiled kernel (same code) against argmin over all."""
    body = _bodies()[1]  # a box: points level with an edge are equally near two triangles
    t = body.tri
    for p in (np.array([0.9, 0.0, 0.0]), np.array([0.8, 1.4, 0.1]), np.array([2.0, 3.0, 1.0])):
        j, v, w, qx, qy, qz, d2 = nearest_triangle_py(*p, t.a, t.ab, t.ac, t.centre, t.radius)
        _, all_d2 = closest_points_on_triangles(p, t)
        assert d2 == pytest.approx(all_d2.min(), abs=1e-12)
        assert np.allclose((qx, qy, qz), t.a[j] + v * t.ab[j] + w * t.ac[j], atol=1e-12)
        assert j == int(np.flatnonzero(all_d2 <= all_d2.min() + 1e-12)[0])


@settings(max_examples=100, deadline=None)
@given(pos=vec, goal=vec, centre=vec, u=rotvec, radius=st.floats(0.05, 3.0), rotate=st.booleans())
def test_plane_shadow_equals_the_numpy_shadow(
    pos: np.ndarray, goal: np.ndarray, centre: np.ndarray, u: np.ndarray, radius: float,
    rotate: bool,
) -> None:  # fmt: skip
    body = _bodies()[2]
    frame = online_frame(pos, goal + np.array([0.0, 9.0, 0.0]))
    outline = body.vertices + centre
    rot = rotation_from_vector(u) if rotate else None
    pts = outline if rot is None else np.concatenate([outline, (outline - centre) @ rot.T + centre])
    ref = shadow_of(frame, pts, centre, radius)
    kernels = [plane_shadow_py]
    if numba_enabled():
        kernels.append(plane_shadow)
    for fn in kernels:
        args = (rot if rot is not None else np.eye(3),) if fn is plane_shadow_py else (rot,)
        if fn is plane_shadow_py:
            got = fn(outline, centre, args[0], rot is not None, frame.origin, frame.x_axis,
                     frame.y_axis, radius)  # fmt: skip
        else:
            got = fn(outline, centre, rot, frame.origin, frame.x_axis, frame.y_axis, radius)
        psi_c, lo, hi, inside = got
        assert inside == ref.inside
        assert math.isclose(psi_c, ref.centre_angle, abs_tol=1e-9)
        assert math.isclose(lo, ref.lo, abs_tol=1e-9) and math.isclose(hi, ref.hi, abs_tol=1e-9)


def test_atan2_bound_is_within_its_error_everywhere() -> None:
    """The cheap angle that decides which points to skip is within ATAN2_BOUND_ERROR of atan2,
    over all directions and 12 decades of length (and exact on the axes' signs)."""
    angles = np.linspace(-math.pi, math.pi, 100_001)
    lengths = np.geomspace(1e-6, 1e6, angles.size)
    ys, xs = lengths * np.sin(angles), lengths * np.cos(angles)
    worst = max(
        abs(atan2_bound(y, x) - math.atan2(y, x))
        for y, x in zip(ys.tolist(), xs.tolist(), strict=True)
    )
    assert worst < 1.5e-5 < ATAN2_BOUND_ERROR
    assert atan2_bound(0.0, 0.0) == 0.0
    assert atan2_bound(1.0, 0.0) == pytest.approx(0.5 * math.pi, abs=1.5e-5)
    assert atan2_bound(-1.0, -1.0) == pytest.approx(-0.75 * math.pi, abs=1.5e-5)


def _callee_one(x: float) -> float:
    return x + 1.0


def _callee_two(x: float) -> float:
    return x + 2.0


def _caller(x: float) -> float:
    return _callee(x)  # noqa: F821 - bound by compile_family


@pytest.mark.skipif(not numba_available(), reason="needs numba (the fast extra)")
def test_a_kernel_is_compiled_again_when_a_callee_it_inlines_changes() -> None:
    """numba's cache keys a kernel on its own file only; the family's stamp in every copy's
    name keeps a caller cached with one callee from being loaded with another."""
    one = compile_family([("_callee", _callee_one), _caller])
    two = compile_family([("_callee", _callee_two), _caller])
    assert one["_caller"](1.0) == 2.0
    assert two["_caller"](1.0) == 3.0
    assert one["_caller"].py_func.__qualname__ != two["_caller"].py_func.__qualname__
    again = compile_family([("_callee", _callee_one), _caller])
    assert again["_caller"].py_func.__qualname__ == one["_caller"].py_func.__qualname__


_STEP = 1.0


def _uses_a_constant(x: float) -> float:
    return x + _STEP


def test_the_stamp_follows_the_module_constants_a_kernel_reads() -> None:
    """numba compiles a module-level number in as a constant: a family reading another value
    of it gets another stamp."""
    f = _uses_a_constant
    other = types.FunctionType(f.__code__, {**f.__globals__, "_STEP": 2.0}, f.__name__)
    assert family_stamp([f]) == family_stamp([f])
    assert family_stamp([f]) != family_stamp([other])


def _ratio(x: float, y: float) -> float:
    return x / y


@pytest.mark.skipif(not numba_available(), reason="needs numba (the fast extra)")
def test_the_numpy_error_model_divides_by_zero_without_raising() -> None:
    """``error_model="numpy"``: a float divided by zero gives inf, as numpy's does; the default
    raises as Python does; the two copies carry different names (separate cache entries)."""
    plain = compile_family([_ratio])["_ratio"]
    quiet = compile_family([_ratio], error_model="numpy")["_ratio"]
    assert quiet(1.0, 0.0) == math.inf and quiet(3.0, 2.0) == plain(3.0, 2.0) == 1.5
    with pytest.raises(ZeroDivisionError):
        plain(1.0, 0.0)
    assert plain.py_func.__qualname__ != quiet.py_func.__qualname__
