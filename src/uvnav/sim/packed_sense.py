"""The compiled sensing kernels of :mod:`uvnav.sim.packed`: the exact readings of one world,
the lidar cast and ``uvnav/Nav2D-v0``'s observation vectors.

Each function here is plain Python that numba compiles (:func:`uvnav.sim.packed.kernel`); the
numbers are those of :func:`uvnav.sensors.exact.sense_obstacles` and
:func:`uvnav.sensors.lidar_scan`, bit for bit.
"""

from __future__ import annotations

import math

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.polygons import ring_nearest_py
from uvnav.geometry.small import pyhypot
from uvnav.sim.packed_kernels import (
    COLLISION,
    I_ACTIVE,
    I_NOBS,
    I_STATUS,
    P_BOUND,
    S_HEADING,
    S_OMEGA,
    S_VX,
    S_VY,
    S_X,
    S_Y,
    SUCCESS,
    TIMEOUT,
    W_GX,
    W_GY,
    W_LOW,
    W_TH,
    W_U,
    W_UMAX,
    W_V,
    W_VMAX,
    W_X,
    W_Y,
    _clearance,
    _move_obstacles,
    _transform_ring,
    step_worlds_py,
)

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


def _lidar_in(k: int, ox: float, oy: float, th: float, turns: FloatArray, max_range: float,
              n_obs: int, params: FloatArray, state: FloatArray, rings: FloatArray,
              ring: FloatArray, dirs: FloatArray, ranges: FloatArray) -> None:  # fmt: skip
    """:func:`_lidar` of world ``k`` of the packed arrays ``params``, ``state``, ``rings``
    (:func:`step_worlds_py`'s layout) into ``ranges[k]``, indexing them here: slicing them per
    world and passing the slices cost more than a tenth of the cast."""
    ct, st = math.cos(th), math.sin(th)
    for r in range(turns.shape[1]):
        ranges[k, r] = max_range
        cr, sr = turns[0, r], turns[1, r]
        dirs[0, r], dirs[1, r] = ct * cr - st * sr, st * cr + ct * sr
    slack = 1e-9 * (1.0 + abs(ox) + abs(oy))
    limit = max_range * (1.0 + 1e-9) + slack
    for o in range(n_obs):
        cx, cy, h = state[k, S_X, o], state[k, S_Y, o], state[k, S_HEADING, o]
        bound = params[k, P_BOUND, o]
        ex, ey = cx - ox, cy - oy
        dc = math.sqrt(ex * ex + ey * ey)
        if abs(dc - bound - limit) <= 1e-12 * (1.0 + dc + bound + limit) or not dc < 1e300:
            dc = math.hypot(cx - ox, cy - oy)  # near the edge, huge or not a number: libm's
        if dc - bound > limit:
            continue  # its hits would be beyond max_range
        reach = bound * (1.0 + 1e-9) + slack
        cast = False
        for r in range(turns.shape[1]):
            dx, dy = dirs[0, r], dirs[1, r]
            # a beam that passes outside the bounding disc, or starts beyond it, cannot hit
            if abs(dx * ey - dy * ex) > reach or dx * ex + dy * ey < -reach:
                continue
            if not cast:  # _transform_ring's operations, inlined (as the loop below)
                ch, sh = math.cos(h), math.sin(h)
                for j in range(ring.shape[1]):
                    rx, ry = rings[k, 0, o, j], rings[k, 1, o, j]
                    ring[0, j] = ch * rx + sh * -ry + cx
                    ring[1, j] = ch * ry + sh * rx + cy
                cast = True
            best = ranges[k, r]  # rays_rings_hit's test for one ray and one ring, as a loop
            for j in range(ring.shape[1] - 1):
                sx, sy = ring[0, j], ring[1, j]
                qx, qy = ring[0, j + 1] - sx, ring[1, j + 1] - sy
                wx, wy = sx - ox, sy - oy
                den = dx * qy - dy * qx
                if abs(den) >= 1e-12:
                    t = (wx * qy - wy * qx) / den
                    s = (wx * dy - wy * dx) / den
                    if t >= 0.0 and s >= 0.0 and s <= 1.0 and t < best:
                        best = t
            ranges[k, r] = best


