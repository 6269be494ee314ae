"""Compiled kernels for the hot paths of the 3D world (thesis Chapter 3), with numpy fallbacks.

Y. Zhang, thesis Chapter 3, §3.2, eq. (3.8) (d_min and r_min, the exact nearest point of a solid,
possibly non-convex obstacle) and §3.3.2-§3.3.3 (the obstacle seen in the on-line plane, inflated
by the forecast sphere (3.17)).  Two kernels run for every obstacle at every decision or step:

* :func:`nearest_triangle` — the nearest point of a triangle mesh to a point: one pass over the
  triangles with the Voronoi-region test of C. Ericson, *Real-Time Collision Detection* (2005),
  §5.1.5 (:func:`closest_barycentric_scalar`), skipping a triangle when its bounding sphere's lower
  bound ``||p - centre_j|| - radius_j`` already exceeds the best distance found (an exact cull: a
  skipped triangle cannot be nearer);
* :func:`plane_shadow` — the angular extent, in the on-line plane, of a body's boundary points
  (now and rotated one sampling period ahead), each inflated by the forecast circle.

Both are exact (the same formulas as :mod:`uvnav.geometry.mesh3d` and
:func:`uvnav.controllers.zhang2020_3d.shadow_of`, to rounding).  With numba installed (the ``fast``
extra) they are compiled (``numba.njit(cache=True)``); without it (or with ``UVNAV_NO_NUMBA=1`` at
import, or after ``use_compiled(False)``) the callers use their vectorised numpy paths, and the
tests check that both agree to 1e-9.

Why numba and not a library BVH (python-fcl): a body has a few hundred triangles, so one compiled
pass with the bounding-sphere cull is already a few microseconds, and the cost of a query from
Python is dominated by the call itself, which a BVH does not reduce (fcl's Python binding builds a
request/result object per query); fcl also returns no triangle index, which the exact inside/outside
sign (angle-weighted pseudo-normals of the nearest feature) needs.  Numpy alone is much slower
here, because each query is a handful of array operations whose fixed overhead
(~1 µs each) dominates arrays this small.
"""

from __future__ import annotations

import hashlib
import importlib.util
import math
import os
import types
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from typing import Any, Literal

import numpy as np

from uvnav.geometry.angles import FloatArray

#: numba is installed (the optional ``fast`` extra); it is imported on the first kernel call only
_HAVE_NUMBA = importlib.util.find_spec("numba") is not None
#: the compiled kernels are used (see :func:`use_compiled`)
_ENABLED = _HAVE_NUMBA and os.environ.get("UVNAV_NO_NUMBA", "") != "1"


def compile_family(
    functions: Sequence[Callable[..., Any] | tuple[str, Callable[..., Any]]],
    bound: Mapping[str, Callable[..., Any]] | None = None,
    *,
    error_model: Literal["python", "numpy"] = "python",
) -> dict[str, Callable[..., Any]]:
    """numba-compiled copies of ``functions`` (callees before callers), by name.

    Each copy runs in its own module's globals with the names of the functions compiled before it
    bound to their compiled copies, so a compiled kernel calls compiled callees while the Python
    functions stay untouched: they remain the reference path of :func:`use_compiled` (False).  A
    ``(name, function)`` pair binds the function's compiled copy under ``name`` (a global the
    Python path binds to something numba cannot compile the same, e.g. ``math.hypot``).
    ``bound``: compiled kernels of other families, bound under their names in every copy (not
    returned).  ``error_model``: numba's (``"numpy"``: a float divided by zero gives inf or nan
    instead of raising, which spares a check at every division; a copy's name carries it).
    """
    import numba

    done: dict[str, Callable[..., Any]] = dict(bound or {})
    made: dict[str, Callable[..., Any]] = {}
    stamp = family_stamp(functions, bound) + ("" if error_model == "python" else f"_{error_model}")
    for item in functions:
        name, f = item if isinstance(item, tuple) else (item.__name__, item)
        env = {**f.__globals__, **done}
        copy = types.FunctionType(f.__code__, env, f.__name__, f.__defaults__, f.__closure__)
        copy.__qualname__ = f"{f.__qualname__}_{stamp}"
        done[name] = made[name] = numba.njit(cache=True, nogil=True, error_model=error_model)(copy)
    return made


