"""The unicycle's choice of ``zhang2019-v2`` among candidates checked along their rolled-out paths,
in one loop (compiled by numba when it is enabled, plain Python otherwise).

:func:`plan_paths_py` computes per candidate, on floats and in the same order of operations, what
the numpy building blocks of :mod:`uvnav.controllers.zhang2019_v2` and
:mod:`uvnav.controllers.zhang2019_limits` compute for all of them at once: the candidates
(:func:`~uvnav.controllers.zhang2019_v2.candidates`), the path of the law's own steering toward
each (:func:`advance`, as :func:`~uvnav.controllers.zhang2019_limits.rollout`), its first contact
and comfort penalty (:func:`risk_along`, as :func:`~uvnav.controllers.zhang2019_limits.path_risk`),
whether the robot can still stop before that contact (as
:func:`~uvnav.controllers.zhang2019_limits.stoppable`), and the least-cost choice (as
:func:`~uvnav.controllers.zhang2019_v2.least_cost` with ``admissible``).  What it does not compute
is what cannot change the choice:

* it visits the candidates by their cost without the risk terms (a lower bound: the risk terms
  are >= 0) and stops once a safe candidate costs no more than the next bound; a first visit
  leaves a candidate as soon as it cannot be safe or cannot win, and only where no candidate is
  safe are they all checked to the end (resuming where the first visit left off);
* a path is rolled out only as far as it is checked, and its check stops at the segment of its
  first contact (later segments start later) once past the comfort horizon;
* per chunk of :data:`CHUNK` segments, the bodies that can reach any path over the chunk (a
  square about the start, as wide as the fastest path goes) are listed once per decision, by
  the low x of their boxes over the chunk grown by their reach (:func:`_chunk_bodies`); a
  candidate's chunk visits only those whose grown boxes meet its path's box (a bisection on
  that low x, then a box test: sweep and prune), and skips a body, then a disc, whose box over
  the chunk stays out of reach of the path's box;
* where no candidate is safe, whether one can still brake is computed only where its cost could
  win; a braking check answers yes at once when the straight line to a point before the contact
  already exceeds the stopping distance;
* the heading and turn rate of a path do not depend on its speed: the paths toward one direction
  share their sines and cosines (:func:`advance`'s track).

So it picks the reference's candidate, to rounding (its sines and cosines are the C library's,
the reference's numpy's; tests: hypothesis on random scenes), and exactly the candidate of the
full evaluation (every path to the horizon, every disc, every segment) made of its own kernels
(tests).  Units: metres, seconds, radians.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from uvnav.controllers import zhang2019_v2_loop
from uvnav.controllers.zhang2019_v2_loop import boundary_discs_py, reachable_py
from uvnav.geometry import contact
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.contact import TANGENT_SLACK, _contact_scalar, _gap_scalar, tangents_py
from uvnav.geometry.kernels3d import compile_family, numba_enabled

#: indices into the ``prm`` vector of :func:`choose_on_paths_py` and :func:`plan_paths_py`
(M_VMAX, M_UMAX, M_ACCEL, M_TURN, M_PERIOD, M_HORIZON, M_STEP, M_COMFORT, M_CHOR, M_MARGIN,
 M_SPREAD, M_MIN_TTC, M_W_TTC, M_W_COMFORT, M_W_CHANGE, M_T_F, M_N_TAN,
 M_N_HEAD, M_RADIUS, M_SPACING, M_STILL, M_STILL_CAP, M_TURN_FIRST) = range(23)  # fmt: skip


def _approach(value: float, target: float, most: float) -> float:
    """``value`` moved toward ``target`` by at most ``most`` (as the vehicle does)."""
    if math.isinf(most):
        return target
    return value + min(max(target - value, -most), most)


def _ramp_turn(u_now: float, target: float, rate: float, period: float) -> float:
    """:func:`uvnav.dynamics.unicycle.ramp_turn` (the period's turn of a turn-then-move
    vehicle), as the vehicle computes it."""
    if math.isinf(rate):
        return target * period
    gap = target - u_now
    ramp = min(abs(gap) / rate, period)
    u_end = u_now + math.copysign(rate * ramp, gap)
    if ramp < period:
        return 0.5 * (u_now + u_end) * ramp + target * (period - ramp)
    return 0.5 * (u_now + u_end) * period


def _window(now: float, rate: float, period: float, low: float, high: float) -> tuple[float, float]:
    """The values reachable from ``now`` within one period, clipped to [``low``, ``high``]."""
    step = rate * period
    return min(max(now - step, low), high), min(max(now + step, low), high)


def _turn(beta: float, u_now: float, prm: FloatArray) -> float:
    """:func:`uvnav.controllers.zhang2019_limits.turn_command` for one heading error."""
    period, u_max, a = prm[M_PERIOD], prm[M_UMAX], prm[M_TURN]
    b = abs(beta)
    mag = min(b / period, u_max)
    if math.isfinite(a):
        half = 0.5 * a * period
        mag = min(mag, math.sqrt(half * half + 2.0 * a * b) - half)
    lo, hi = _window(u_now, a, period, -u_max, u_max)
    sign = 1.0 if beta > 0.0 else (-1.0 if beta < 0.0 else 0.0)
    return min(max(sign * mag, lo), hi)


def advance(
    st: FloatArray, aim: float, speed: float, prm: FloatArray, n_sub: int, xy: FloatArray,
    speeds: FloatArray, upto: int, track: FloatArray, known: FloatArray,
) -> None:  # fmt: skip
    """Extend the path of :func:`uvnav.controllers.zhang2019_limits.rollout` toward one ``aim``
    [rad] at ``speed`` [m/s] (``xy`` (S + 1, 2), ``speeds`` (S + 1,), ``n_sub`` substeps per
    period) to its point ``upto``; ``st``: heading, speed, turn rate, speed and turn rate
    commanded, and the last point computed, updated (from ``xy[0]``, ``speeds[0]``: the pose, its
    speed and turn rate, held, and 0).

    The heading and turn rate do not depend on the speed: per substep ``track`` (S, 8) holds
    the half-turn, its sinc, the cosine and sine of the chord's direction, the cosine of the
    heading error (at a decision), the turn rate after, the heading after and the turn rate
    commanded, shared by the paths toward the same ``aim`` from the same start; its first
    ``known[0]`` rows are read, not computed again, and it is extended as the path is.  With
    ``prm[M_TURN_FIRST]`` the vehicle turns by the period's turn at each decision and moves
    straight (:func:`uvnav.controllers.zhang2019_limits.rollout`'s ``turn_first``)."""
    h = prm[M_PERIOD] / n_sub
    i0 = int(st[5])
    x, y, th, v, u, v_cmd, u_cmd = xy[i0, 0], xy[i0, 1], st[0], st[1], st[2], st[3], st[4]
    half_was, sinc, last, n_known = math.nan, 1.0, i0, int(known[0])
    for i in range(i0, min(upto, xy.shape[0] - 1)):
        steer = i % n_sub == 0
        if i >= n_known:  # the heading track, computed and kept for the paths toward ``aim``
            if steer:
                beta = (aim - th + math.pi) % (2.0 * math.pi) - math.pi
                track[i, 4], track[i, 7] = math.cos(beta), _turn(beta, u, prm)
            else:
                track[i, 7] = track[i - 1, 7]
            u1 = _approach(u, track[i, 7], prm[M_TURN] * h)
            if prm[M_TURN_FIRST] > 0.0:  # the period's turn at the decision, then straight
                if steer:
                    th = th + _ramp_turn(u, track[i, 7], prm[M_TURN], prm[M_PERIOD])
                half = 0.0
            else:
                half = 0.25 * (u + u1) * h
            if half != half_was:  # the same half-turn as the substep before: the same sinc
                arg = math.pi * (half / math.pi if half != 0.0 else 1.0e-20)  # numpy's sinc
                sinc, half_was = math.sin(arg) / arg, half
            track[i, 0], track[i, 1], track[i, 5] = half, sinc, u1
            track[i, 2], track[i, 3] = math.cos(th + half), math.sin(th + half)
            track[i, 6] = th + 2.0 * half
            n_known = i + 1
        if steer:
            lo, hi = _window(v, prm[M_ACCEL], prm[M_PERIOD], 0.0, prm[M_VMAX])
            v_cmd = min(max(speed * max(track[i, 4], 0.0), lo), hi)
        v1 = _approach(v, v_cmd, prm[M_ACCEL] * h)
        chord = 0.5 * (v + v1) * h * track[i, 1]
        x = x + chord * track[i, 2]
        y = y + chord * track[i, 3]
        th, v, u, u_cmd = track[i, 6], v1, track[i, 5], track[i, 7]
        xy[i + 1, 0], xy[i + 1, 1], speeds[i + 1] = x, y, v
        last = i + 1
    known[0] = n_known
    st[0], st[1], st[2], st[3], st[4], st[5] = th, v, u, v_cmd, u_cmd, last


#: segments per chunk of :func:`risk_along`'s cull
CHUNK = 4


def _box_far(box: FloatArray, ax: float, ay: float, bx: float, by: float, lim: float) -> bool:
    """The distance [m] between the box ``(x lo, x hi, y lo, y hi)`` and the bounding box of the
    segment ``(ax, ay)``-``(bx, by)`` exceeds ``lim``: ``hypot(dx, dy) > lim``, decided on the
    squares where they settle it (far from equality) and by ``hypot`` where they do not."""
    dx = max(min(ax, bx) - box[1], box[0] - max(ax, bx), 0.0)
    dy = max(min(ay, by) - box[3], box[2] - max(ay, by), 0.0)
    sq, lim_sq = dx * dx + dy * dy, lim * lim
    if sq > lim_sq * (1.0 + 1e-12):
        return True
    if sq < lim_sq * (1.0 - 1e-12):
        return False
    return math.hypot(dx, dy) > lim


def _path_box(xy: FloatArray, i0: int, i1: int, box: FloatArray) -> None:
    """The bounding box of the path points ``xy[i0:i1 + 1]`` into ``box`` (x lo, x hi, y lo,
    y hi)."""
    box[0], box[1], box[2], box[3] = xy[i0, 0], xy[i0, 0], xy[i0, 1], xy[i0, 1]
    for i in range(i0 + 1, i1 + 1):
        box[0], box[1] = min(box[0], xy[i, 0]), max(box[1], xy[i, 0])
        box[2], box[3] = min(box[2], xy[i, 1]), max(box[3], xy[i, 1])


def _disc_along(
    xy: FloatArray, times: FloatArray, i0: int, i1: int, qw: tuple[float, float, float, float],
    reach: float, prm: FloatArray, risk: FloatArray,
) -> None:  # fmt: skip
    """Fold one disc (centre and velocity ``qw``, radius sum ``reach``) on the segments
    ``i0 .. i1 - 1`` of the path ``xy`` into ``risk`` (first contact, comfort penalty)."""
    horizon, comfort, c_h, margin = prm[M_HORIZON], prm[M_COMFORT], prm[M_CHOR], prm[M_MARGIN]
    qx, qy, wx, wy = qw
    walks = math.hypot(wx, wy) >= prm[M_STILL]  # a body standing still: no comfort distance
    for i in range(i0, i1):
        t0 = times[i]
        near = t0 < c_h and walks
        if not (near or risk[0] > t0):
            continue
        h = times[i + 1] - t0
        vx, vy = (xy[i + 1, 0] - xy[i, 0]) / h, (xy[i + 1, 1] - xy[i, 1]) / h
        rx, ry = qx + wx * t0 - xy[i, 0], qy + wy * t0 - xy[i, 1]
        px, py = vx - wx, vy - wy
        if risk[0] > t0:
            seg_h = max(min(h, horizon - t0), 0.0)
            spread = prm[M_SPREAD] * (t0 + h)
            if not walks:  # a body standing still grows by at most still_cap
                spread = min(spread, prm[M_STILL_CAP])
            grown = reach + spread
            t = t0 + _contact_scalar(rx, ry, px, py, grown, seg_h, margin)
            if t < risk[0]:
                risk[0] = t
        if near:
            g = comfort - _gap_scalar(rx, ry, px, py, reach, min(h, c_h - t0))
            if g > risk[1]:
                risk[1] = g


def _far(box: FloatArray, qw: tuple[float, float, float, float], t_a: float, t_b: float,
         lim: float) -> bool:  # fmt: skip
    """A point moving with ``qw`` (position at 0, velocity) stays, over [``t_a``, ``t_b``],
    farther than ``lim`` from the ``box``, box to box."""
    qx, qy, wx, wy = qw
    return _box_far(box, qx + wx * t_a, qy + wy * t_a, qx + wx * t_b, qy + wy * t_b, lim)


def _chunk_bodies(
    c: int, t_a: float, t_b: float, lim: float, xy: FloatArray, bodies: FloatArray,
    cull: tuple[np.ndarray, float, FloatArray, FloatArray, FloatArray],
) -> None:  # fmt: skip
    """The bodies that may come within reach of any path over chunk ``c`` (times ``t_a`` ..
    ``t_b``), into ``cull``'s lists, by the low x of their boxes: a path moves at most
    ``cull[1]`` [m/s] from its start ``xy[0]``, so its box over the chunk lies in the square of
    that half-width about the start, and a body whose box over the chunk stays, box to box,
    farther than its bounding reach plus ``lim`` from that square is farther from the path's box
    too.  Per listed body, its box over the chunk grown by that reach (``cull[3]``, rows from
    ``c * N``: x lo, x hi, y lo, y hi), and in ``cull[2][c]`` the widest of them in x: a path's
    box can meet only those whose low x lies within that width below its own low x."""
    lists, top, grown = cull[0], cull[1], cull[3]
    n_b = bodies.shape[0]
    half = top * t_b * (1.0 + 1e-9) + 1e-9
    square = np.array((xy[0, 0] - half, xy[0, 0] + half, xy[0, 1] - half, xy[0, 1] + half))
    row0 = c * n_b
    near = np.empty(n_b, dtype=np.int64)
    lows = np.empty(n_b)
    n = 0
    for b in range(n_b):
        body = (bodies[b, 2], bodies[b, 3], bodies[b, 4], bodies[b, 5])
        if not _far(square, body, t_a, t_b, bodies[b, 6] + lim):
            pad = (bodies[b, 6] + lim) * (1.0 + 1e-9) + 1e-9  # never tighter than _far
            near[n] = b
            lows[n] = min(body[0] + body[2] * t_a, body[0] + body[2] * t_b) - pad
            n += 1
    by = np.argsort(lows[:n])
    for i in range(n):
        b = near[by[i]]
        pad = (bodies[b, 6] + lim) * (1.0 + 1e-9) + 1e-9
        xa, xb = bodies[b, 2] + bodies[b, 4] * t_a, bodies[b, 2] + bodies[b, 4] * t_b
        ya, yb = bodies[b, 3] + bodies[b, 5] * t_a, bodies[b, 3] + bodies[b, 5] * t_b
        lists[0, row0 + i] = b
        grown[row0 + i, 0], grown[row0 + i, 1] = lows[by[i]], max(xa, xb) + pad
        grown[row0 + i, 2], grown[row0 + i, 3] = min(ya, yb) - pad, max(ya, yb) + pad
        cull[2][c] = max(cull[2][c], grown[row0 + i, 1] - grown[row0 + i, 0])
    lists[1, c] = n


def risk_along(
    path: tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray], aim: float,
    speed: float, n_sub: int,
    times: FloatArray, discs: tuple[FloatArray, FloatArray, FloatArray], bodies: FloatArray,
    cull: tuple[np.ndarray, float, FloatArray, FloatArray, FloatArray],
    prm: FloatArray,
    give_up: float, base: float,
    safe_only: bool, risk: FloatArray,
) -> None:  # fmt: skip
    """The first contact and comfort penalty of one candidate's path
    (:func:`uvnav.controllers.zhang2019_limits.path_risk` of one row), rolled out as far as it
    is read (``path``: :func:`advance`'s ``xy``, ``speeds``, ``st``, ``track`` and ``known``),
    into ``risk`` (ttc, pen,
    and the first segment not yet checked: a later call resumes there); stops early, with the
    figures so far, once the cost exceeds ``give_up`` (``base`` plus the risk terms so far: the
    path cannot win) or, when ``safe_only``, once a contact comes at or before ``min_ttc`` (the
    path is not safe).

    The path is checked :data:`CHUNK` segments at a time; a body (``bodies``: first and end
    disc, centre, velocity, bounding reach), then a disc, whose positions over a chunk stay, box
    to box, farther from the robot's than its grown reach (and the comfort distance within the
    comfort horizon) is not checked on that chunk's segments: none would count.  ``cull``: per
    chunk the bodies that can reach some path, by the low x of their grown boxes
    (:func:`_chunk_bodies`: lists, the fastest path's speed, the widest box per chunk, the
    boxes), and room for the path's box; a chunk visits only the bodies whose grown boxes meet
    the path's box, found by bisection on that low x."""
    xy, speeds, st, track, known = path
    q, w, reach = discs
    lists, wide, grown, box = cull[0], cull[2], cull[3], cull[4]
    n_b = bodies.shape[0]
    c_h, spread, w_ttc, w_comfort = prm[M_CHOR], prm[M_SPREAD], prm[M_W_TTC], prm[M_W_COMFORT]
    n_seg = times.shape[0] - 1
    while risk[2] < n_seg:
        i0 = int(risk[2])
        i1 = min(i0 + CHUNK, n_seg)
        if times[i0] >= c_h and risk[0] <= times[i0]:
            risk[2] = n_seg  # no earlier contact on later segments, no comfort term beyond c_h
            break
        advance(st, aim, speed, prm, n_sub, xy, speeds, i1, track, known)
        t_a, t_b = times[i0], times[i1]
        lim_far = spread * t_b + (prm[M_COMFORT] if t_a < c_h else 0.0) + 1e-9
        _path_box(xy, i0, i1, box)
        c = i0 // CHUNK
        if lists[1, c] < 0:
            _chunk_bodies(c, t_a, t_b, lim_far, xy, bodies, cull)
        row0, end = c * n_b, c * n_b + lists[1, c]
        at = row0 + np.searchsorted(grown[row0:end, 0], box[0] - wide[c])
        for idx in range(at, end):
            if grown[idx, 0] > box[1]:
                break  # this body and the next ones lie beyond the path's box in x
            if grown[idx, 1] < box[0] or grown[idx, 2] > box[3] or grown[idx, 3] < box[2]:
                continue
            b = lists[0, idx]
            body = (bodies[b, 2], bodies[b, 3], bodies[b, 4], bodies[b, 5])
            if _far(box, body, t_a, t_b, bodies[b, 6] + lim_far):
                continue
            first, end = int(bodies[b, 0]), int(bodies[b, 1])
            for j in range(first, end):
                qw = (q[j, 0], q[j, 1], w[j, 0], w[j, 1])
                if end - first > 1 and _far(box, qw, t_a, t_b, reach[j] + lim_far):
                    continue
                _disc_along(xy, times, i0, i1, qw, reach[j], prm, risk)
        risk[2] = i1
        if risk[0] <= prm[M_MIN_TTC] and safe_only:
            break
        if base + w_ttc / max(risk[0], 1e-3) + w_comfort * risk[1] > give_up:
            break