def _lidar(
    ox: float,
    oy: float,
    th: float,
    turns: FloatArray,
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
    one world into ``out`` (R,): beams along :func:`~uvnav.sensors.exact.beam_directions`, the
    offsets' rotations ``turns`` (2, R) (:func:`~uvnav.sensors.exact.beam_turns`) turned by
    libm's cos and sin of ``th``, capped at ``max_range`` [m] (``ring`` (2, W) and ``dirs`` (2,
    R): scratch).  A body is cast where :meth:`ObstacleField.ray_hits` casts it, and only by
    the beams that meet its bounding disc (the others cannot hit it: the same ranges, far fewer
    edges).

    A body's centre distance is taken by ``sqrt`` (libm's ``hypot`` only where the two could
    decide differently), and a beam's bounding-disc test has a relative margin of 1e-9 over the
    body's bounding radius.  The ring's transform (:func:`_transform_ring`) and the ray-ring
    test (:func:`uvnav.geometry.polygons.rays_rings_hit`'s) are their operations written out
    in the loop, where calls that passed array rows cost more than the arithmetic.  The beams
    are fixed in the sensor's frame and turned once a scan: two libm calls a scan, where a beam
    at its own angle took a cos and a sin for every beam that met a body's disc (about a fifth
    of ``uvnav/Nav2D-v0``'s batched observation).  (Skipping an edge's two divisions by its
    numerators' signs first made a stepping env's observation slower: their branches
    mispredict.)"""
    _lidar_in(0, ox, oy, th, turns, max_range, n_obs, prm[None], st[None], rings[None], ring,
              dirs, out[None])  # fmt: skip


def vector_one_py(
    x: float,
    y: float,
    th: float,
    goal_x: float,
    goal_y: float,
    goal_scale: float,
    speed: float,
    v_max: float,
    turns: FloatArray,
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
    :func:`_lidar`'s ranges [m] (beams at ``turns``; into ``ranges`` (R,); scratch ``ring``,
    ``dirs``) over ``max_range`` in [0, 1]."""
    _lidar(x, y, th, turns, max_range, n_obs, prm, st, rings, ring, dirs, ranges)
    _features(0, x, y, th, goal_x, goal_y, goal_scale, speed, v_max, max_range, ranges[None],
              out[None])  # fmt: skip


def _features(k: int, x: float, y: float, th: float, goal_x: float, goal_y: float,
              goal_scale: float, speed: float, v_max: float, max_range: float,
              ranges: FloatArray, out: np.ndarray) -> None:  # fmt: skip
    """Row ``k`` of the observation vectors ``out`` (K, 4 + R) float32 (:func:`vector_one_py`'s)
    from the pose, goal, speed and the lidar ranges ``ranges[k]`` [m]."""
    gx, gy = goal_x - x, goal_y - y
    bearing = math.atan2(gy, gx) - th
    out[k, 0] = min(pyhypot(gx, gy) / goal_scale, 1.0)
    out[k, 1] = math.cos(bearing)
    out[k, 2] = math.sin(bearing)
    out[k, 3] = min(max(speed / v_max, 0.0), 1.0)
    for r in range(ranges.shape[1]):
        out[k, 4 + r] = min(max(ranges[k, r] / max_range, 0.0), 1.0)


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
    turns = np.empty((2, rel.shape[0]))  # beam_turns(rel), for every world
    for r in range(rel.shape[0]):
        turns[0, r], turns[1, r] = math.cos(rel[r]), math.sin(rel[r])
    for k in range(wf.shape[0]):
        x, y, th = wf[k, W_X], wf[k, W_Y], wf[k, W_TH]
        gx, gy = wf[k, W_GX] - x, wf[k, W_GY] - y
        dist[k] = d = pyhypot(gx, gy)
        status = wi[k, I_STATUS]
        speed = 0.0 if status in (SUCCESS, COLLISION) else wf[k, W_V]
        _lidar_in(k, x, y, th, turns, max_range, wi[k, I_NOBS], params, state, rings, ring,
                  dirs, ranges)  # fmt: skip
        # _features' operations, written out (the distance computed once)
        bearing = math.atan2(gy, gx) - th
        out[k, 0] = min(d / goal_scale, 1.0)
        out[k, 1] = math.cos(bearing)
        out[k, 2] = math.sin(bearing)
        out[k, 3] = min(max(speed / wf[k, W_VMAX], 0.0), 1.0)
        for r in range(rel.shape[0]):
            out[k, 4 + r] = min(max(ranges[k, r] / max_range, 0.0), 1.0)


def commands_py(actions: FloatArray, restart: np.ndarray, wf: FloatArray, wi: np.ndarray,
                running: np.ndarray) -> None:  # fmt: skip
    """``uvnav/Nav2D-v0``'s normalised ``actions`` (K, 2) (finite) to held commands of the worlds
    that act: :func:`uvnav.envs.core.action_commands` (clipped to [-1, 1], mapped onto [0,
    V_max] x [-U_max, U_max]) then :meth:`UnicycleCommand.clipped
    <uvnav.dynamics.unicycle.UnicycleCommand.clipped>`'s saturation, numpy's operations per
    world.  ``running[k]`` says whether world ``k`` steps from a running state (not
    ``restart[k]``, not arrived or collided); it acts unless it also timed out."""
    for k in range(wf.shape[0]):
        status = wi[k, I_STATUS]
        running[k] = not restart[k] and status != SUCCESS and status != COLLISION
        if not running[k] or status == TIMEOUT:
            continue
        vmax, umax = wf[k, W_VMAX], wf[k, W_UMAX]
        a0 = min(max(actions[k, 0], -1.0), 1.0)
        a1 = min(max(actions[k, 1], -1.0), 1.0)
        v = 0.5 * (a0 + 1.0) * vmax
        u = a1 * umax
        wf[k, W_V] = min(max(v, 0.0), vmax)
        wf[k, W_U] = min(max(u, -umax), umax)


