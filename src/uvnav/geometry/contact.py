"""First contact and closest approach of a moving disc among moving discs, for many candidate
velocities at once (the candidate check of ``zhang2019-v2``, :mod:`uvnav.controllers.zhang2019_v2`).

A candidate k is a motion of the robot in two phases: velocity ``turn[k]`` for ``tau[k]`` seconds,
then ``cand[k]`` (a holonomic robot: ``tau = 0``).  A boundary disc j (centre ``q[j]``, velocity
``w[j]``, radius sum ``reach[j]`` with the robot) moves at constant velocity.  Per candidate:

* ``ttc[k]``: the first time in [0, horizon] at which the robot is within ``reach`` of any disc
  (0 for a pair already in contact and closing; inf when none);
* ``pen[k]``: the largest ``comfort - gap`` (clipped at 0) over the discs moving at
  ``min_speed`` or faster, ``gap`` the smallest distance beyond ``reach`` over
  [0, comfort_horizon] while moving at ``turn[k]`` (a disc standing still is kept clear of, not
  at a comfort distance: people standing at or beside the goal would otherwise hold the robot
  off it for good);
* ``soc[k]`` (the social term, :func:`social_risk`): the largest ``reach + band - g`` (clipped at
  0) over the *moving* discs, ``g`` the smallest distance between the robot, along the candidate
  over its first T_s seconds, and the disc's constant-velocity forecast over the next S seconds
  as it will be then (the segment ``q + w t .. q + w (t + S)`` at time t): 0 when the robot stays
  ``band`` clear of where the body will walk, up to ``reach + band`` when its path crosses that
  (passing in front of a walking person).  In the body's frame the forecast seen along a straight
  stretch of the path is a parallelogram (:func:`forecast_gap`), so ``g`` is in closed form.

:func:`candidate_risk` is the numpy reference (arrays K x M); with numba installed (the ``fast``
extra) :func:`candidate_risk_compiled` runs one compiled loop that first tests each body's
bounding disc (``bodies``: index ranges of its discs, centre, velocity and reach), skipping bodies
no candidate comes near — the same numbers (tests compare the two to 1e-12), at a fraction of
the cost with 100 bodies.  :func:`decide_compiled` goes one step further for ``zhang2019-v2``:
the candidates, their costs and the choice in the same loop, branch-and-bound (:func:`decide_py`).
Units: metres, seconds.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.kernels3d import compile_family, numba_enabled

#: integer arrays (indices)
IntArray = np.ndarray


#: the forecast circles the tangents touch are the contact discs grown by this share: a tangent
#: to a standing body's disc grazes it, and whether a contact exactly at the tangent point
#: counts would be decided by rounding, differently in numpy and in the compiled loops; grown,
#: the tangent clears the disc by about a nanometre in both
TANGENT_SLACK = 1e-9


def first_contact(
    rel_pos: FloatArray,
    rel_vel: FloatArray,
    reach: FloatArray,
    horizon: float | FloatArray,
    margin: float = 0.0,
) -> FloatArray:
    """First time [s] in [0, horizon] at which ``|rel_pos - rel_vel t| <= reach``; inf if never.

    ``rel_pos`` (..., 2): a body relative to the robot; ``rel_vel`` (..., 2): the robot's velocity
    relative to the body; ``reach``: the radius sum (broadcast).  A pair already in contact reads 0
    while it closes in and inf while it opens.  With a ``margin`` [m] (``reach`` = the bodies'
    radius sum + ``margin``), a pair already within ``reach`` and closing reads its first contact
    with ``reach - margin`` instead (the bodies themselves touching), 0 when that too is reached:
    inside the margin, candidates are told apart by how soon they would really touch.

    >>> first_contact(np.array([2.0, 0.0]), np.array([1.0, 0.0]), np.array(1.0), 5.0).item()
    1.0
    >>> first_contact(np.array([2.0, 0.0]), np.array([-1.0, 0.0]), np.array(1.0), 5.0).item()
    inf
    >>> first_contact(np.array([0.5, 0.0]), np.array([1.0, 0.0]), np.array(1.0), 5.0).item()
    0.0
    >>> first_contact(np.array([0.875, 0.0]), np.array([0.5, 0.0]), np.array(1.0), 5.0, 0.25).item()
    0.25
    """
    a = np.einsum("...i,...i->...", rel_vel, rel_vel)
    b = np.einsum("...i,...i->...", rel_pos, rel_vel)
    pp = np.einsum("...i,...i->...", rel_pos, rel_pos)
    c = pp - reach * reach
    out = _roots(a, b, c, horizon)
    if margin > 0.0:
        inner = reach - margin
        out = np.where((c <= 0.0) & (b > 0.0), _roots(a, b, pp - inner * inner, horizon), out)
    return np.asarray(out, dtype=float)


def _roots(a: FloatArray, b: FloatArray, c: FloatArray, horizon: float | FloatArray) -> FloatArray:
    """First root in [0, horizon] of ``a t^2 - 2 b t + c`` (0 when ``c <= 0`` and closing, inf
    when ``c <= 0`` and opening, or no root)."""
    disc = b * b - a * c
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (b - np.sqrt(np.maximum(disc, 0.0))) / a
    hit = (disc >= 0.0) & (b > 0.0) & (a > 1e-12) & (t <= horizon)
    out = np.where(hit, np.maximum(t, 0.0), np.inf)
    return np.asarray(np.where(c <= 0.0, np.where(b > 0.0, 0.0, np.inf), out), dtype=float)


def closest_gap(
    rel_pos: FloatArray, rel_vel: FloatArray, reach: FloatArray, horizon: float
) -> FloatArray:
    """Smallest ``|rel_pos - rel_vel t| - reach`` over t in [0, horizon] [m] (negative: overlap).

    >>> closest_gap(np.array([2.0, 1.0]), np.array([1.0, 0.0]), np.array(0.5), 5.0).item()
    0.5
    """
    a = np.einsum("...i,...i->...", rel_vel, rel_vel)
    b = np.einsum("...i,...i->...", rel_pos, rel_vel)
    t = np.clip(b / np.maximum(a, 1e-12), 0.0, horizon)
    gap = rel_pos - rel_vel * t[..., None]
    return np.asarray(np.hypot(gap[..., 0], gap[..., 1]) - reach, dtype=float)


def candidate_risk(
    position: FloatArray,
    cand: FloatArray,
    turn: FloatArray,
    tau: FloatArray,
    discs: tuple[FloatArray, FloatArray, FloatArray],
    horizon: float,
    comfort: float,
    comfort_horizon: float,
    margin: float = 0.0,
    min_speed: float = 0.0,
) -> tuple[FloatArray, FloatArray]:
    """``(ttc, pen)`` per candidate (module docstring), numpy over K x M; ``margin``: that of
    :func:`first_contact`; ``min_speed`` [m/s]: the slowest disc kept at the comfort distance."""
    q, w, reach = discs
    if not len(q):
        return np.full(len(cand), np.inf), np.zeros(len(cand))
    rel = (q - position)[None, :, :]
    r = reach[None, :]
    turn_rel = turn[:, None, :] - w[None, :, :]
    t1 = first_contact(rel, turn_rel, r, tau[:, None], margin)
    rel2 = rel - turn_rel * tau[:, None, None]
    t2 = first_contact(rel2, cand[:, None, :] - w[None, :, :], r, (horizon - tau)[:, None], margin)
    ttc = np.minimum(t1, tau[:, None] + t2).min(axis=1)
    gap = closest_gap(rel, turn_rel, r, comfort_horizon)
    walks = w[:, 0] * w[:, 0] + w[:, 1] * w[:, 1] >= min_speed * min_speed
    pen = np.clip(np.where(walks[None, :], comfort - gap, 0.0), 0.0, None).max(axis=1)
    return ttc, pen


def forecast_gap(d: FloatArray, u: FloatArray, e: FloatArray) -> FloatArray:
    """Distance [m] from the origin to the parallelogram ``d + alpha u + beta e`` (alpha, beta
    in [0, 1]), elementwise over (..., 2); 0 when the origin lies in it.

    With ``d`` a body relative to the robot, ``u`` its relative displacement over a stretch of
    the robot's path and ``e`` the body's displacement over the forecast time, the parallelogram
    holds every point of the body's forecast (module docstring, ``soc``) seen from the robot
    along that stretch.

    >>> forecast_gap(np.array([2.0, -1.0]), np.array([0.0, 2.0]), np.array([1.0, 0.0])).item()
    2.0
    >>> forecast_gap(np.array([-1.0, -1.0]), np.array([0.0, 2.0]), np.array([2.0, 0.0])).item()
    0.0
    """
    c = u[..., 0] * e[..., 1] - u[..., 1] * e[..., 0]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        alpha = -(d[..., 0] * e[..., 1] - d[..., 1] * e[..., 0]) / c
        beta = (d[..., 0] * u[..., 1] - d[..., 1] * u[..., 0]) / c
    inside = (np.abs(c) > 1e-12) & (alpha >= 0.0) & (alpha <= 1.0) & (beta >= 0.0) & (beta <= 1.0)
    edges = np.minimum(
        np.minimum(_edge_gap(d, u), _edge_gap(d + e, u)),
        np.minimum(_edge_gap(d, e), _edge_gap(d + u, e)),
    )
    return np.asarray(np.where(inside, 0.0, edges), dtype=float)


def _edge_gap(a: FloatArray, e: FloatArray) -> FloatArray:
    """Distance [m] from the origin to the segment ``a + s e``, s in [0, 1], elementwise."""
    ee = e[..., 0] * e[..., 0] + e[..., 1] * e[..., 1]
    s = np.clip(-(a[..., 0] * e[..., 0] + a[..., 1] * e[..., 1]) / np.maximum(ee, 1e-12), 0.0, 1.0)
    return np.asarray(np.hypot(a[..., 0] + s * e[..., 0], a[..., 1] + s * e[..., 1]), dtype=float)


def social_risk(
    position: FloatArray,
    cand: FloatArray,
    turn: FloatArray,
    tau: FloatArray,
    discs: tuple[FloatArray, FloatArray, FloatArray],
    social: tuple[float, float, float],
) -> FloatArray:
    """``soc`` per candidate (module docstring), numpy over K x M; ``social``: the robot's path
    time T_s [s], the forecast time S [s] and the band [m]."""
    q, w, reach = discs
    span, forecast, band = social
    if not len(q):
        return np.zeros(len(cand))
    d0 = (q - position)[None, :, :]
    t1 = np.minimum(tau, span)[:, None, None]
    t2 = span - t1
    e = (w * forecast)[None, :, :]
    a1 = w[None, :, :] - turn[:, None, :]
    g1 = forecast_gap(d0, a1 * t1, e)
    d1 = d0 + a1 * t1
    g2 = forecast_gap(d1, (w[None, :, :] - cand[:, None, :]) * t2, e)
    pen = reach[None, :] + band - np.minimum(g1, g2)
    moving = (w[:, 0] != 0.0) | (w[:, 1] != 0.0)
    return np.asarray(np.clip(np.where(moving[None, :], pen, 0.0), 0.0, None).max(axis=1))


# -- the compiled path ------------------------------------------------------------------------


def _contact_scalar(
    px: float, py: float, vx: float, vy: float, reach: float, h: float, margin: float
) -> float:
    """:func:`first_contact` for one pair, on floats."""
    a = vx * vx + vy * vy
    b = px * vx + py * vy
    pp = px * px + py * py
    c = pp - reach * reach
    if c <= 0.0:
        if b <= 0.0:
            return math.inf
        inner = reach - margin
        c = pp - inner * inner
        if margin <= 0.0 or c <= 0.0:
            return 0.0
    disc = b * b - a * c
    if disc < 0.0 or b <= 0.0 or a <= 1e-12:
        return math.inf
    t = (b - math.sqrt(disc)) / a
    return max(t, 0.0) if t <= h else math.inf


def _gap_scalar(px: float, py: float, vx: float, vy: float, reach: float, h: float) -> float:
    """:func:`closest_gap` for one pair, on floats."""
    a = vx * vx + vy * vy
    b = px * vx + py * vy
    t = min(max(b / max(a, 1e-12), 0.0), h)
    return math.hypot(px - vx * t, py - vy * t) - reach


def _clear_scalar(px: float, py: float, vx: float, vy: float, lim: float, h: float) -> bool:
    """``|p - v t| > lim`` for every t in [0, h] (squared distances: no square root)."""
    a = vx * vx + vy * vy
    b = px * vx + py * vy
    t = min(max(b / max(a, 1e-12), 0.0), h)
    dx, dy = px - vx * t, py - vy * t
    return dx * dx + dy * dy > lim * lim


def _edge_scalar(ax: float, ay: float, ex: float, ey: float) -> float:
    """:func:`_edge_gap` for one segment, on floats."""
    ee = ex * ex + ey * ey
    s = min(max(-(ax * ex + ay * ey) / max(ee, 1e-12), 0.0), 1.0)
    return math.hypot(ax + s * ex, ay + s * ey)


def _sheet_scalar(dx: float, dy: float, ux: float, uy: float, ex: float, ey: float) -> float:
    """:func:`forecast_gap` for one parallelogram, on floats."""
    c = ux * ey - uy * ex
    if abs(c) > 1e-12:
        alpha = -(dx * ey - dy * ex) / c
        beta = (dx * uy - dy * ux) / c
        if 0.0 <= alpha <= 1.0 and 0.0 <= beta <= 1.0:
            return 0.0
    return min(
        min(_edge_scalar(dx, dy, ux, uy), _edge_scalar(dx + ex, dy + ey, ux, uy)),
        min(_edge_scalar(dx, dy, ex, ey), _edge_scalar(dx + ux, dy + uy, ex, ey)),
    )


def social_one(
    px: float,
    py: float,
    cx: float,
    cy: float,
    tx: float,
    ty: float,
    tk: float,
    q: FloatArray,
    w: FloatArray,
    reach: FloatArray,
    span: float,
    forecast: float,
    band: float,
) -> float:
    """``soc`` of one candidate (velocity ``(tx, ty)`` for ``tk`` s, then ``(cx, cy)``) for a
    robot at ``(px, py)`` (module docstring; :func:`social_risk`'s numbers, on floats)."""
    best = 0.0
    t1 = min(tk, span)
    t2 = span - t1
    for j in range(q.shape[0]):
        wx, wy = w[j, 0], w[j, 1]
        if wx == 0.0 and wy == 0.0:
            continue
        dx, dy = q[j, 0] - px, q[j, 1] - py
        ex, ey = wx * forecast, wy * forecast
        ax, ay = wx - tx, wy - ty
        g = _sheet_scalar(dx, dy, ax * t1, ay * t1, ex, ey)
        dx, dy = dx + ax * t1, dy + ay * t1
        g = min(g, _sheet_scalar(dx, dy, (wx - cx) * t2, (wy - cy) * t2, ex, ey))
        pen = reach[j] + band - g
        if pen > best:
            best = pen
    return best


def social_risk_py(
    position: FloatArray,
    cand: FloatArray,
    turn: FloatArray,
    tau: FloatArray,
    q: FloatArray,
    w: FloatArray,
    reach: FloatArray,
    span: float,
    forecast: float,
    band: float,
    soc: FloatArray,
) -> None:
    """The loop of :func:`social_risk_compiled`: :func:`social_one` per candidate, into ``soc``."""
    for k in range(cand.shape[0]):
        soc[k] = social_one(position[0], position[1], cand[k, 0], cand[k, 1], turn[k, 0],
                            turn[k, 1], tau[k], q, w, reach, span, forecast, band)  # fmt: skip


def risk_one(
    px: float,
    py: float,
    cx: float,
    cy: float,
    tx: float,
    ty: float,
    tk: float,
    q: FloatArray,
    w: FloatArray,
    reach: FloatArray,
    bodies: FloatArray,
    horizon: float,
    comfort: float,
    comfort_horizon: float,
    margin: float,
    min_speed: float,
) -> tuple[float, float]:
    """``(ttc, pen)`` of one candidate (velocity ``(tx, ty)`` for ``tk`` s, then ``(cx, cy)``)
    for a robot at ``(px, py)``, with the bounding-disc cull (compiled by numba; plain Python
    otherwise); only discs moving at ``min_speed`` [m/s] or faster are kept ``comfort`` away.

    ``bodies`` (N, 7): first disc index, end index, centre x, y, velocity x, y, bounding reach.
    """
    best_t, best_p, still2 = math.inf, 0.0, min_speed * min_speed
    for b in range(bodies.shape[0]):
        bx, by = bodies[b, 2] - px, bodies[b, 3] - py
        ux, uy = tx - bodies[b, 4], ty - bodies[b, 5]
        lim = bodies[b, 6] + comfort
        bx2, by2 = bx - ux * tk, by - uy * tk
        vx, vy = cx - bodies[b, 4], cy - bodies[b, 5]
        if _clear_scalar(bx, by, ux, uy, lim, max(tk, comfort_horizon)) and _clear_scalar(
            bx2, by2, vx, vy, lim, horizon - tk
        ):
            continue  # the bounding disc stays clear: so does every boundary disc
        for j in range(int(bodies[b, 0]), int(bodies[b, 1])):
            rx, ry = q[j, 0] - px, q[j, 1] - py
            ax, ay = tx - w[j, 0], ty - w[j, 1]
            t = _contact_scalar(rx, ry, ax, ay, reach[j], tk, margin)
            t2 = _contact_scalar(rx - ax * tk, ry - ay * tk, cx - w[j, 0], cy - w[j, 1],
                                 reach[j], horizon - tk, margin)  # fmt: skip
            t = min(t, tk + t2)
            if t < best_t:
                best_t = t
            if w[j, 0] * w[j, 0] + w[j, 1] * w[j, 1] < still2:
                continue  # standing still: kept clear of, not at the comfort distance
            g = comfort - _gap_scalar(rx, ry, ax, ay, reach[j], comfort_horizon)
            if g > best_p:
                best_p = g
    return best_t, best_p


def candidate_risk_py(
    position: FloatArray,
    cand: FloatArray,
    turn: FloatArray,
    tau: FloatArray,
    q: FloatArray,
    w: FloatArray,
    reach: FloatArray,
    bodies: FloatArray,
    horizon: float,
    comfort: float,
    comfort_horizon: float,
    margin: float,
    min_speed: float,
    ttc: FloatArray,
    pen: FloatArray,
) -> None:
    """The loop of :func:`candidate_risk_compiled`: :func:`risk_one` per candidate, written into
    ``ttc`` and ``pen``."""
    for k in range(cand.shape[0]):
        ttc[k], pen[k] = risk_one(position[0], position[1], cand[k, 0], cand[k, 1], turn[k, 0],
                                  turn[k, 1], tau[k], q, w, reach, bodies, horizon, comfort,
                                  comfort_horizon, margin, min_speed)  # fmt: skip


def tangents_py(
    px: float,
    py: float,
    q: FloatArray,
    grow: FloatArray,
    owner: FloatArray,
    n: int,
    out: FloatArray,
) -> int:
    """Per body among the first ``n`` circles (centres ``q``, radii ``grow``, ``owner``
    non-decreasing), the outermost tangent direction [rad] on each side, written into ``out`` as
    all the lower ones, then all the upper ones; returns the number of bodies (the loop of
    :func:`uvnav.controllers.zhang2019_v2.tangent_directions`)."""
    n_bodies = 0
    for i in range(n):
        if i == 0 or owner[i] != owner[i - 1]:
            n_bodies += 1
    b, i = 0, 0
    while i < n:
        end = i
        while end < n and owner[end] == owner[i]:
            end += 1
        near, near_d = i, math.inf
        for j in range(i, end):
            d = math.hypot(q[j, 0] - px, q[j, 1] - py)
            if d < near_d:
                near, near_d = j, d
        ref = math.atan2(q[near, 1] - py, q[near, 0] - px)
        lo, hi = math.inf, -math.inf
        for j in range(i, end):
            dx, dy = q[j, 0] - px, q[j, 1] - py
            d = math.hypot(dx, dy)
            half = math.asin(min(grow[j] / d, 1.0)) if d > grow[j] else 0.5 * math.pi
            rel = (math.atan2(dy, dx) - ref + math.pi) % (2.0 * math.pi) - math.pi
            lo = min(lo, rel - half)
            hi = max(hi, rel + half)
        out[b], out[n_bodies + b] = ref + lo, ref + hi
        b += 1
        i = end
    return 2 * n_bodies


def decide_py(
    state: FloatArray,
    extra: FloatArray,
    speeds: FloatArray,
    q: FloatArray,
    w: FloatArray,
    r: FloatArray,
    owner: IntArray,
    centre: FloatArray,
    vel: FloatArray,
    body_r: FloatArray,
    weights: FloatArray,
    out: FloatArray,
) -> None:
    """One whole choice of ``zhang2019-v2`` in one loop (compiled by numba): the candidate
    headings (the forecast circles' tangents of the nearest bodies, then ``extra``), every heading
    at every speed in ``speeds``, the preferred velocity and standing still; the least-cost one
    written into ``out``: velocity x, y [m/s], its first contact [s], 1.0 when it is the preferred
    one.

    Bodies: boundary discs ``q``, ``w``, ``r`` (M,) of the bodies ``owner`` (non-decreasing), and
    per body (N,) its ``centre``, ``vel`` and bounding radius ``body_r`` (the discs included).
    ``state``: robot x, y, heading [rad], U_max [rad/s] (heading NaN: a holonomic robot), the
    preferred velocity x, y, the previous choice x, y; ``weights``: horizon, comfort,
    comfort horizon, w_ttc, w_change, w_comfort, min_ttc, the robot's radius plus margin,
    forecast time T_f, the number of nearest bodies whose tangents are candidates, the margin
    (:func:`first_contact`), then w_social, the robot's path time T_s [s], the forecast time S [s]
    and the band [m] of the social term (:func:`social_one`; not computed when w_social is 0),
    then the slowest speed [m/s] of a body kept at the comfort distance (:func:`risk_one`).

    The same candidates, costs and first-index tie-break as
    :func:`uvnav.controllers.zhang2019_v2.choose_velocity`, but branch-and-bound: candidates are
    visited by their cost without the risk terms (a lower bound: the risk terms are >= 0), and
    the visit stops once a safe candidate costs no more than the next bound, so candidates that
    cannot win are never checked against the bodies.
    """
    px, py, hd, u_max = state[0], state[1], state[2], state[3]
    fx, fy, ox, oy = state[4], state[5], state[6], state[7]
    horizon, comfort, c_h = weights[0], weights[1], weights[2]
    w_ttc, w_change, w_comfort, min_ttc = weights[3], weights[4], weights[5], weights[6]
    pad, t_f, n_tan, margin = weights[7], weights[8], weights[9], weights[10]
    w_social, span, forecast, band = weights[11], weights[12], weights[13], weights[14]
    min_speed = weights[15]
    reach, grow = r + pad, np.empty(q.shape[0])
    bodies = np.empty((centre.shape[0], 7))
    n_few = 0
    for j in range(q.shape[0]):
        grow[j] = reach[j] * (1.0 + TANGENT_SLACK) + math.hypot(w[j, 0], w[j, 1]) * t_f
        if owner[j] < n_tan:
            n_few = j + 1
        if j == 0 or owner[j] != owner[j - 1]:
            bodies[owner[j], 0] = j
        bodies[owner[j], 1] = j + 1
    for b in range(centre.shape[0]):
        bodies[b, 2], bodies[b, 3] = centre[b, 0], centre[b, 1]
        bodies[b, 4], bodies[b, 5] = vel[b, 0], vel[b, 1]
        bodies[b, 6] = body_r[b] + pad
    tang = np.empty(2 * n_few + 1)
    n_t = tangents_py(px, py, q, grow, owner, n_few, tang)
    n_s = speeds.shape[0]
    n_h = n_t + extra.shape[0]
    n_c = n_h * n_s + 2
    ang, spd = np.empty(n_c), np.empty(n_c)
    for h in range(n_h):
        a = tang[h] if h < n_t else extra[h - n_t]
        for s in range(n_s):
            ang[h * n_s + s], spd[h * n_s + s] = a, speeds[s]
    ang[n_c - 2] = ang[n_c - 1] = math.atan2(fy, fx)
    spd[n_c - 2], spd[n_c - 1] = math.hypot(fx, fy), 0.0
    cand = np.empty((n_c, 2))
    bound = np.empty(n_c)
    for k in range(n_c):
        cand[k, 0], cand[k, 1] = spd[k] * math.cos(ang[k]), spd[k] * math.sin(ang[k])
        bound[k] = math.hypot(cand[k, 0] - fx, cand[k, 1] - fy) + w_change * math.hypot(
            cand[k, 0] - ox, cand[k, 1] - oy
        )
    best = np.array([math.inf, -1.0, math.inf, -1.0, math.inf, math.inf])  # all, safe: cost, k, ttc
    for k in np.argsort(bound, kind="mergesort"):
        if best[3] >= 0.0 and bound[k] > best[2]:
            break
        tx, ty, tk = cand[k, 0], cand[k, 1], 0.0
        if not math.isnan(hd):
            beta = (ang[k] - hd + math.pi) % (2.0 * math.pi) - math.pi
            tk = min(abs(beta) / u_max, horizon)
            s1 = spd[k] * max(math.cos(0.5 * beta), 0.0)
            tx, ty = s1 * math.cos(hd + 0.5 * beta), s1 * math.sin(hd + 0.5 * beta)
        ttc, pen = risk_one(px, py, cand[k, 0], cand[k, 1], tx, ty, tk, q, w, reach, bodies,
                            horizon, comfort, c_h, margin, min_speed)  # fmt: skip
        cost = bound[k] + w_ttc / max(ttc, 1e-3) + w_comfort * pen
        if w_social > 0.0:
            cost += w_social * social_one(px, py, cand[k, 0], cand[k, 1], tx, ty, tk, q, w,
                                          reach, span, forecast, band)  # fmt: skip
        if cost < best[0] or (cost == best[0] and k < best[1]):
            best[0], best[1], best[4] = cost, k, ttc
        if ttc > min_ttc and (cost < best[2] or (cost == best[2] and k < best[3])):
            best[2], best[3], best[5] = cost, k, ttc
    pick, t_pick = (int(best[3]), best[5]) if best[3] >= 0.0 else (int(best[1]), best[4])
    out[0], out[1], out[2] = cand[pick, 0], cand[pick, 1], t_pick
    out[3] = 1.0 if pick == n_c - 2 and math.isinf(t_pick) else 0.0


_COMPILED: dict[str, Callable[..., Any]] = {}


def _kernels() -> dict[str, Callable[..., Any]]:
    """The numba-compiled loops by name (compiled, or loaded from numba's cache, on the first
    call); the Python functions stay the reference path (:func:`compile_family`)."""
    if not _COMPILED:
        _COMPILED.update(compile_family([
            _contact_scalar, _gap_scalar, _clear_scalar, _edge_scalar, _sheet_scalar,
            social_one, risk_one, tangents_py, decide_py, candidate_risk_py, social_risk_py,
        ]))  # fmt: skip
    return _COMPILED


def candidate_risk_compiled(
    position: FloatArray,
    cand: FloatArray,
    turn: FloatArray,
    tau: FloatArray,
    discs: tuple[FloatArray, FloatArray, FloatArray],
    bodies: FloatArray,
    horizon: float,
    comfort: float,
    comfort_horizon: float,
    margin: float = 0.0,
    min_speed: float = 0.0,
) -> tuple[FloatArray, FloatArray]:
    """:func:`candidate_risk` with the bounding-disc cull, compiled (module docstring)."""
    q, w, reach = discs
    ttc = np.empty(len(cand))
    pen = np.empty(len(cand))
    fn = _kernels()["candidate_risk_py"] if numba_enabled() else candidate_risk_py
    fn(np.ascontiguousarray(position, dtype=float), np.ascontiguousarray(cand),
       np.ascontiguousarray(turn), np.ascontiguousarray(tau), np.ascontiguousarray(q),
       np.ascontiguousarray(w), np.ascontiguousarray(reach), np.ascontiguousarray(bodies),
       float(horizon), float(comfort), float(comfort_horizon), float(margin), float(min_speed),
       ttc, pen)  # fmt: skip
    return ttc, pen


def social_risk_compiled(
    position: FloatArray,
    cand: FloatArray,
    turn: FloatArray,
    tau: FloatArray,
    discs: tuple[FloatArray, FloatArray, FloatArray],
    social: tuple[float, float, float],
) -> FloatArray:
    """:func:`social_risk` in one loop, compiled when numba is enabled."""
    q, w, reach = discs
    soc = np.empty(len(cand))
    fn = _kernels()["social_risk_py"] if numba_enabled() else social_risk_py
    c = np.ascontiguousarray
    fn(c(position, dtype=float), c(cand, dtype=float), c(turn, dtype=float), c(tau, dtype=float),
       c(q, dtype=float), c(w, dtype=float), c(reach, dtype=float), float(social[0]),
       float(social[1]), float(social[2]), soc)  # fmt: skip
    return soc


def decide_compiled(
    state: FloatArray,
    extra: FloatArray,
    speeds: FloatArray,
    discs: tuple[FloatArray, FloatArray, FloatArray, IntArray],
    bodies: tuple[FloatArray, FloatArray, FloatArray],
    weights: FloatArray,
) -> FloatArray:
    """:func:`decide_py`, compiled when numba is enabled: ``(vx, vy, ttc, preferred)``.

    ``discs``: centres, velocities, radii and owners of the boundary discs; ``bodies``: centres,
    velocities and bounding radii of the bodies.
    """
    q, w, r, owner = discs
    centre, vel, body_r = bodies
    out = np.empty(4)
    fn = _kernels()["decide_py"] if numba_enabled() else decide_py
    c = np.ascontiguousarray
    fn(c(state, dtype=float), c(extra, dtype=float), c(speeds, dtype=float), c(q, dtype=float),
       c(w, dtype=float), c(r, dtype=float), c(owner, dtype=np.int64), c(centre, dtype=float),
       c(vel, dtype=float), c(body_r, dtype=float), c(weights, dtype=float), out)  # fmt: skip
    return out