def family_stamp(
    functions: Sequence[Callable[..., Any] | tuple[str, Callable[..., Any]]],
    bound: Mapping[str, Callable[..., Any]] | None = None,
) -> str:
    """A digest of the code of ``functions`` and of the ``bound`` kernels (their Python
    functions), part of every compiled copy's name and so of numba's cache key.

    numba's cache checks only the source file of the function it compiled: a callee changed in
    another file (a kernel compiled with the callee inlined) would be loaded stale from the
    cache.  Named after the whole family, a copy is compiled again when any of its code changes.

    >>> def f(): return 1
    >>> def g(): return 2
    >>> family_stamp([f]) == family_stamp([f]), family_stamp([f]) == family_stamp([("f", g)])
    (True, False)
    """
    digest = hashlib.sha1(usedforsecurity=False)
    items = [*(i if isinstance(i, tuple) else (i.__name__, i) for i in functions),
             *sorted((bound or {}).items())]  # fmt: skip
    for name, f in items:
        py = getattr(f, "py_func", f)
        digest.update(name.encode() + _code_bytes(py.__code__, py.__globals__))
    return digest.hexdigest()[:12]


def _code_bytes(code: types.CodeType, scope: Mapping[str, Any]) -> bytes:
    """What a code object computes, as bytes the same in every process: its bytecode, names
    and constants, nested code included, and the values of the module-level numbers and
    strings it reads from ``scope`` (numba compiles those in as constants); ``marshal`` would
    not do: its output depends on reference counts."""
    consts = [
        _code_bytes(c, scope) if isinstance(c, types.CodeType)
        else repr(sorted(map(repr, c)) if isinstance(c, frozenset) else c).encode()
        for c in code.co_consts
    ]  # fmt: skip
    read = [repr(scope[n]) for n in code.co_names if isinstance(scope.get(n), int | float | str)]
    names = (*code.co_names, *code.co_varnames, *code.co_freevars, code.co_filename, *read)
    return code.co_code + b"\0".join(consts) + "\0".join(names).encode()


def numba_available() -> bool:
    """numba can be imported (the ``fast`` extra is installed)."""
    return _HAVE_NUMBA


def numba_enabled() -> bool:
    """The compiled kernels are used: numba is installed, ``UVNAV_NO_NUMBA`` was not ``1`` when
    uvnav was imported, and :func:`use_compiled` has not turned them off."""
    return _ENABLED


def use_compiled(enabled: bool) -> bool:
    """Use the compiled kernels (``True``, when numba is installed) or the numpy fallback
    (``False``) from now on, in this process; returns the previous setting (benchmarks and tests
    compare the two paths)."""
    global _ENABLED
    previous = _ENABLED
    _ENABLED = bool(enabled) and _HAVE_NUMBA
    return previous


@contextmanager
def compiled(enabled: bool) -> Iterator[None]:
    """:func:`use_compiled` for the ``with`` block only (the setting before it is restored)."""
    previous = use_compiled(enabled)
    try:
        yield
    finally:
        use_compiled(previous)