def outcome_py(status: np.ndarray, low: FloatArray, restart: np.ndarray, running: np.ndarray,
               before: FloatArray, dist: FloatArray, clear: FloatArray, weights: FloatArray,
               rewards: FloatArray, terminated: np.ndarray,
               truncated: np.ndarray) -> None:  # fmt: skip
    """``uvnav/Nav2D-v0``'s rewards, terminations and truncations of K worlds after a step (the
    operations of :meth:`uvnav.envs.core.EnvWorld.reward` on each): from the worlds' status
    codes and lowest clearances ``low`` [m] over the step, the (K,) bools ``restart`` (the world
    restarted instead of stepping) and ``running`` (it stepped from a running state), goal
    distances ``before`` and ``dist`` [m] and the reward's ``weights`` (progress, time,
    clearance, clearance margin, success, collision).  ``clear`` [m] takes ``low`` where the
    world ran and ``low`` is finite, and is the clearance the penalty reads."""
    progress, time_cost, clearance, margin = weights[0], weights[1], weights[2], weights[3]
    success, collision = weights[4], weights[5]
    for k in range(status.shape[0]):
        if running[k] and abs(low[k]) < math.inf:
            clear[k] = low[k]
        s = status[k]
        r = progress * (before[k] - dist[k]) - time_cost
        gap = margin - clear[k]
        r = r - clearance * (0.0 if gap <= 0.0 else gap)  # numpy's maximum(0.0, gap)
        if s == SUCCESS:
            r = r + success
        if s == COLLISION:
            r = r - collision
        rewards[k] = r if running[k] else 0.0
        terminated[k] = not restart[k] and s in (SUCCESS, COLLISION)
        truncated[k] = not restart[k] and s == TIMEOUT


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
    _move_obstacles(0, n_obs, st[None], prm[None], oi[None], ubuf[None], t, dt)
    shift = 0.0
    for o in range(n_obs):
        dx, dy = st[S_X, o] - prev[0, o], st[S_Y, o] - prev[1, o]
        turn = abs(st[S_HEADING, o] - prev[2, o])
        if turn > math.pi:  # (headings are wrapped)
            turn = 2.0 * math.pi - turn
        s = math.sqrt(dx * dx + dy * dy) + turn * prm[P_BOUND, o]
        if s > shift:
            shift = s
    gap, at = _clearance(0, x, y, radius, n_obs, prm[None], st[None], rings[None], ring, low)
    m = -1
    if sensing_range >= 0.0:
        m = sense_one_py(x, y, sensing_range, n_obs, prm, st, rings, ids, rows, outlines)
    return gap, at, m, shift


def vector_step_py(actions: FloatArray, restart: np.ndarray, raw: bool, wf: FloatArray,
                   wi: np.ndarray, oi: np.ndarray, params: FloatArray, state: FloatArray,
                   ubuf: FloatArray, rings: FloatArray, rel: FloatArray, max_range: float,
                   goal_scale: float, ranges: FloatArray, out: np.ndarray, dist: FloatArray,
                   clear: FloatArray, weights: FloatArray, rewards: FloatArray,
                   terminated: np.ndarray, truncated: np.ndarray) -> int:  # fmt: skip
    """One step of ``uvnav/Nav2D-v0``'s batched env in one call: the held commands from the
    normalised ``actions`` (:func:`commands_py`; with ``raw`` the caller has set them and only
    which worlds run is worked out), every world not restarting (``restart`` (K,) bool) advanced
    by one decision (:func:`step_worlds_py`), the observation vectors, lidar ranges and goal
    distances (:func:`observe_py`), then the rewards, terminations and truncations
    (:func:`outcome_py`, from the goal distances before and after).  Returns
    :func:`step_worlds_py`'s count of calls the pre-drawn numbers cover."""
    k_all = wf.shape[0]
    running = np.empty(k_all, dtype=np.bool_)
    if raw:
        for k in range(k_all):
            s = wi[k, I_STATUS]
            running[k] = not restart[k] and s != SUCCESS and s != COLLISION
    else:
        commands_py(actions, restart, wf, wi, running)
    before = dist.copy()
    for k in range(k_all):
        wi[k, I_ACTIVE] = 0 if restart[k] else 1
    safe = step_worlds_py(wf, wi, oi, params, state, ubuf, rings)
    for k in range(k_all):
        wi[k, I_ACTIVE] = 1
    observe_py(wf, wi, params, state, rings, rel, max_range, goal_scale, ranges, out, dist)
    outcome_py(wi[:, I_STATUS], wf[:, W_LOW], restart, running, before, dist, clear, weights,
               rewards, terminated, truncated)  # fmt: skip
    return safe