def _stops(xy: FloatArray, times: FloatArray, speeds: FloatArray, ttc: float, n_sub: int,
           prm: FloatArray) -> bool:  # fmt: skip
    """:func:`uvnav.controllers.zhang2019_limits.stoppable` of one path."""
    if not math.isfinite(ttc):
        return True
    v_t = speeds[min(n_sub, speeds.shape[0] - 1)]
    need = v_t * prm[M_PERIOD] + v_t * v_t / (2.0 * prm[M_ACCEL])
    m = min(int(ttc / times[1]), times.shape[0] - 1)
    while m > 0 and times[m] > ttc:
        m -= 1
    if math.hypot(xy[m, 0] - xy[0, 0], xy[m, 1] - xy[0, 1]) > need * (1.0 + 1e-9) + 1e-12:
        return True  # the path to the contact is longer than the straight line to a point on it
    length, to_contact = 0.0, math.nan
    for i in range(times.shape[0] - 1):
        after = length + math.hypot(xy[i + 1, 0] - xy[i, 0], xy[i + 1, 1] - xy[i, 1])
        if ttc < times[i + 1]:  # numpy's interp on this interval
            slope = (after - length) / (times[i + 1] - times[i])
            to_contact = slope * (ttc - times[i]) + length
            break
        length = after
    if math.isnan(to_contact):
        to_contact = length
    return to_contact >= need