def closest_barycentric_scalar(
    p: tuple[float, float, float],
    a: tuple[float, float, float],
    ab: tuple[float, float, float],
    ac: tuple[float, float, float],
) -> tuple[float, float]:
    """Barycentric weights ``(v, w)`` (of b and c) of the nearest point of one triangle to ``p``
    on plain floats (Ericson §5.1.5; the nearest point is ``a + v ab + w ac``)."""
    apx, apy, apz = p[0] - a[0], p[1] - a[1], p[2] - a[2]
    abx, aby, abz = ab[0], ab[1], ab[2]
    acx, acy, acz = ac[0], ac[1], ac[2]
    d1 = abx * apx + aby * apy + abz * apz
    d2 = acx * apx + acy * apy + acz * apz
    if d1 <= 0.0 and d2 <= 0.0:
        return 0.0, 0.0
    bpx, bpy, bpz = apx - abx, apy - aby, apz - abz
    d3 = abx * bpx + aby * bpy + abz * bpz
    d4 = acx * bpx + acy * bpy + acz * bpz
    if d3 >= 0.0 and d4 <= d3:
        return 1.0, 0.0
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        e = d1 - d3
        return (d1 / e if e != 0.0 else 0.0), 0.0
    cpx, cpy, cpz = apx - acx, apy - acy, apz - acz
    d5 = abx * cpx + aby * cpy + abz * cpz
    d6 = acx * cpx + acy * cpy + acz * cpz
    if d6 >= 0.0 and d5 <= d6:
        return 0.0, 1.0
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        e = d2 - d6
        return 0.0, (d2 / e if e != 0.0 else 0.0)
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        e = (d4 - d3) + (d5 - d6)
        w = (d4 - d3) / e if e != 0.0 else 0.0
        return 1.0 - w, w
    denom = va + vb + vc
    if denom == 0.0:
        return 0.0, 0.0
    return vb / denom, vc / denom


#: relative slack of the bounding-sphere cull (rounding of the bound against the exact distance)
CULL_SLACK = 1e-9


def nearest_triangle_py(
    px: float,
    py: float,
    pz: float,
    a: FloatArray,
    ab: FloatArray,
    ac: FloatArray,
    centre: FloatArray,
    radius: FloatArray,
) -> tuple[int, float, float, float, float, float, float]:
    """Nearest point of the triangles ``a + v ab + w ac`` (each (m, 3)) to ``(px, py, pz)``.

    The triangle with the nearest centroid is evaluated first, then all others in index order; one
    replaces the best when strictly nearer (exact ties keep the lowest index, as ``numpy.argmin``
    does); triangle j is skipped when
    ``||p - centre_j|| - radius_j > 0`` and its square exceeds the best squared distance by more
    than the slack :data:`CULL_SLACK` (then it cannot be nearer).

    Returns:
        ``(j, v, w, qx, qy, qz, d2)``: triangle index, barycentric weights, nearest point [m] and
        squared distance [m^2] (``j = -1`` without triangles).
    """
    best = math.inf
    bj, bv, bw, bx, by, bz = -1, 0.0, 0.0, 0.0, 0.0, 0.0
    m = a.shape[0]
    # start from the triangle with the nearest centroid: a tight first bound for the cull
    k, dk = 0, math.inf
    for j in range(m):
        gx, gy, gz = px - centre[j, 0], py - centre[j, 1], pz - centre[j, 2]
        g = gx * gx + gy * gy + gz * gz
        if g < dk:
            k, dk = j, g
    for i in range(m + 1):
        j = k if i == 0 else i - 1
        if i > 0 and j == k:
            continue
        gx, gy, gz = px - centre[j, 0], py - centre[j, 1], pz - centre[j, 2]
        low = math.sqrt(gx * gx + gy * gy + gz * gz) - radius[j]
        if low > 0.0 and low * low > best * (1.0 + CULL_SLACK):
            continue
        a0, a1, a2 = a[j, 0], a[j, 1], a[j, 2]
        b0, b1, b2 = ab[j, 0], ab[j, 1], ab[j, 2]
        c0, c1, c2 = ac[j, 0], ac[j, 1], ac[j, 2]
        v, w = closest_barycentric_scalar((px, py, pz), (a0, a1, a2), (b0, b1, b2), (c0, c1, c2))
        qx = a0 + b0 * v + c0 * w
        qy = a1 + b1 * v + c1 * w
        qz = a2 + b2 * v + c2 * w
        dd = (px - qx) ** 2 + (py - qy) ** 2 + (pz - qz) ** 2
        if dd < best or (dd == best and j < bj):
            best, bj, bv, bw, bx, by, bz = dd, j, v, w, qx, qy, qz
    return bj, bv, bw, bx, by, bz, best


