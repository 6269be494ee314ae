"""First contact and closest approach of a moving disc among moving discs, for many candidate
velocities at once (the candidate check of ``zhang2019-v2``, :mod:`uvnav.controllers.zhang2019_v2`).

A candidate k is a motion of the robot in two phases: velocity ``turn[k]`` for ``tau[k]`` seconds,
then ``cand[k]`` (a holonomic robot: ``tau = 0``).  A boundary disc j (centre ``q[j]``, velocity
``w[j]``, radius sum ``reach[j]`` with the robot) moves at constant velocity.  Per candidate:

* ``ttc[k]``: the first time in [0, horizon] at which the robot is within ``reach`` of any disc
  (0 for a pair already in contact and closing; inf when none);
* ``pen[k]``: the largest ``comfort - gap`` (clipped at 0) over the discs, ``gap`` the smallest
  distance beyond ``reach`` over [0, comfort_horizon] while moving at ``turn[k]``.

:func:`candidate_risk` is the numpy reference (arrays K x M); with numba installed (the ``fast``
extra) :func:`candidate_risk_compiled` runs one compiled loop that first tests each body's
bounding disc (``bodies``: index ranges of its discs, centre, velocity and reach), skipping bodies
no candidate comes near — the same numbers (tests compare the two to 1e-12), at a fraction of
the cost with 100 bodies.  Units: metres, seconds.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.kernels3d import numba_enabled


def first_contact(
    rel_pos: FloatArray, rel_vel: FloatArray, reach: FloatArray, horizon: float | FloatArray
) -> FloatArray:
    """First time [s] in [0, horizon] at which ``|rel_pos - rel_vel t| <= reach``; inf if never.

    ``rel_pos`` (..., 2): a body relative to the robot; ``rel_vel`` (..., 2): the robot's velocity
    relative to the body; ``reach``: the radius sum (broadcast).  A pair already in contact reads 0
    while it closes in and inf while it opens.

    >>> first_contact(np.array([2.0, 0.0]), np.array([1.0, 0.0]), np.array(1.0), 5.0).item()
    1.0
    >>> first_contact(np.array([2.0, 0.0]), np.array([-1.0, 0.0]), np.array(1.0), 5.0).item()
    inf
    >>> first_contact(np.array([0.5, 0.0]), np.array([1.0, 0.0]), np.array(1.0), 5.0).item()
    0.0
    """
    a = np.einsum("...i,...i->...", rel_vel, rel_vel)
    b = np.einsum("...i,...i->...", rel_pos, rel_vel)
    c = np.einsum("...i,...i->...", rel_pos, rel_pos) - reach * reach
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
) -> tuple[FloatArray, FloatArray]:
    """``(ttc, pen)`` per candidate (module docstring), numpy over K x M."""
    q, w, reach = discs
    if not len(q):
        return np.full(len(cand), np.inf), np.zeros(len(cand))
    rel = (q - position)[None, :, :]
    r = reach[None, :]
    turn_rel = turn[:, None, :] - w[None, :, :]
    t1 = first_contact(rel, turn_rel, r, tau[:, None])
    rel2 = rel - turn_rel * tau[:, None, None]
    t2 = first_contact(rel2, cand[:, None, :] - w[None, :, :], r, (horizon - tau)[:, None])
    ttc = np.minimum(t1, tau[:, None] + t2).min(axis=1)
    gap = closest_gap(rel, turn_rel, r, comfort_horizon)
    pen = np.clip(comfort - gap, 0.0, None).max(axis=1)
    return ttc, pen


# -- the compiled path ------------------------------------------------------------------------


def _contact_scalar(px: float, py: float, vx: float, vy: float, reach: float, h: float) -> float:
    """:func:`first_contact` for one pair, on floats."""
    a = vx * vx + vy * vy
    b = px * vx + py * vy
    c = px * px + py * py - reach * reach
    if c <= 0.0:
        return 0.0 if b > 0.0 else math.inf
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
    ttc: FloatArray,
    pen: FloatArray,
) -> None:
    """The loop of :func:`candidate_risk_compiled` (compiled by numba; plain Python otherwise).

    ``bodies`` (N, 7): first disc index, end index, centre x, y, velocity x, y, bounding reach.
    """
    px, py = position[0], position[1]
    for k in range(cand.shape[0]):
        best_t, best_p = math.inf, 0.0
        tk = tau[k]
        for b in range(bodies.shape[0]):
            bx, by = bodies[b, 2] - px, bodies[b, 3] - py
            ux, uy = turn[k, 0] - bodies[b, 4], turn[k, 1] - bodies[b, 5]
            lim = bodies[b, 6] + comfort
            bx2, by2 = bx - ux * tk, by - uy * tk
            cx, cy = cand[k, 0] - bodies[b, 4], cand[k, 1] - bodies[b, 5]
            if _clear(bx, by, ux, uy, lim, max(tk, comfort_horizon)) and _clear(
                bx2, by2, cx, cy, lim, horizon - tk
            ):
                continue  # the bounding disc stays clear: so does every boundary disc
            for j in range(int(bodies[b, 0]), int(bodies[b, 1])):
                rx, ry = q[j, 0] - px, q[j, 1] - py
                ax, ay = turn[k, 0] - w[j, 0], turn[k, 1] - w[j, 1]
                t = _contact_scalar(rx, ry, ax, ay, reach[j], tk)
                t2 = _contact_scalar(rx - ax * tk, ry - ay * tk, cand[k, 0] - w[j, 0],
                                     cand[k, 1] - w[j, 1], reach[j], horizon - tk)  # fmt: skip
                t = min(t, tk + t2)
                if t < best_t:
                    best_t = t
                g = comfort - _gap_scalar(rx, ry, ax, ay, reach[j], comfort_horizon)
                if g > best_p:
                    best_p = g
        ttc[k] = best_t
        pen[k] = best_p


_COMPILED: dict[str, Callable[..., Any]] = {}
_contact: Callable[..., float] = _contact_scalar
_gap: Callable[..., float] = _gap_scalar
_clear: Callable[..., bool] = _clear_scalar


def _kernel() -> Callable[..., Any]:
    """The numba-compiled loop (compiled, or loaded from numba's cache, on the first call)."""
    global _contact, _gap, _clear
    if not _COMPILED:
        import numba

        _contact = numba.njit(cache=True, nogil=True)(_contact_scalar)
        _gap = numba.njit(cache=True, nogil=True)(_gap_scalar)
        _clear = numba.njit(cache=True, nogil=True)(_clear_scalar)
        globals()["_contact_scalar"], globals()["_gap_scalar"] = _contact, _gap
        globals()["_clear_scalar"] = _clear
        _COMPILED["risk"] = numba.njit(cache=True, nogil=True)(candidate_risk_py)
    return _COMPILED["risk"]


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
) -> tuple[FloatArray, FloatArray]:
    """:func:`candidate_risk` with the bounding-disc cull, compiled (module docstring)."""
    q, w, reach = discs
    ttc = np.empty(len(cand))
    pen = np.empty(len(cand))
    fn = _kernel() if numba_enabled() else candidate_risk_py
    fn(np.ascontiguousarray(position, dtype=float), np.ascontiguousarray(cand),
       np.ascontiguousarray(turn), np.ascontiguousarray(tau), np.ascontiguousarray(q),
       np.ascontiguousarray(w), np.ascontiguousarray(reach), np.ascontiguousarray(bodies),
       float(horizon), float(comfort), float(comfort_horizon), ttc, pen)  # fmt: skip
    return ttc, pen