def _better(best: FloatArray, slot: int, cost: float, k: int) -> bool:
    """Candidate ``k`` at ``cost`` would replace ``best``'s ``slot`` (cost, index, ttc): it costs
    less, or as much with a lower index."""
    return cost < best[slot] or (cost == best[slot] and k < best[slot + 1])


def _keep(best: FloatArray, slot: int, cost: float, k: int, ttc: float) -> None:
    """Record candidate ``k`` in ``best``'s ``slot`` when :func:`_better`."""
    if _better(best, slot, cost, k):
        best[slot], best[slot + 1], best[slot + 2] = cost, k, ttc


def _groups(ang: FloatArray) -> np.ndarray:
    """Per candidate the index of its direction among the distinct values of ``ang``."""
    by = np.argsort(ang)
    group = np.empty(ang.shape[0], dtype=np.int64)
    g = -1
    for i in range(by.shape[0]):
        if i == 0 or ang[by[i]] != ang[by[i - 1]]:
            g += 1
        group[by[i]] = g
    return group


def choose_on_paths_py(
    pose: FloatArray, now: FloatArray, cand: tuple[FloatArray, FloatArray, FloatArray],
    order: np.ndarray, discs: tuple[FloatArray, FloatArray, FloatArray], bodies: FloatArray,
    prm: FloatArray, out: FloatArray,
) -> None:  # fmt: skip
    """The least-cost candidate (``cand``: directions, speeds, costs without the risk terms;
    visited in ``order``: that cost ascending, ties by index) of a unicycle at ``pose`` with
    speed and turn rate ``now``, each checked along its rolled-out path against the ``discs``
    (centres, velocities, radius sums) of the ``bodies`` (:func:`risk_along`): its index and
    first contact [s] written into ``out`` (module docstring).  ``prm``: V_max, U_max, the speed
    and turn-rate limits, the period, the horizon, the longest substep, comfort, the comfort
    horizon, the margin, the spread, min_ttc, w_ttc and w_comfort."""
    ang, spd, base = cand
    period = prm[M_PERIOD]
    n_sub = max(1, math.ceil(period / prm[M_STEP] - 1e-9))
    h = period / n_sub
    n = max(1, math.ceil(prm[M_HORIZON] / h - 1e-9))
    times = h * np.arange(n + 1).astype(np.float64)
    n_c = ang.shape[0]
    xy, speeds, st = np.empty((n_c, n + 1, 2)), np.empty((n_c, n + 1)), np.empty((n_c, 6))
    risk = np.zeros((n_c, 3))  # per path: first contact, comfort penalty, next segment
    risk[:, 0] = math.inf
    for k in range(n_c):  # every path starts at the pose, at the speed and turn rate it has
        xy[k, 0, 0], xy[k, 0, 1], speeds[k, 0] = pose[0], pose[1], now[0]
        st[k, 0], st[k, 1], st[k, 2], st[k, 3], st[k, 4], st[k, 5] = (
            pose[2], now[0], now[1], now[0], now[1], 0.0)  # fmt: skip
    group = _groups(ang)  # the paths toward one direction share their heading track
    track = np.empty((int(group.max()) + 1 if n_c else 0, n, 8))
    known = np.zeros(track.shape[0])
    min_ttc, w_ttc, w_comfort = prm[M_MIN_TTC], prm[M_W_TTC], prm[M_W_COMFORT]
    n_chunks = (n + CHUNK - 1) // CHUNK
    n_rows = max(n_chunks * bodies.shape[0], n_chunks)
    lists = np.full((2, n_rows), -1, dtype=np.int64)
    top = max(prm[M_VMAX], abs(now[0]))  # no path moves faster
    cull = (lists, top, np.zeros(n_chunks), np.empty((n_rows, 4)), np.empty(4))
    # best safe, best admissible, best of all: cost, index, ttc
    best = np.array([math.inf, -1.0, math.inf, math.inf, -1.0, math.inf, math.inf, -1.0, math.inf])
    for safe_only in (True, False):  # the safe one if any; all of them only when none is
        for k in order:
            if best[1] >= 0.0 and base[k] > best[0]:
                break
            give_up = best[0] if best[1] >= 0.0 else math.inf
            g = group[k]
            path = (xy[k], speeds[k], st[k], track[g], known[g : g + 1])
            risk_along(path, ang[k], spd[k], n_sub, times, discs, bodies, cull, prm, give_up,
                       base[k], safe_only, risk[k])  # fmt: skip
            ttc, pen = risk[k, 0], risk[k, 1]
            cost = base[k] + w_ttc / max(ttc, 1e-3) + w_comfort * pen
            if (safe_only and ttc <= min_ttc) or cost > give_up:
                continue
            if not (safe_only or _better(best, 3, cost, k)):
                _keep(best, 6, cost, k, ttc)  # whether it brakes cannot matter
                continue
            if math.isfinite(ttc):  # the path to the contact and the speed after one period
                upto = max(n_sub, min(int(ttc / h) + 2, n))
                advance(st[k], ang[k], spd[k], prm, n_sub, xy[k], speeds[k], upto, track[g],
                        known[g : g + 1])  # fmt: skip
            brakes = _stops(xy[k], times, speeds[k], ttc, n_sub, prm)
            if brakes and ttc > min_ttc:
                _keep(best, 0, cost, k, ttc)
            if not safe_only and brakes:
                _keep(best, 3, cost, k, ttc)
            if not safe_only:
                _keep(best, 6, cost, k, ttc)
        if best[1] >= 0.0:
            break
    slot = 0 if best[1] >= 0.0 else (3 if best[4] >= 0.0 else 6)
    out[0], out[1] = best[slot + 1], best[slot + 2]