def signed_nearest_world_py(
    p: FloatArray,
    centre: FloatArray,
    rotation: FloatArray,
    a: FloatArray,
    ab: FloatArray,
    ac: FloatArray,
    tri_centre: FloatArray,
    tri_radius: FloatArray,
    face: FloatArray,
    edge: FloatArray,
    vertex: FloatArray,
) -> tuple[float, float, float, float, int]:
    """Nearest surface point (world) of a mesh body at pose ``(centre, rotation)`` to the world
    point ``p`` and the signed distance (negative inside; the sign of ``(p - q) . N`` with N the
    angle-weighted pseudo-normal of the feature q lies on, as in
    :meth:`uvnav.geometry.mesh3d.PseudoNormals.normal_at`).

    Args:
        p: (3,) world point [m]; centre: (3,) [m] and rotation: (3, 3) the body's pose.
        a, ab, ac, tri_centre, tri_radius: the body-frame triangles
            (:class:`uvnav.geometry.mesh3d.Triangles`).
        face, edge, vertex: the pseudo-normals (:class:`uvnav.geometry.mesh3d.PseudoNormals`).

    Returns:
        ``(qx, qy, qz, d, j)``: the world nearest point [m], the signed distance [m] and the
        triangle index.
    """
    gx, gy, gz = p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]
    bx = rotation[0, 0] * gx + rotation[1, 0] * gy + rotation[2, 0] * gz
    by = rotation[0, 1] * gx + rotation[1, 1] * gy + rotation[2, 1] * gz
    bz = rotation[0, 2] * gx + rotation[1, 2] * gy + rotation[2, 2] * gz
    j, v, w, qx, qy, qz, d2 = nearest_triangle_py(bx, by, bz, a, ab, ac, tri_centre, tri_radius)
    d = math.sqrt(d2)
    if d > 0.0:
        tol = 1e-12
        u = 1.0 - v - w
        zu, zv, zw = u <= tol, v <= tol, w <= tol
        if zv and zw:
            n = vertex[j, 0]
        elif zu and zw:
            n = vertex[j, 1]
        elif zu and zv:
            n = vertex[j, 2]
        elif zw:
            n = edge[j, 0]
        elif zu:
            n = edge[j, 1]
        elif zv:
            n = edge[j, 2]
        else:
            n = face[j]
        if (bx - qx) * n[0] + (by - qy) * n[1] + (bz - qz) * n[2] < 0.0:
            d = -d
    wx = centre[0] + rotation[0, 0] * qx + rotation[0, 1] * qy + rotation[0, 2] * qz
    wy = centre[1] + rotation[1, 0] * qx + rotation[1, 1] * qy + rotation[1, 2] * qz
    wz = centre[2] + rotation[2, 0] * qx + rotation[2, 1] * qy + rotation[2, 2] * qz
    return wx, wy, wz, d, j


#: bound [rad] on |atan2_bound(y, x) - atan2(y, x)|: Abramowitz & Stegun 4.4.47 gives 1e-5 on
#: [0, 1]; with its 7-digit coefficients the measured maximum is 1.15e-5 (a test checks 1.5e-5);
#: four times that leaves room for any rounding
ATAN2_BOUND_ERROR = 5e-5


def atan2_bound(y: float, x: float) -> float:
    """atan2(y, x) [rad] to within :data:`ATAN2_BOUND_ERROR`, with no library call.

    Octant reduction and the degree-9 odd polynomial of Abramowitz & Stegun, *Handbook of
    Mathematical Functions* (1964), 4.4.47 (|error| <= 1e-5 for 0 <= z <= 1).  It only decides
    which boundary points cannot widen a shadow; the extent itself always uses ``math.atan2``.
    """
    ax = abs(x)
    ay = abs(y)
    big = ax if ax > ay else ay
    if big == 0.0:
        return 0.0
    z = (ay if ax > ay else ax) / big
    z2 = z * z
    a = z * (0.9998660 + z2 * (-0.3302995 + z2 * (0.1801410 + z2 * (-0.0851330 + z2 * 0.0208351))))
    if ay > ax:
        a = 0.5 * math.pi - a
    if x < 0.0:
        a = math.pi - a
    return -a if y < 0.0 else a


