"""Packed 2D worlds: K unicycle worlds among rigid moving polygons, stepped in one compiled call.

The world of thesis Ch. 2 (unicycle (2.1)-(2.4) among rigid bodies moving and rotating as in
§2.2) for the cases that need speed more than generality: batched learning
(:mod:`uvnav.envs.nav2d_vec`) and the world-step benchmark.  Each world's state lives in rows of
preallocated arrays (robot pose and command, obstacle poses, random-turn draws, body rings), and
:func:`step_worlds_py` advances every running world by one decision (``control_period / dt``
integration steps) in one loop, compiled by numba when it is enabled (:func:`numba_enabled`).

The numbers are those of :class:`uvnav.sim.episode.World2D` with exact clearance, bit for
bit (the test suite compares them):

* robot: :func:`uvnav.dynamics.unicycle.unicycle_advance`, the same operations;
* obstacles: :class:`~uvnav.obstacles.motion.RandomTurn` and
  :class:`~uvnav.obstacles.motion.ConstantVelocity` with the operations of
  :class:`~uvnav.obstacles.batch.ObstacleBatch`.  A random-turn obstacle's draws come from its own
  generator, pre-drawn in rows of blocks (:meth:`PackedWorlds.refill`): ``Generator.random(n)``
  gives the same numbers as ``n`` calls of ``random()`` (and ``random(out=...)`` as many), so
  the stream is the one the lazy draws read;
* clearance: the signed distance of :meth:`uvnav.obstacles.ObstacleField.query` (the loop of
  :func:`uvnav.geometry.polygons.rings_nearest_py` on the transformed rings; the depth inside a
  body by numpy's ``hypot``, libm's, as the field takes it) minus the robot's radius; arrival
  uses :func:`pyhypot`, CPython's ``math.hypot`` (which is not libm's ``hypot``);
* lidar (:func:`lidar_worlds_py`): :func:`uvnav.sensors.lidar_scan`'s beams and ray-edge test.

Only these motions and polygon bodies are packed; :func:`pack_check` says why a scene is not.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from uvnav.dynamics.unicycle import UnicycleSpec, unicycle_advance
from uvnav.geometry.angles import FloatArray, wrap_scalar
from uvnav.geometry.kernels3d import compile_family, numba_enabled
from uvnav.geometry.polygons import ray_ring_hit_py, ring_nearest_py
from uvnav.geometry.small import pyhypot
from uvnav.obstacles.bodies import PolygonBody
from uvnav.obstacles.motion import ConstantVelocity, RandomTurn
from uvnav.obstacles.obstacle import FieldTemplate, Obstacle, ObstacleState
from uvnav.sim.ledger import decision_ratio, step_count
from uvnav.sim.setup import EpisodeSetup

#: status codes of a packed world
RUNNING, SUCCESS, COLLISION, TIMEOUT = 0, 1, 2, 3
STATUS_NAMES = ("running", "success", "collision", "timeout")
#: motion kinds of a packed obstacle (-1: an empty slot)
EMPTY, CONSTANT, RANDOM_TURN = -1, 0, 1
#: random numbers are pre-drawn per obstacle in rows of ROW_BLOCKS blocks of BLOCK (longer rows
#: where one decision may need more); a row is topped up once half of it has been read
BLOCK = 64
ROW_BLOCKS = 4

# Columns of the (K, NW) float array of the worlds: pose [m, m, rad], held command [m/s, rad/s],
# goal [m], robot radius [m], goal tolerance [m], dt [s], clearance now and lowest over the last
# decision [m], V_max [m/s], U_max [rad/s].
(W_X, W_Y, W_TH, W_V, W_U, W_GX, W_GY, W_RADIUS, W_TOL, W_DT, W_CLEAR, W_LOW, W_VMAX,
 W_UMAX) = range(14)  # fmt: skip
NW = 14
# Columns of the (K, NI) int array of the worlds: step index, steps per decision, steps in the
# episode, status code, number of obstacles, 1 when the next step() advances it.
I_STEP, I_RATIO, I_NSTEPS, I_STATUS, I_NOBS, I_ACTIVE = range(6)
NI = 6
# Rows of the (K, 2, M) int array of the obstacles: motion kind, next unread pre-drawn number.
O_KIND, O_UPOS = 0, 1
# Parameter rows of the (K, P, M) obstacle parameter array.
(P_VX, P_VY, P_OMEGA, P_SPEED_LO, P_SPEED_SPAN, P_TURN_LO, P_TURN_SPAN, P_PERIOD, P_SPIN,
 P_X0, P_Y0, P_X1, P_Y1, P_MIDX, P_MIDY, P_LIMIT, P_ARENA, P_BOUND) = range(18)  # fmt: skip
N_PARAMS = 18
# State rows of the (K, S, M) obstacle state array (the velocity and rotation rate are those
# used over the last step, as :class:`ObstacleBatch` reports them).
(S_X, S_Y, S_HEADING, S_COURSE, S_SPEED, S_TURN, S_NEXT, S_THRESHOLD, S_VX, S_VY,
 S_OMEGA) = range(11)  # fmt: skip
N_STATE = 11


def _move_obstacles(n: int, st: FloatArray, prm: FloatArray, oi: np.ndarray, ubuf: FloatArray,
                    t: float, dt: float) -> None:  # fmt: skip
    """Advance obstacles ``0..n-1`` of one world (``st`` (S, M), ``prm`` (P, M), ``oi`` (2, M),
    ``ubuf`` (M, B)) from ``t`` by ``dt`` [s]: :class:`ObstacleBatch`'s arithmetic.

    One call moves them all: a compiled call that takes arrays passes each one as a struct and
    counts references to it, about 35 ns for the four arrays here, more than a random-turn step
    itself (about 25 ns) when it was made once per obstacle."""
    for o in range(n):
        kind = oi[O_KIND, o]
        if kind == CONSTANT:
            st[S_HEADING, o] = wrap_scalar(st[S_HEADING, o] + prm[P_OMEGA, o] * dt)
            st[S_X, o] = st[S_X, o] + prm[P_VX, o] * dt
            st[S_Y, o] = st[S_Y, o] + prm[P_VY, o] * dt
            st[S_VX, o], st[S_VY, o], st[S_OMEGA, o] = prm[P_VX, o], prm[P_VY, o], prm[P_OMEGA, o]
            continue
        if t >= st[S_THRESHOLD, o]:  # a new speed and turn rate (RandomTurn.step's two draws)
            p = oi[O_UPOS, o]
            st[S_SPEED, o] = prm[P_SPEED_LO, o] + prm[P_SPEED_SPAN, o] * ubuf[o, p]
            st[S_TURN, o] = prm[P_TURN_LO, o] + prm[P_TURN_SPAN, o] * ubuf[o, p + 1]
            oi[O_UPOS, o] = p + 2
            nc = t + prm[P_PERIOD, o]
            st[S_NEXT, o] = nc
            st[S_THRESHOLD, o] = nc - 1e-12
        turn = st[S_TURN, o]
        px, py = st[S_X, o], st[S_Y, o]
        if prm[P_ARENA, o] > 0.0 and not (
            prm[P_X0, o] <= px <= prm[P_X1, o] and prm[P_Y0, o] <= py <= prm[P_Y1, o]
        ):  # outside its arena: turn back toward the centre at the largest rate
            to_c = math.atan2(prm[P_MIDY, o] - py, prm[P_MIDX, o] - px)
            lim = prm[P_LIMIT, o]
            turn = min(max(wrap_scalar(to_c - st[S_COURSE, o]) / dt, -lim), lim)
        om = turn + prm[P_SPIN, o]
        course = wrap_scalar(st[S_COURSE, o] + turn * dt)
        st[S_HEADING, o] = wrap_scalar(st[S_HEADING, o] + om * dt)
        st[S_COURSE, o] = course
        mid = course - 0.5 * turn * dt
        speed = st[S_SPEED, o]
        vx, vy = math.cos(mid) * speed, math.sin(mid) * speed
        st[S_X, o] = px + vx * dt
        st[S_Y, o] = py + vy * dt
        st[S_VX, o], st[S_VY, o], st[S_OMEGA, o] = vx, vy, om


def _transform_ring(rings: FloatArray, o: int, c: float, s: float, cx: float, cy: float,
                    out: FloatArray) -> None:  # fmt: skip
    """Ring ``o`` of ``rings`` (2, M, W) turned by (``c``, ``s``) = (cos, sin) of its heading and
    moved to ``(cx, cy)`` [m], into ``out`` (2, W): :func:`transform_rings`'s operations."""
    for j in range(rings.shape[2]):
        rx, ry = rings[0, o, j], rings[1, o, j]
        out[0, j] = c * rx + s * -ry + cx
        out[1, j] = c * ry + s * rx + cy