def plan_paths_py(
    state: FloatArray, q: FloatArray, w: FloatArray, reach: FloatArray, owner: np.ndarray,
    bodies: FloatArray, speeds: FloatArray, prm: FloatArray, out: FloatArray,
) -> None:  # fmt: skip
    """One decision of the unicycle on rolled-out paths after reading the observation: the
    candidates of :func:`uvnav.controllers.zhang2019_v2.candidates` (the tangents of the forecast
    circles of the nearest bodies, :func:`uvnav.geometry.contact.tangents_py`, the extra
    headings, each at every speed of ``speeds``, the preferred velocity, standing still), their
    costs without the risk terms, and :func:`choose_on_paths_py`; written into ``out``: velocity
    x, y [m/s], its first contact [s], 1.0 when it is the preferred one.

    ``state``: robot x, y, heading [rad], speed [m/s], turn rate [rad/s], the preferred velocity
    x, y and its norm, the previous choice x, y, 1.0 when the previous choice is moving (its
    direction is a candidate); ``q``, ``w``, ``reach``, ``owner``: the boundary discs (owner
    non-decreasing, nearest body first); ``bodies`` (N, 7): per body its first and end disc,
    centre, velocity and bounding reach (every disc's positions over the horizon within it);
    ``prm``: :func:`choose_on_paths_py`'s, then w_change,
    the forecast time T_f, the number of nearest bodies whose tangents are candidates and
    n_headings."""
    px, py = state[0], state[1]
    fx, fy, f_norm, ox, oy = state[5], state[6], state[7], state[8], state[9]
    n_tan, n_head, w_change = prm[M_N_TAN], int(prm[M_N_HEAD]), prm[M_W_CHANGE]
    n_few = 0
    grow = np.empty(q.shape[0])
    for j in range(q.shape[0]):  # the discs of the nearest bodies (owner is non-decreasing)
        if owner[j] >= n_tan:
            break
        grow[j] = reach[j] * (1.0 + TANGENT_SLACK) + math.hypot(w[j, 0], w[j, 1]) * prm[M_T_F]
        n_few = j + 1
    tang = np.empty(2 * n_few + 1)
    n_t = tangents_py(px, py, q, grow, owner, n_few, tang)
    n_x = n_head + (2 if state[10] > 0.0 else 1)
    n_s = speeds.shape[0]
    n_c = (n_t + n_x) * n_s + 2
    ang, spd = np.empty(n_c), np.empty(n_c)
    cand, base = np.empty((n_c, 2)), np.empty(n_c)
    for i in range(n_t + n_x + 1):  # each direction's cosine and sine once, for all its speeds
        if i < n_t:
            a = tang[i]
        elif i - n_t < n_head:
            a = 2.0 * math.pi * float(i - n_t) / max(n_head, 1)
        elif i - n_t == n_head + 1 and i < n_t + n_x:  # the previous choice's direction
            a = math.atan2(oy, ox)
        else:  # the goal's, for the preferred velocity and standing still too
            a = math.atan2(fy, fx)
        cos_a, sin_a = math.cos(a), math.sin(a)
        for k in range(n_s if i < n_t + n_x else 2):
            j = i * n_s + k if i < n_t + n_x else n_c - 2 + k
            ang[j] = a
            if i < n_t + n_x:
                spd[j] = speeds[k]
            else:  # the preferred velocity, then standing still
                spd[j] = f_norm if k == 0 else 0.0
            cand[j, 0], cand[j, 1] = spd[j] * cos_a, spd[j] * sin_a
    for k in range(n_c):
        cx, cy = cand[k, 0], cand[k, 1]
        base[k] = math.hypot(cx - fx, cy - fy) + w_change * math.hypot(cx - ox, cy - oy)
    order = np.argsort(base, kind="mergesort")
    pick = np.empty(2)
    choose_on_paths_py(state[:3], state[3:5], (ang, spd, base), order, (q, w, reach), bodies,
                       prm, pick)  # fmt: skip
    k = int(pick[0])
    out[0], out[1], out[2] = cand[k, 0], cand[k, 1], pick[1]
    out[3] = 1.0 if k == n_c - 2 and math.isinf(pick[1]) else 0.0


