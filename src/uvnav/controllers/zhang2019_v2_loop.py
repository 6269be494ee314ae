"""The whole ``zhang2019-v2`` decision on the ideal vehicle after reading the observation, in one
call (compiled by numba when it is enabled, plain Python otherwise).

:func:`plan_loop_py` computes on floats, with the same operations in the same order, what the numpy
building blocks of :mod:`uvnav.controllers.zhang2019_v2` and
:mod:`uvnav.controllers.zhang2019_v2_bodies` compute: the bodies that can reach the robot within the
horizon (:func:`~uvnav.controllers.zhang2019_v2_bodies.reachable`), their boundary discs
(:func:`~uvnav.controllers.zhang2019_v2_bodies.boundary_discs`), their bounding radii for the cull
and the extra headings (:func:`~uvnav.controllers.zhang2019_v2_bodies.extra_headings`); then it runs
the branch-and-bound choice :func:`uvnav.geometry.contact.decide_py`.  The caller computes the
preferred velocity and whether the previous choice is moving, in Python, as the building blocks do
(CPython's ``math.hypot`` need not round as the C library's, which numba calls, does).  The result
equals the building blocks' to the bit (tests); among a few polygons one call replaces some forty
small numpy operations, whose fixed costs were most of a decision.
Units: metres, seconds, radians.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from itertools import accumulate
from typing import Any

import numpy as np

from uvnav.geometry import contact
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.contact import decide_py
from uvnav.geometry.kernels3d import compile_family, numba_enabled
from uvnav.sensors.observation import ObstacleReading

IntArray = np.ndarray

#: how many weights :func:`uvnav.geometry.contact.decide_py` reads from the ``prm`` vector
N_WEIGHTS = 16
#: indices into the ``prm`` vector of :func:`plan_loop_py` (after decide_py's weights)
P_SPACING, P_HEADINGS, P_VMAX = 16, 17, 18
N_PRM = 19


def reachable_py(scal: FloatArray, vel: FloatArray, v_max: float, horizon: float) -> np.ndarray:
    """Indices of the bodies that can reach the robot within ``horizon`` [s]: a body's distance
    ``scal[k, 0]`` [m] at most (``v_max`` + its speed + |angular velocity| x bounding radius)
    x ``horizon`` (:func:`uvnav.controllers.zhang2019_v2_bodies.reachable`, as a loop)."""
    n = scal.shape[0]
    keep = np.empty(n, dtype=np.int64)
    n_keep = 0
    for k in range(n):
        bound = math.hypot(vel[k, 0], vel[k, 1]) + abs(scal[k, 1]) * scal[k, 3]
        if scal[k, 0] <= (v_max + bound) * horizon:
            keep[n_keep] = k
            n_keep += 1
    return keep[:n_keep]


def boundary_discs_py(
    keep: IntArray,
    scal: FloatArray,
    centre: FloatArray,
    vel: FloatArray,
    rings: FloatArray,
    ring_start: IntArray,
    spacing: float,
) -> tuple[FloatArray, FloatArray, FloatArray, IntArray]:
    """The boundary discs of the bodies ``keep``: centres (M, 2), velocities (M, 2), radii (M,)
    and owners (M,) (the index into ``keep``), as
    :func:`uvnav.controllers.zhang2019_v2.plan` makes them: where every kept body is a disc, the
    bodies themselves; otherwise
    :func:`uvnav.controllers.zhang2019_v2_bodies.boundary_discs` (a disc is its centre, a
    polygon, radius <= 0, its outline ``rings[ring_start[k]:ring_start[k + 1]]``
    sampled at most ``spacing`` apart)."""
    n_keep = keep.shape[0]
    discs_only = True
    for i in range(n_keep):
        if not scal[keep[i], 2] > 0.0:
            discs_only = False
    if discs_only:
        q, w, r = np.empty((n_keep, 2)), np.empty((n_keep, 2)), np.empty(n_keep)
        for i in range(n_keep):
            k = keep[i]
            q[i, 0], q[i, 1], w[i, 0], w[i, 1] = centre[k, 0], centre[k, 1], vel[k, 0], vel[k, 1]
            r[i] = scal[k, 2]
        return q, w, r, np.arange(n_keep)
    n_d = 0
    for i in range(n_keep):
        k = keep[i]
        if scal[k, 2] <= 0.0:
            a, b = ring_start[k], ring_start[k + 1]
            for v in range(a, b):
                nv = v + 1 if v + 1 < b else a
                ex, ey = rings[nv, 0] - rings[v, 0], rings[nv, 1] - rings[v, 1]
                n_d += max(math.ceil(math.hypot(ex, ey) / spacing), 1)
        else:
            n_d += 1
    q, w = np.empty((n_d, 2)), np.empty((n_d, 2))
    r, owner = np.empty(n_d), np.empty(n_d, dtype=np.int64)
    j = 0
    for i in range(n_keep):
        k = keep[i]
        cx, cy, vx, vy, om = centre[k, 0], centre[k, 1], vel[k, 0], vel[k, 1], scal[k, 1]
        rk = scal[k, 2] if scal[k, 2] > 0.0 else 0.5 * spacing - scal[k, 2]
        polygon = scal[k, 2] <= 0.0
        a, b = (ring_start[k], ring_start[k + 1]) if polygon else (0, 1)
        for v in range(a, b):
            sx, sy, ex, ey = cx, cy, 0.0, 0.0  # a disc: its centre, no edge
            if polygon:
                nv = v + 1 if v + 1 < b else a
                sx, sy = rings[v, 0], rings[v, 1]
                ex, ey = rings[nv, 0] - sx, rings[nv, 1] - sy
            n_sub = max(math.ceil(math.hypot(ex, ey) / spacing), 1)
            for f in range(n_sub):
                fr = float(f) / float(n_sub)
                qx, qy = sx + fr * ex, sy + fr * ey
                rx, ry = qx - cx, qy - cy
                q[j, 0], q[j, 1] = qx, qy
                w[j, 0], w[j, 1] = vx + om * -ry, vy + om * rx
                r[j], owner[j] = rk, i
                j += 1
    return q, w, r, owner


def plan_loop_py(
    state: FloatArray,
    scal: FloatArray,
    centre: FloatArray,
    vel: FloatArray,
    rings: FloatArray,
    ring_start: IntArray,
    speeds: FloatArray,
    prm: FloatArray,
    out: FloatArray,
) -> None:
    """One decision of ``zhang2019-v2`` (module docstring), written into ``out``: velocity x, y
    [m/s], its first contact [s], 1.0 when it is the preferred one.

    ``state``: decide_py's (robot x, y, heading [rad] (NaN: holonomic), U_max [rad/s], the
    preferred velocity x, y, the previous choice x, y), then 1.0 when the previous choice's
    direction is a candidate (its norm is above 1e-9), 0.0 if not; the readings as ``scal``
    (N, 4: distance, angular velocity, radius, bounding radius), ``centre`` and ``vel`` (N, 2),
    polygons' outlines in ``rings`` (body k's rows ``ring_start[k]:ring_start[k + 1]``);
    ``speeds``: V_max times the speed levels; ``prm``: decide_py's weights, then spacing,
    n_headings, V_max.
    """
    v_max, horizon = prm[P_VMAX], prm[0]
    fx, fy = state[4], state[5]
    keep = reachable_py(scal, vel, v_max, horizon)
    n_keep = keep.shape[0]
    if n_keep == 0:
        out[0], out[1], out[2], out[3] = fx, fy, math.inf, 1.0
        return
    spacing = prm[P_SPACING]
    q, w, r, owner = boundary_discs_py(keep, scal, centre, vel, rings, ring_start, spacing)
    c_k, v_k, body_r = np.empty((n_keep, 2)), np.empty((n_keep, 2)), np.empty(n_keep)
    for i in range(n_keep):
        k = keep[i]
        c_k[i, 0], c_k[i, 1], v_k[i, 0], v_k[i, 1] = (
            centre[k, 0],
            centre[k, 1],
            vel[k, 0],
            vel[k, 1],
        )
        if scal[k, 2] > 0.0:
            body_r[i] = scal[k, 3]
        else:
            uh = scal[k, 1] * horizon
            body_r[i] = scal[k, 3] * math.sqrt(1.0 + uh * uh) + 0.5 * spacing
    n_h = int(prm[P_HEADINGS])
    ox, oy, moving = state[6], state[7], state[8] > 0.0
    extra = np.empty(n_h + (2 if moving else 1))
    for i in range(n_h):
        extra[i] = 2.0 * math.pi * float(i) / max(n_h, 1)
    extra[n_h] = math.atan2(fy, fx)
    if moving:
        extra[n_h + 1] = math.atan2(oy, ox)
    decide_py(state[:8], extra, speeds, q, w, r, owner, c_k, v_k, body_r, prm[:N_WEIGHTS], out)


_COMPILED: dict[str, Callable[..., Any]] = {}


def _compiled_plan() -> Callable[..., Any]:
    """:func:`plan_loop_py` compiled by numba (on the first call, or loaded from numba's cache),
    calling the compiled copies of :mod:`uvnav.geometry.contact`'s loops."""
    if not _COMPILED:
        _COMPILED.update(
            compile_family(
                (reachable_py, boundary_discs_py, plan_loop_py), bound=contact._kernels()
            )
        )
    return _COMPILED["plan_loop_py"]


def plan_loop(
    state: FloatArray,
    table: tuple[FloatArray, FloatArray, FloatArray],
    rings: tuple[FloatArray, IntArray],
    speeds: FloatArray,
    prm: FloatArray,
) -> FloatArray:
    """:func:`plan_loop_py` (compiled when numba is enabled): ``(vx, vy, ttc, preferred)``."""
    out = np.empty(4)
    fn = _compiled_plan() if numba_enabled() else plan_loop_py
    scal, centre, vel = table
    fn(state, scal, centre, vel, rings[0], rings[1], speeds, prm, out)
    return out


def outline_rings(
    readings: tuple[ObstacleReading, ...], scal: FloatArray
) -> tuple[FloatArray, np.ndarray]:
    """The outlines of ``readings`` stacked (V, 2) [m] and where each reading's rows start
    (N + 1,), when any reading is a polygon (``scal``'s radius <= 0); none otherwise (a crowd of
    discs).  A disc's outline is carried along but never read."""
    n = len(readings)
    if not n or not bool((scal[:, 2] <= 0.0).any()):
        return _NO_RINGS, np.zeros(n + 1, dtype=np.int64)
    outlines = [rd.outline for rd in readings]
    try:
        rings = np.concatenate(outlines, dtype=float)
    except ValueError:  # an outline that is not (n, 2): as boundary_discs reads it
        outlines = [np.asarray(x, dtype=float).reshape(-1, 2) for x in outlines]
        rings = np.concatenate(outlines)
    return rings, np.fromiter(accumulate(map(len, outlines), initial=0), np.int64, n + 1)


_NO_RINGS = np.zeros((0, 2))