def _clearance(x: float, y: float, radius: float, n_obs: int, prm: FloatArray, st: FloatArray,
               rings: FloatArray, ring: FloatArray,
               low: FloatArray) -> tuple[float, int]:  # fmt: skip
    """Exact clearance [m] of the robot disc at ``(x, y)`` in one world (``prm`` (P, M), ``st``
    (S, M), ``rings`` (2, M, W); ``ring`` (2, W) and ``low`` (M,) scratch): the signed distance
    of :meth:`ObstacleField.query` (boundary distance outside, minus it inside) minus the
    radius, and the obstacle it is to (the first in index order on a tie, as the field's
    ``argmin``); ``(inf, -1)`` without obstacles.

    A broad phase skips the bodies that cannot lower the minimum, in two passes: a lower bound
    of every body's gap (centre distance minus bounding radius minus the robot's radius), then
    the exact gap of the body with the lowest bound first and of every other body whose bound
    does not exceed the gap found so far.  Starting from the likely nearest body, a step of
    the benchmark's worlds computes about one exact gap (scanning in index order computed 3.3
    of 10, 5.9 of 100).  A bound is ``sqrt(dx^2 + dy^2) (1 - 1e-9)``: libm's ``hypot`` costs
    twice as much, and the relative margin covers the few ulps between them, as the absolute
    ``slack`` covers the rounding of the transformed rings (the :meth:`ObstacleField.query`
    cull's margins); a distance whose square is not below 1e300 takes ``hypot``.  The kept
    bodies' gaps have the same arithmetic as before, and the first lowest one in index order
    is returned, as the scan in index order returned it (it matters only for ``-0.0``)."""
    if n_obs == 0:
        return math.inf, -1
    slack = 1e-9 * (1.0 + abs(x) + abs(y))
    first, best = 0, math.inf
    for o in range(n_obs):
        dx, dy = st[S_X, o] - x, st[S_Y, o] - y
        dd = dx * dx + dy * dy
        dc = math.sqrt(dd) if dd < 1e300 else math.hypot(dx, dy)
        bound = dc * (1.0 - 1e-9) - prm[P_BOUND, o] - radius
        low[o] = bound
        if bound < best:
            first, best = o, bound
    gap, at = math.inf, n_obs
    for j in range(-1, n_obs):
        o = first if j < 0 else j
        if j == first or low[o] > gap + slack:
            continue  # done first, or its bounding disc is farther than the gap so far
        h = st[S_HEADING, o]
        _transform_ring(rings, o, math.cos(h), math.sin(h), st[S_X, o], st[S_Y, o], ring)
        d, qx, qy, inside = ring_nearest_py(x, y, ring[0], ring[1], True)
        if inside:
            d = -float(np.hypot(qx - x, qy - y))  # numpy's (libm's), as the field's depth
        g = d - radius
        if g < gap or g != g or (g == gap and o < at):
            gap, at = g, o
    return gap, (at if at < n_obs else -1)