def plan_readings_py(
    state: FloatArray, scal: FloatArray, centre: FloatArray, vel: FloatArray, rings: FloatArray,
    ring_start: np.ndarray, speeds: FloatArray, prm: FloatArray, out: FloatArray,
) -> None:  # fmt: skip
    """:func:`plan_paths_py` from the readings as arrays (``scal``, ``centre``, ``vel``,
    ``rings``, ``ring_start``: as :func:`uvnav.controllers.zhang2019_v2_loop.plan_loop_py`
    reads them): the bodies that can reach the robot within the horizon
    (:func:`~uvnav.controllers.zhang2019_v2_bodies.reachable`), their boundary discs
    (:func:`~uvnav.controllers.zhang2019_v2_loop.boundary_discs_py`), each disc's reach (its
    radius plus the robot's radius ``prm[M_RADIUS]`` and the margin) and per body its discs,
    centre, velocity and bounding reach (:func:`uvnav.controllers.zhang2019_v2.bounding_reach`
    plus the same), computed as the numpy building blocks compute them."""
    v_max, horizon, spacing = prm[M_VMAX], prm[M_HORIZON], prm[M_SPACING]
    keep = reachable_py(scal, vel, v_max, horizon)
    n_keep = keep.shape[0]
    q, w, r, owner = boundary_discs_py(keep, scal, centre, vel, rings, ring_start, spacing)
    reach = np.empty(r.shape[0])
    for j in range(r.shape[0]):
        reach[j] = r[j] + prm[M_RADIUS] + prm[M_MARGIN]
    bodies = np.zeros((n_keep, 7))
    for j in range(owner.shape[0]):  # owner is non-decreasing: each body's first and end disc
        b = owner[j]
        if j == 0 or owner[j - 1] != b:
            bodies[b, 0] = j
        bodies[b, 1] = j + 1
    for i in range(n_keep):
        k = keep[i]
        bodies[i, 2], bodies[i, 3], bodies[i, 4], bodies[i, 5] = (
            centre[k, 0], centre[k, 1], vel[k, 0], vel[k, 1])  # fmt: skip
        if scal[k, 2] > 0.0:
            bound_r = scal[k, 3]
        else:
            uh = scal[k, 1] * horizon
            bound_r = scal[k, 3] * math.sqrt(1.0 + uh * uh) + 0.5 * spacing
        bodies[i, 6] = bound_r + prm[M_RADIUS] + prm[M_MARGIN]
    plan_paths_py(state, q, w, reach, owner, bodies, speeds, prm, out)