def plane_shadow_py(
    points: FloatArray,
    centre: FloatArray,
    rotation: FloatArray,
    rotate: bool,
    origin: FloatArray,
    x_axis: FloatArray,
    y_axis: FloatArray,
    radius: float,
) -> tuple[float, float, float, bool]:
    """Angular extent in the on-line plane of ``points`` (world, (n, 3)) — and, with ``rotate``,
    of the same points turned by ``rotation`` about ``centre`` — each inflated by a circle of
    ``radius`` [m] (the forecast circle), as seen from ``origin`` (the robot).

    Angles psi are counter-clockwise from Y' (``atan2(-x', y')``), measured relative to the
    centre's psi_c and wrapped to [-pi, pi]; the inflation of a point at plane distance r is
    ``asin(min(radius / r, 1))``, plus ``(radius - r) / radius * pi / 2`` when r < radius.

    Two exact short cuts keep the pass cheap:

    * a rotated point ``c + R (p - c)`` is projected with the rotated axes ``R^T X'``, ``R^T Y'``
      (the same two dot products as an unrotated one);
    * a point whose inflated extent cannot widen the one found so far is skipped before any
      library call: its angle is bounded by :func:`atan2_bound` (to ``ATAN2_BOUND_ERROR``) and
      its inflation by ``asin(x) <= min(x pi / 2, x / sqrt(1 - x^2))``.  Points near the ±pi
      cut, and points within their own circle, take the exact path.  On the benchmark's bodies
      (324 points, a forecast radius of 1.2 m at 3-13 m) about 5 % of the points reach
      ``math.atan2`` and ``math.asin``.

    Returns:
        ``(psi_c, lo, hi, inside)``: the centre's angle [rad], the extent ``psi_c + [lo, hi]`` and
        whether some point lies within its circle's radius of the robot.
    """
    ox, oy, oz = origin[0], origin[1], origin[2]
    xx, xy, xz = x_axis[0], x_axis[1], x_axis[2]
    yx, yy, yz = y_axis[0], y_axis[1], y_axis[2]
    cx, cy, cz = centre[0], centre[1], centre[2]
    c1 = (cx - ox) * xx + (cy - oy) * xy + (cz - oz) * xz
    c2 = (cx - ox) * yx + (cy - oy) * yy + (cz - oz) * yz
    n = points.shape[0]
    reps = 2 if rotate else 1
    # per pass: q1 = p . a1 + b1, q2 = p . a2 + b2 (pass 1: a = R^T X', R^T Y' about the centre)
    ax1 = np.empty((reps, 3))
    ax2 = np.empty((reps, 3))
    off = np.empty((reps, 2))
    ax1[0, 0], ax1[0, 1], ax1[0, 2] = xx, xy, xz
    ax2[0, 0], ax2[0, 1], ax2[0, 2] = yx, yy, yz
    off[0, 0] = -(ox * xx + oy * xy + oz * xz)
    off[0, 1] = -(ox * yx + oy * yy + oz * yz)
    if rotate:
        for j in range(3):
            ax1[1, j] = rotation[0, j] * xx + rotation[1, j] * xy + rotation[2, j] * xz
            ax2[1, j] = rotation[0, j] * yx + rotation[1, j] * yy + rotation[2, j] * yz
        off[1, 0] = c1 - (cx * ax1[1, 0] + cy * ax1[1, 1] + cz * ax1[1, 2])
        off[1, 1] = c2 - (cx * ax2[1, 0] + cy * ax2[1, 1] + cz * ax2[1, 2])
    if math.hypot(c1, c2) > 1e-9:
        psi_c = math.atan2(-c1, c2)
    else:  # the centre straight above/below the robot: the mean of the projected points
        s1 = 0.0
        s2 = 0.0
        for r in range(reps):
            a10, a11, a12 = ax1[r, 0], ax1[r, 1], ax1[r, 2]
            a20, a21, a22 = ax2[r, 0], ax2[r, 1], ax2[r, 2]
            for i in range(n):
                px, py, pz = points[i, 0], points[i, 1], points[i, 2]
                s1 += px * a10 + py * a11 + pz * a12 + off[r, 0]
                s2 += px * a20 + py * a21 + pz * a22 + off[r, 1]
        psi_c = math.atan2(-s1 / (reps * n), s2 / (reps * n))
    lo = math.inf
    hi = -math.inf
    inside = False
    half_pi = 0.5 * math.pi
    near_cut = math.pi - 2.0 * ATAN2_BOUND_ERROR
    for r in range(reps):
        a10, a11, a12 = ax1[r, 0], ax1[r, 1], ax1[r, 2]
        a20, a21, a22 = ax2[r, 0], ax2[r, 1], ax2[r, 2]
        b1, b2 = off[r, 0], off[r, 1]
        for i in range(n):
            px, py, pz = points[i, 0], points[i, 1], points[i, 2]
            q1 = px * a10 + py * a11 + pz * a12 + b1
            q2 = px * a20 + py * a21 + pz * a22 + b2
            dist = math.sqrt(q1 * q1 + q2 * q2)
            if dist <= radius:
                inside = True
            ratio = min(max(radius / max(dist, 1e-12), 0.0), 1.0)
            if dist >= radius:
                # asin(x) <= min(x pi / 2, tan(asin x) = x / sqrt(1 - x^2)): the second is tight
                # for small x, where most points lie
                bound = min(ratio * half_pi, ratio / math.sqrt(max(1.0 - ratio * ratio, 1e-300)))
                rough = atan2_bound(-q1, q2) - psi_c
                if rough > math.pi:
                    rough -= 2.0 * math.pi
                elif rough < -math.pi:
                    rough += 2.0 * math.pi
                reach = bound + ATAN2_BOUND_ERROR
                if abs(rough) < near_cut and rough - reach >= lo and rough + reach <= hi:
                    continue  # this point cannot widen the extent
            rel = math.atan2(-q1, q2) - psi_c  # in (-2 pi, 2 pi): wrapped once
            if rel > math.pi:
                rel -= 2.0 * math.pi
            elif rel < -math.pi:
                rel += 2.0 * math.pi
            half = math.asin(ratio)
            if dist < radius:
                half += (radius - dist) / max(radius, 1e-9) * half_pi
            if rel - half < lo:
                lo = rel - half
            if rel + half > hi:
                hi = rel + half
    return psi_c, lo, hi, inside