def step_worlds_py(
    wf: FloatArray,
    wi: np.ndarray,
    oi: np.ndarray,
    params: FloatArray,
    state: FloatArray,
    ubuf: FloatArray,
    rings: FloatArray,
) -> int:
    """Advance every active running world by one decision (``wi[k, I_RATIO]`` integration
    steps), in place; return how many more calls the pre-drawn numbers cover (at two a step).

    The worlds' floats ``wf`` (K, NW) and ints ``wi`` (K, NI) are laid out as the ``W_*`` and
    ``I_*`` columns say; obstacle ``o`` < ``wi[k, I_NOBS]`` of world ``k`` has its motion kind
    and next unread draw in ``oi[k, :, o]``, its parameters ``params[k, :, o]`` (``P_*``), its
    state ``state[k, :, o]`` (``S_*``), its pre-drawn uniforms ``ubuf[k, o]`` and its body
    ring ``rings[k, :, o]`` (body frame).  The caller guarantees two unread draws per step.

    The count returned spares :meth:`PackedWorlds.step` numpy's per-call costs (about 5 µs)
    when it asks whether a top-up is due."""
    ring = np.empty((2, rings.shape[3]))
    low = np.empty(rings.shape[2])
    for k in range(wf.shape[0]):
        wf[k, W_LOW] = math.inf
        if wi[k, I_ACTIVE] == 0 or wi[k, I_STATUS] != RUNNING:
            continue
        dt = wf[k, W_DT]
        radius, tol = wf[k, W_RADIUS], wf[k, W_TOL]
        v, u = wf[k, W_V], wf[k, W_U]
        for _ in range(wi[k, I_RATIO]):
            i = wi[k, I_STEP]
            t = i * dt
            x, y, th = unicycle_advance(wf[k, W_X], wf[k, W_Y], wf[k, W_TH], v, u, dt)
            wf[k, W_X], wf[k, W_Y], wf[k, W_TH] = x, y, th
            _move_obstacles(wi[k, I_NOBS], state[k], params[k], oi[k], ubuf[k], t, dt)
            wi[k, I_STEP] = i = i + 1
            gap, _ = _clearance(x, y, radius, wi[k, I_NOBS], params[k], state[k], rings[k],
                                ring, low)  # fmt: skip
            wf[k, W_CLEAR] = gap
            if gap < wf[k, W_LOW]:
                wf[k, W_LOW] = gap
            if gap < 0.0:
                wi[k, I_STATUS] = COLLISION
            elif pyhypot(wf[k, W_GX] - x, wf[k, W_GY] - y) <= tol:
                wi[k, I_STATUS] = SUCCESS
            elif i >= wi[k, I_NSTEPS]:
                wi[k, I_STATUS] = TIMEOUT
            if wi[k, I_STATUS] != RUNNING:
                break
    safe = 1 << 40
    for k in range(wf.shape[0]):
        read = 0
        for o in range(wi[k, I_NOBS]):
            read = max(read, oi[k, O_UPOS, o])
        safe = min(safe, (ubuf.shape[2] - read) // (2 * max(wi[k, I_RATIO], 1)))
    return safe


def advance_one_py(x: float, y: float, radius: float, t: float, dt: float, n_obs: int,
                   oi: np.ndarray, prm: FloatArray, st: FloatArray, ubuf: FloatArray,
                   rings: FloatArray, sensing_range: float, ids: np.ndarray, rows: FloatArray,
                   outlines: FloatArray,
                   prev: FloatArray) -> tuple[float, int, int, float]:  # fmt: skip
    """Move the ``n_obs`` obstacles of one world (one slot's ``oi``, ``params``, ``state``,
    ``ubuf`` and ``rings``: :func:`step_worlds_py`'s layout) from ``t`` by ``dt`` [s]; return
    :func:`_clearance` of the robot disc of ``radius`` [m] at ``(x, y)`` then, for a
    ``sensing_range`` >= 0 [m] the number of readings :func:`sense_one_py` writes from there
    (else -1), and the most any body point moved [m] (centre shift plus bounding radius times
    the turn): the step of :class:`~uvnav.sim.bodies2d.PackedBodies`, in one call.  The poses
    before the step go to ``prev`` (3, n): x, y, heading.  The caller guarantees two unread
    draws per obstacle."""
    ring = np.empty((2, rings.shape[2]))
    low = np.empty(rings.shape[1])
    for o in range(n_obs):
        prev[0, o], prev[1, o], prev[2, o] = st[S_X, o], st[S_Y, o], st[S_HEADING, o]
    _move_obstacles(n_obs, st, prm, oi, ubuf, t, dt)
    shift = 0.0
    for o in range(n_obs):
        dx, dy = st[S_X, o] - prev[0, o], st[S_Y, o] - prev[1, o]
        turn = abs(st[S_HEADING, o] - prev[2, o])
        if turn > math.pi:  # (headings are wrapped)
            turn = 2.0 * math.pi - turn
        s = math.sqrt(dx * dx + dy * dy) + turn * prm[P_BOUND, o]
        if s > shift:
            shift = s
    gap, at = _clearance(x, y, radius, n_obs, prm, st, rings, ring, low)
    m = -1
    if sensing_range >= 0.0:
        m = sense_one_py(x, y, sensing_range, n_obs, prm, st, rings, ids, rows, outlines)
    return gap, at, m, shift


def clearance_one_py(x: float, y: float, radius: float, n_obs: int, prm: FloatArray,
                     st: FloatArray, rings: FloatArray) -> tuple[float, int]:  # fmt: skip
    """:func:`_clearance` of the robot disc of ``radius`` [m] at ``(x, y)`` among the ``n_obs``
    obstacles of one world as they stand (one slot's ``params``, ``state`` and ``rings``), with
    its own scratch: :meth:`ObstacleField.query`'s signed distance minus the radius [m] and the
    nearest obstacle (-1 without any), without building the field."""
    ring = np.empty((2, rings.shape[2]))
    low = np.empty(rings.shape[1])
    return _clearance(x, y, radius, n_obs, prm, st, rings, ring, low)


#: columns of :func:`sense_one_py`'s reading rows: distance [m], nearest point [m], centre [m],
#: velocity [m/s], rotation rate [rad/s]
R_DIST, R_NEAR, R_CENTRE, R_VEL, R_OMEGA = 0, 1, 3, 5, 7
NR = 8


def sense_one_py(x: float, y: float, sensing_range: float, n_obs: int, prm: FloatArray,
                 st: FloatArray, rings: FloatArray, ids: np.ndarray, rows: FloatArray,
                 outlines: FloatArray) -> int:  # fmt: skip
    """The readings of :func:`uvnav.sensors.exact.sense_obstacles` in one world from
    ``(x, y)``: their number ``m`` and, nearest first (ties in index order, NaN last, as a
    stable ``argsort``), in the first ``m`` rows of ``ids`` (M,) the obstacles' indices, of
    ``rows`` (M, NR) their ``R_*`` columns and of ``outlines`` (M, W, 2) their world rings.  The
    distance to the set (0 inside) and nearest boundary point are those of
    :meth:`ObstacleField.query`; a body whose bounding disc lies beyond ``sensing_range`` [m]
    (with the query's cull margins) is not measured, its distance exceeding the range."""
    slack = 1e-9 * (1.0 + abs(x) + abs(y))
    limit = sensing_range * (1.0 + 1e-9) + slack
    ring = np.empty((2, rings.shape[2]))
    m = 0
    for o in range(n_obs):
        cx, cy = st[S_X, o], st[S_Y, o]
        dx, dy = cx - x, cy - y
        dd = dx * dx + dy * dy
        dc = math.sqrt(dd) if dd < 1e300 else math.hypot(dx, dy)
        if dc * (1.0 - 1e-9) - prm[P_BOUND, o] > limit:
            continue
        h = st[S_HEADING, o]
        _transform_ring(rings, o, math.cos(h), math.sin(h), cx, cy, ring)
        d, qx, qy, inside = ring_nearest_py(x, y, ring[0], ring[1], True)
        if inside:
            d = 0.0
        if d > sensing_range:
            continue
        at = m  # insert after every reading nearer or as near (NaN: after all)
        while at > 0:
            prev = rows[at - 1, R_DIST]
            if not (prev > d or (d == d and prev != prev)):
                break
            at -= 1
        for r in range(m, at, -1):
            ids[r] = ids[r - 1]
            rows[r] = rows[r - 1]
            outlines[r] = outlines[r - 1]
        ids[at] = o
        rows[at, R_DIST], rows[at, R_NEAR], rows[at, R_NEAR + 1] = d, qx, qy
        rows[at, R_CENTRE], rows[at, R_CENTRE + 1] = cx, cy
        rows[at, R_VEL], rows[at, R_VEL + 1] = st[S_VX, o], st[S_VY, o]
        rows[at, R_OMEGA] = st[S_OMEGA, o]
        for j in range(ring.shape[1]):
            outlines[at, j, 0], outlines[at, j, 1] = ring[0, j], ring[1, j]
        m += 1
    return m


def _lidar(
    ox: float,
    oy: float,
    th: float,
    rel: FloatArray,
    max_range: float,
    n_obs: int,
    prm: FloatArray,
    st: FloatArray,
    rings: FloatArray,
    ring: FloatArray,
    dirs: FloatArray,
    out: FloatArray,
) -> None:
    """Ranges [m] of :func:`uvnav.sensors.lidar_scan` (no noise) from pose ``(ox, oy, th)`` in
    one world into ``out`` (R,): beams at ``wrap(th + rel)`` [rad], capped at ``max_range``
    [m] (``ring`` (2, W) and ``dirs`` (2, R): scratch).  A body is cast where
    :meth:`ObstacleField.ray_hits` casts it, and only by the beams that meet its bounding disc
    (the others cannot hit it: the same ranges, far fewer edges)."""
    n_rays = rel.shape[0]
    for r in range(n_rays):
        out[r] = max_range
        a = wrap_scalar(th + rel[r])
        dirs[0, r], dirs[1, r] = math.cos(a), math.sin(a)
    slack = 1e-9 * (1.0 + abs(ox) + abs(oy))
    limit = max_range * (1.0 + 1e-9) + slack
    for o in range(n_obs):
        cx, cy, h = st[S_X, o], st[S_Y, o], st[S_HEADING, o]
        bound = prm[P_BOUND, o]
        if math.hypot(cx - ox, cy - oy) - bound > limit:
            continue  # its hits would be beyond max_range
        reach = bound * (1.0 + 1e-9) + slack
        _transform_ring(rings, o, math.cos(h), math.sin(h), cx, cy, ring)
        for r in range(n_rays):
            dx, dy = dirs[0, r], dirs[1, r]
            # a beam that passes outside the bounding disc, or starts beyond it, cannot hit
            if abs(dx * (cy - oy) - dy * (cx - ox)) > reach:
                continue
            if dx * (cx - ox) + dy * (cy - oy) < -reach:
                continue
            out[r] = min(out[r], ray_ring_hit_py(ox, oy, dx, dy, ring[0], ring[1]))


def vector_one_py(
    x: float,
    y: float,
    th: float,
    goal_x: float,
    goal_y: float,
    goal_scale: float,
    speed: float,
    v_max: float,
    rel: FloatArray,
    max_range: float,
    n_obs: int,
    prm: FloatArray,
    st: FloatArray,
    rings: FloatArray,
    ring: FloatArray,
    dirs: FloatArray,
    ranges: FloatArray,
    out: np.ndarray,
) -> None:
    """One observation vector of ``uvnav/Nav2D-v0`` (:meth:`uvnav.envs.core.EnvWorld.vector`)
    into ``out`` (4 + R,) float32, as :func:`observe_py` writes a world's: from pose ``(x, y,
    th)`` and goal ``(goal_x, goal_y)`` [m], the goal distance / ``goal_scale`` capped at 1, cos
    and sin of the goal bearing in the robot frame, ``speed`` / ``v_max`` in [0, 1], and
    :func:`_lidar`'s ranges [m] (into ``ranges`` (R,); scratch ``ring``, ``dirs``) over
    ``max_range`` in [0, 1]."""
    _lidar(x, y, th, rel, max_range, n_obs, prm, st, rings, ring, dirs, ranges)
    gx, gy = goal_x - x, goal_y - y
    bearing = math.atan2(gy, gx) - th
    out[0] = min(pyhypot(gx, gy) / goal_scale, 1.0)
    out[1] = math.cos(bearing)
    out[2] = math.sin(bearing)
    out[3] = min(max(speed / v_max, 0.0), 1.0)
    for r in range(ranges.shape[0]):
        out[4 + r] = min(max(ranges[r] / max_range, 0.0), 1.0)


def observe_py(
    wf: FloatArray,
    wi: np.ndarray,
    params: FloatArray,
    state: FloatArray,
    rings: FloatArray,
    rel: FloatArray,
    max_range: float,
    goal_scale: float,
    ranges: FloatArray,
    out: np.ndarray,
    dist: FloatArray,
) -> None:
    """``uvnav/Nav2D-v0``'s observation vectors (:meth:`uvnav.envs.core.EnvWorld.vector`) of
    every world into ``out`` (K, 4 + R) float32, their lidar ranges [m] into ``ranges`` (K, R)
    and goal distances [m] into ``dist`` (K,): goal distance / ``goal_scale`` capped at 1, cos
    and sin of the goal bearing in the robot frame, speed / V_max in [0, 1] (0 once arrived or
    collided), ranges / ``max_range`` in [0, 1] (beams at heading + ``rel`` [rad])."""
    ring = np.empty((2, rings.shape[3]))
    dirs = np.empty((2, rel.shape[0]))
    for k in range(wf.shape[0]):
        x, y, th = wf[k, W_X], wf[k, W_Y], wf[k, W_TH]
        dist[k] = pyhypot(wf[k, W_GX] - x, wf[k, W_GY] - y)
        status = wi[k, I_STATUS]
        speed = 0.0 if status in (SUCCESS, COLLISION) else wf[k, W_V]
        vector_one_py(x, y, th, wf[k, W_GX], wf[k, W_GY], goal_scale, speed, wf[k, W_VMAX], rel,
                      max_range, wi[k, I_NOBS], params[k], state[k], rings[k], ring, dirs,
                      ranges[k], out[k])  # fmt: skip


#: the kernels by short name, and everything they call (callees first)
_PUBLIC = {
    "step": "step_worlds_py",
    "observe": "observe_py",
    "advance_one": "advance_one_py",
    "sense_one": "sense_one_py",
    "clearance_one": "clearance_one_py",
    "lidar": "_lidar",
    "vector_one": "vector_one_py",
}
_KERNELS: dict[str, Callable[..., Any]] = {}


def kernel(name: str) -> Callable[..., Any]:
    """A kernel by short name (:data:`_PUBLIC`: ``"step"`` is :func:`step_worlds_py`...),
    compiled by numba on first use when it is enabled (:func:`numba_enabled`), else the Python
    function."""
    if not numba_enabled():
        return globals()[_PUBLIC[name]]
    if not _KERNELS:
        _KERNELS.update(compile_family([
            wrap_scalar, unicycle_advance, pyhypot, ring_nearest_py, ray_ring_hit_py,
            _transform_ring, _move_obstacles, _clearance, _lidar, vector_one_py, step_worlds_py,
            observe_py,
            sense_one_py, advance_one_py, clearance_one_py,
        ]))  # fmt: skip
    return _KERNELS[_PUBLIC[name]]


def pack_check(setup: EpisodeSetup) -> str | None:
    """Why ``setup`` cannot be packed (one line), or None: a unicycle among polygon bodies with
    :class:`ConstantVelocity` or :class:`RandomTurn` motion, each obstacle drawing from its own
    generator (the numbers are pre-drawn per obstacle)."""
    if type(setup.spec) is not UnicycleSpec:
        return f"the robot is a {type(setup.spec).__name__}, packed worlds hold unicycles"
    if setup.spec.kinematics != "arc":
        return f"the robot's kinematics is {setup.spec.kinematics}, packed worlds integrate arcs"
    if not setup.spec.ideal:
        return "the robot has acceleration limits, packed worlds hold ideal unicycles"
    owner: dict[int, int] = {}
    for j, ob in enumerate(setup.obstacles):
        rng = getattr(ob.motion, "rng", None)
        if rng is not None and owner.setdefault(id(rng), j) != j:
            return (
                f"obstacles {owner[id(rng)]} and {j} draw from one generator, packed worlds "
                "pre-draw each obstacle's numbers"
            )
        if not isinstance(ob.body, PolygonBody):
            return f"obstacle {j} is a {type(ob.body).__name__}, packed worlds hold polygons"
        if type(ob.motion) not in (ConstantVelocity, RandomTurn):
            return (
                f"obstacle {j} moves by {type(ob.motion).__name__}, packed worlds hold "
                "constant-velocity and random-turn motion"
            )
    return None


def _random_turn_columns(mod: RandomTurn, state: ObstacleState, st: list[float],
                         prm: list[float]) -> None:  # fmt: skip
    """A random-turn model's state (``S_*``: course, draws, next change) and parameters
    (``P_*``: draw ranges, period, spin, turn limit, arena) into the column lists."""
    st[S_COURSE] = mod.course_at(state)
    st[S_SPEED], st[S_TURN] = mod._speed, mod._turn
    st[S_NEXT] = mod._next_change
    st[S_THRESHOLD] = mod._next_change - 1e-12
    for lo_row, span_row, bounds in (
        (P_SPEED_LO, P_SPEED_SPAN, mod.speed),
        (P_TURN_LO, P_TURN_SPAN, mod.turn_rate),
    ):
        lo = float(bounds[0])
        span = float(bounds[1]) - lo
        if not (math.isfinite(span) and span >= 0.0):
            raise ValueError(f"random-turn bounds {tuple(bounds)} are not (low, high)")
        prm[lo_row], prm[span_row] = lo, span
    prm[P_PERIOD] = float(mod.change_period)
    prm[P_SPIN] = float(mod.spin)
    prm[P_LIMIT] = max(abs(mod.turn_rate[0]), abs(mod.turn_rate[1]))
    if mod.arena is not None:
        x0, y0, x1, y1 = mod.arena
        prm[P_ARENA] = 1.0
        prm[P_X0], prm[P_Y0], prm[P_X1], prm[P_Y1] = x0, y0, x1, y1
        prm[P_MIDX], prm[P_MIDY] = 0.5 * (x0 + x1), 0.5 * (y0 + y1)


class PackedWorlds:
    """``k`` slots of packed worlds (module docstring); :meth:`load` an episode into a slot,
    :meth:`step` the running ones by one decision, :meth:`observe` them.

    The arrays are the state (:func:`step_worlds_py` gives their layout; :attr:`robot`,
    :attr:`command`, :attr:`status`... are views of them).  A slot's random-turn obstacles keep
    their generators, read ahead by up to a row of pre-drawn numbers (:data:`ROW_BLOCKS` x
    :data:`BLOCK`, more where a decision has over :data:`BLOCK` integration steps): the models
    are not written back (unlike :meth:`World2D.close
    <uvnav.sim.episode.World2D.close>`).
    """

    oi: np.ndarray
    #: (k, M) numbers of each obstacle's generator read before its row's last top-up (with
    #: ``oi[:, O_UPOS]``: the numbers its draws have consumed)
    read: np.ndarray
    params: FloatArray
    state: FloatArray
    ubuf: FloatArray
    rings: FloatArray

    def __init__(self, k: int) -> None:
        self.k = int(k)
        self.wf = np.zeros((k, NW))
        self.wi = np.zeros((k, NI), dtype=np.int64)
        self.wi[:, I_STATUS] = TIMEOUT
        self.wi[:, I_ACTIVE] = 1
        self.wf[:, W_CLEAR] = self.wf[:, W_LOW] = math.inf
        self.rngs: list[list[np.random.Generator | None]] = [[] for _ in range(k)]
        self.safe_calls = 0  # step() calls before a refill may be needed
        self._templates: dict[tuple[int, ...], tuple[FieldTemplate, list[Any]]] = {}
        self._alloc(0, 2, ROW_BLOCKS * BLOCK)

    # views of the state, by meaning
    @property
    def robot(self) -> FloatArray:
        """(k, 3) poses ``(x, y, theta)`` [m, m, rad]."""
        return self.wf[:, W_X : W_TH + 1]

    @property
    def command(self) -> FloatArray:
        """(k, 2) held commands ``(v, u)`` [m/s, rad/s], used as given (saturate them first)."""
        return self.wf[:, W_V : W_U + 1]

    @property
    def limits(self) -> FloatArray:
        """(k, 2) ``(V_max [m/s], U_max [rad/s])``."""
        return self.wf[:, W_VMAX : W_UMAX + 1]

    @property
    def clearance(self) -> FloatArray:
        """(k,) exact clearance after the last step [m] (``inf`` without obstacles)."""
        return self.wf[:, W_CLEAR]

    @property
    def low(self) -> FloatArray:
        """(k,) lowest clearance over the last :meth:`step` [m] (``inf`` where none ran)."""
        return self.wf[:, W_LOW]

    @property
    def status(self) -> np.ndarray:
        """(k,) status codes (:data:`STATUS_NAMES`)."""
        return self.wi[:, I_STATUS]

    @property
    def time(self) -> FloatArray:
        """(k,) simulated time [s] (step index x dt, as the loop world counts it)."""
        return self.wi[:, I_STEP] * self.wf[:, W_DT]

    def _alloc(self, m: int, w: int, b: int) -> None:
        """(Re)allocate the obstacle arrays for ``m`` obstacles of ``w``-column rings and ``b``
        pre-drawn numbers, keeping what the slots hold (the unread numbers move to the end of
        the longer rows, the next top-up fills the rest)."""
        k = self.k
        oi = np.zeros((k, 2, m), dtype=np.int64)
        oi[:, O_KIND] = EMPTY
        read = np.zeros((k, m), dtype=np.int64)
        params = np.zeros((k, N_PARAMS, m))
        state = np.zeros((k, N_STATE, m))
        ubuf = np.zeros((k, m, b))
        rings = np.zeros((k, 2, m, w))
        if hasattr(self, "oi"):
            m0, w0, b0 = self.rings.shape[2], self.rings.shape[3], self.ubuf.shape[2]
            oi[:, :, :m0] = self.oi
            moved = np.where(self.oi[:, O_KIND] == RANDOM_TURN, b - b0, 0)
            oi[:, O_UPOS, :m0] += moved
            read[:, :m0] = self.read - moved  # read + next unread: the numbers consumed
            params[:, :, :m0] = self.params
            state[:, :, :m0] = self.state
            ubuf[:, :m0, b - b0 :] = self.ubuf
            rings[:, :, :m0, :w0] = self.rings
            rings[:, :, :m0, w0:] = self.rings[:, :, :, :1]  # more copies of the first vertex
        self.oi, self.params, self.state, self.ubuf, self.rings = oi, params, state, ubuf, rings
        self.read = read

    def load(self, slot: int, setup: EpisodeSetup) -> None:
        """Put ``setup``'s episode in ``slot`` as :meth:`World2D.start
        <uvnav.sim.episode.World2D.start>` begins it (status and clearance at t = 0).

        Raises:
            ValueError: the episode cannot be packed (:func:`pack_check`).
        """
        why = pack_check(setup)
        if why is not None:
            raise ValueError(why)
        obstacles = setup.obstacles
        m = len(obstacles)
        tpl = self._template([o.body for o in obstacles])
        spec, dt = setup.spec, float(setup.dt)
        ratio = decision_ratio(float(setup.control_period), dt)
        b = max(self.ubuf.shape[2], 4 * ratio)  # half a row: a decision's draws, 2 a step
        self.load_obstacles(slot, obstacles, tpl, b)
        x, y, th = (float(c) for c in np.asarray(setup.start, dtype=float)[:3])
        gx, gy = (float(c) for c in np.asarray(setup.goal, dtype=float)[:2])
        wf, wi = self.wf[slot], self.wi[slot]
        wf[:] = 0.0
        wf[[W_X, W_Y, W_TH, W_GX, W_GY]] = (x, y, th, gx, gy)
        wf[[W_RADIUS, W_TOL, W_DT]] = (float(spec.radius), float(setup.goal_tolerance), dt)
        wf[[W_VMAX, W_UMAX]] = (float(spec.v_max), float(spec.u_max))
        n_steps = step_count(float(setup.t_max), dt)
        wi[[I_STEP, I_RATIO, I_NSTEPS, I_NOBS]] = (0, ratio, n_steps, m)
        # at t = 0 as World2D.start measures it (the field's query), from the slot
        gap = float(kernel("clearance_one")(x, y, float(spec.radius), m, self.params[slot],
                                            self.state[slot], self.rings[slot])[0])  # fmt: skip
        wf[W_CLEAR], wf[W_LOW] = gap, math.inf
        status = RUNNING
        if gap < 0:
            status = COLLISION
        elif math.hypot(gx - x, gy - y) <= setup.goal_tolerance:
            status = SUCCESS
        wi[I_STATUS] = status
        # the slot's rows are full: a top-up is due no sooner for it than for the others
        self.safe_calls = min(self.safe_calls, b // (2 * ratio))

    def load_obstacles(self, slot: int, obstacles: list[Obstacle], tpl: FieldTemplate,
                       b: int) -> None:  # fmt: skip
        """Put ``obstacles`` (packable: :func:`pack_check`; ``tpl`` their bodies' template) in
        ``slot``, growing the arrays to hold them and ``b`` pre-drawn numbers a row."""
        m = len(obstacles)
        w = tpl.rings.shape[2] if m else 2
        if m > self.rings.shape[2] or w > self.rings.shape[3] or b > self.ubuf.shape[2]:
            self._alloc(max(m, self.rings.shape[2]), max(w, self.rings.shape[3]), b)
        self.wi[slot, I_NOBS] = m
        self.oi[slot, O_KIND] = EMPTY
        self.oi[slot, O_UPOS] = 0
        self.read[slot] = 0
        self.rings[slot] = 0.0
        if m:
            self.rings[slot, :, :m, :w] = tpl.rings
            self.rings[slot, :, :m, w:] = tpl.rings[:, :, :1]
        self.rngs[slot] = [self._pack_obstacle(slot, o, ob) for o, ob in enumerate(obstacles)]
        self.params[slot, P_BOUND, :m] = tpl.bounding_radii

    def _template(self, bodies: list[Any]) -> FieldTemplate:
        """The bodies' packed geometry, kept for the episodes that share the body objects (the
        scenario's, see :meth:`BodySpec.to_body <uvnav.scenarios.schema.BodySpec.to_body>`)."""
        key = tuple(map(id, bodies))
        hit = self._templates.get(key)
        if hit is None:
            if len(self._templates) >= 64:
                self._templates.clear()
            hit = self._templates[key] = (FieldTemplate.from_bodies(bodies), bodies)
        return hit[0]

    def _pack_obstacle(self, slot: int, o: int, ob: Obstacle) -> np.random.Generator | None:
        """Obstacle ``o`` of ``slot``: its state, parameters and first block of draws; its
        generator (None for constant motion).  The columns are filled as lists and stored in one
        assignment each (a reset of the batched env packs every obstacle of its scene)."""
        mod, state = ob.motion, ob.state
        st, prm = [0.0] * N_STATE, [0.0] * N_PARAMS
        st[S_X], st[S_Y] = np.asarray(state.position, dtype=float).tolist()
        st[S_HEADING] = state.heading
        st[S_VX], st[S_VY] = np.asarray(state.velocity, dtype=float).tolist()
        st[S_OMEGA] = state.angular_velocity
        rng: np.random.Generator | None = None
        if isinstance(mod, ConstantVelocity):
            kind = CONSTANT
            prm[P_VX], prm[P_VY] = np.asarray(mod.velocity, dtype=float).tolist()
            prm[P_OMEGA] = float(mod.angular_velocity)
        else:
            assert isinstance(mod, RandomTurn)
            kind, rng = RANDOM_TURN, mod.rng
            _random_turn_columns(mod, state, st, prm)
        self.oi[slot, :, o] = (kind, 0)
        self.state[slot, :, o], self.params[slot, :, o] = st, prm
        if rng is not None:
            rng.random(out=self.ubuf[slot, o])
        return rng

    def refill(self) -> None:
        """Top up the draws of every obstacle that has read half its row or more: the unread
        ones move to the front, the rest are drawn.  Sets how many :meth:`step` calls are safe
        before the next top-up (a decision reads at most two numbers per integration step, and
        half a row holds a decision's worth: :meth:`load` sizes the rows).

        :meth:`step` calls it only when a row could run out in the next call (the step kernel
        counts the safe calls), and then every half-read row is topped up, so top-ups are rare
        and draw many numbers each: topping up one-block rows whenever one could run out cost
        1.2 (10 obstacles) and 1.8 µs (100) of a world step in
        ``benchmarks/peers/irsim_steps.py``, about 0.1 and 0.2 µs now (mostly the
        generators' calls).
        """
        b = self.ubuf.shape[2]
        upos = self.oi[:, O_UPOS]
        due = (upos >= b // 2).nonzero()
        for slot, o, p in zip(due[0].tolist(), due[1].tolist(), upos[due].tolist(), strict=True):
            rng = self.rngs[slot][o]
            if rng is not None:
                row = self.ubuf[slot, o]
                row[: b - p] = row[p:]
                rng.random(out=row[b - p :])
        self.read[due] += upos[due]
        upos[due] = 0  # (a row without a generator is never read)
        spare = (b - upos) // np.maximum(2 * self.wi[:, I_RATIO, None], 1)
        self.safe_calls = int(spare.min()) if spare.size else 1 << 30

    def ensure_draws(self) -> None:
        """Top up the rows (:meth:`refill`) when the next call could run one out, and count that
        call: :meth:`step`'s rule, for a caller that steps the slots' arrays itself (one
        integration step a call, as :class:`~uvnav.sim.bodies2d.PackedBodies` does)."""
        if self.safe_calls <= 0:
            self.refill()
        self.safe_calls -= 1

    def step(self, active: np.ndarray | None = None) -> None:
        """Advance every running world (of the ``active`` (k,) bool slots) by one decision with
        the commands in :attr:`command`."""
        if active is not None:
            self.wi[:, I_ACTIVE] = active
        self.ensure_draws()  # its count is replaced by the kernel's, which knows the rows read
        self.safe_calls = kernel("step")(
            self.wf, self.wi, self.oi, self.params, self.state, self.ubuf, self.rings
        )
        if active is not None:
            self.wi[:, I_ACTIVE] = 1

    def observe(self, rel: FloatArray, max_range: float, goal_scale: float, ranges: FloatArray,
                out: np.ndarray, dist: FloatArray) -> None:  # fmt: skip
        """:func:`observe_py` on every slot (lidar beams at heading + ``rel`` [rad])."""
        kernel("observe")(self.wf, self.wi, self.params, self.state, self.rings, rel,
                          float(max_range), float(goal_scale), ranges, out, dist)  # fmt: skip