_COMPILED: dict[str, Callable[..., Any]] = {}


def _compiled_plan() -> Callable[..., Any]:
    """:func:`plan_paths_py` compiled by numba (on the first call, or loaded from numba's
    cache), calling the compiled copies of its helpers and of :mod:`uvnav.geometry.contact`'s."""
    if not _COMPILED:
        zhang2019_v2_loop._compiled_plan()
        kernels = (_approach, _ramp_turn, _window, _turn, advance, _box_far, _path_box,
                   _disc_along, _far, _chunk_bodies,
                   risk_along, _stops, _better, _keep, _groups, choose_on_paths_py, plan_paths_py,
                   plan_readings_py)  # fmt: skip
        bound = {**contact._kernels(), **zhang2019_v2_loop._COMPILED}
        _COMPILED.update(compile_family(kernels, bound=bound, error_model="numpy"))
    return _COMPILED["plan_readings_py"]


def plan_paths(
    state: FloatArray,
    table: tuple[FloatArray, FloatArray, FloatArray],
    rings: tuple[FloatArray, np.ndarray],
    speeds: FloatArray,
    prm: FloatArray,
) -> FloatArray:
    """:func:`plan_readings_py` (compiled when numba is enabled) of the readings read into
    arrays (``table``: :func:`~uvnav.controllers.zhang2019_v2_bodies.body_table`, ``rings``:
    :func:`~uvnav.controllers.zhang2019_v2_loop.outline_rings`): ``(vx, vy, ttc, preferred)``."""
    out = np.empty(4)
    fn = _compiled_plan() if numba_enabled() else plan_readings_py
    scal, centre, vel = table
    fn(state, scal, centre, vel, rings[0], rings[1], speeds, prm, out)
    return out