_COMPILED: dict[str, Callable[..., Any]] = {}


def _compiled() -> dict[str, Callable[..., Any]]:
    """The numba-compiled kernels by name (imported and compiled, or loaded from numba's cache,
    on the first call: importing uvnav does not import numba)."""
    if not _COMPILED:
        _COMPILED.update(compile_family([
            closest_barycentric_scalar, nearest_triangle_py, atan2_bound,
            signed_nearest_world_py, plane_shadow_py,
        ]))  # fmt: skip
    return _COMPILED


def signed_nearest_world(
    p: FloatArray,
    centre: FloatArray,
    rotation: FloatArray,
    a: FloatArray,
    ab: FloatArray,
    ac: FloatArray,
    tri_centre: FloatArray,
    tri_radius: FloatArray,
    face: FloatArray,
    edge: FloatArray,
    vertex: FloatArray,
) -> tuple[float, float, float, float, int]:
    """The compiled :func:`signed_nearest_world_py` (call only when :func:`numba_enabled`)."""
    return _compiled()["signed_nearest_world_py"](
        p, centre, rotation, a, ab, ac, tri_centre, tri_radius, face, edge, vertex
    )


def plane_shadow(
    points: FloatArray,
    centre: FloatArray,
    rotation: FloatArray | None,
    origin: FloatArray,
    x_axis: FloatArray,
    y_axis: FloatArray,
    radius: float,
) -> tuple[float, float, float, bool]:
    """The compiled :func:`plane_shadow_py` (call only when :func:`numba_enabled`); ``rotation``
    None: the points only.  The arrays must be float64 (numba compiles one version per layout)."""
    rot = _EYE if rotation is None else rotation
    return _compiled()["plane_shadow_py"](
        points, centre, rot, rotation is not None, origin, x_axis, y_axis, float(radius)
    )


_EYE = np.eye(3)
