"""A route around the crowd searched over cells and time: the full form of the time-dependent
planning of Kollmitz, Hsiao, Gaa and Burgard (ECMR 2015) that :mod:`uvnav.controllers.crowd_grid`
approximates, with a move that waits in place.

* **The layers.**  The grid of :func:`~uvnav.controllers.crowd_grid.grid_way_point` (``CELL`` m
  cells over the box round the robot and its (sub)goal, grown by ``PAD`` m), one exposure map
  per ``step`` [s] of time up to ``span`` [s]: layer ``k`` costs the bodies where they will be
  at ``min((k + 0.5) step, horizon)`` (constant velocity), the last layer standing for every
  later time.
* **The search.**  Dijkstra over (cell, layer) from the robot's cell at time 0, the arrival
  time accumulated along the path at ``speed`` [m/s]: a move to one of the 8 neighbours takes
  its length / ``speed`` and costs its length times ``1 + weight * (mean of the two cells'
  costs, each read in the layer it is reached in)``; waiting in place takes ``step`` and costs
  ``speed * step`` (the metres that time would have driven) times ``1 + weight * (the cell's
  cost)``.  The first state popped in the goal's cell ends the search.
* **The way point.**  Where the path puts the robot ``ahead / speed`` [s] from now (a waiting
  path keeps it where it is), or the goal when the path arrives sooner.

Units: metres, seconds.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from uvnav.controllers.crowd_grid import CELL, PAD, REACH, _exposure
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.kernels3d import compile_family, numba_enabled


def _push(keys: FloatArray, vals: np.ndarray, size: int, key: float, val: int) -> int:
    """Push ``(key, val)`` on the binary heap held in ``keys``/``vals`` of ``size`` entries;
    returns the new size."""
    i = size
    keys[i], vals[i] = key, val
    while i > 0:
        up = (i - 1) // 2
        if keys[up] <= keys[i]:
            break
        keys[up], keys[i] = keys[i], keys[up]
        vals[up], vals[i] = vals[i], vals[up]
        i = up
    return size + 1


def _pop(keys: FloatArray, vals: np.ndarray, size: int) -> int:
    """Remove the heap's least entry (left in ``keys[size - 1]``, ``vals[size - 1]``); returns
    the new size."""
    last = size - 1
    keys[0], keys[last] = keys[last], keys[0]
    vals[0], vals[last] = vals[last], vals[0]
    i = 0
    while True:
        a, b, m = 2 * i + 1, 2 * i + 2, i
        if a < last and keys[a] < keys[m]:
            m = a
        if b < last and keys[b] < keys[m]:
            m = b
        if m == i:
            break
        keys[m], keys[i] = keys[i], keys[m]
        vals[m], vals[i] = vals[i], vals[m]
        i = m
    return last


def timed_search_py(cost: FloatArray, step: float, speed: float, start: np.ndarray,
                    goal: np.ndarray, weight: float, out: FloatArray) -> int:  # fmt: skip
    """The module docstring's search over ``cost`` (L, nx, ny) from cell ``start`` (2,) to cell
    ``goal`` (2,); the path's states from the start, cell i, j and arrival time [s], into
    ``out`` (at least L nx ny rows, 3); returns how many (0: the goal cannot be reached)."""
    n_l, nx, ny = cost.shape
    n = n_l * nx * ny
    best = np.full(n, np.inf)
    when = np.zeros(n)
    parent = np.full(n, -1, dtype=np.int64)
    keys = np.empty(9 * n + 1)
    vals = np.empty(9 * n + 1, dtype=np.int64)
    s0 = start[0] * ny + start[1]
    best[s0] = 0.0
    size = _push(keys, vals, 0, 0.0, s0)
    found = -1
    diag = CELL * math.sqrt(2.0)
    while size > 0:
        size = _pop(keys, vals, size)
        c, s = keys[size], vals[size]
        if c > best[s]:
            continue
        k, rest = s // (nx * ny), s % (nx * ny)
        i, j = rest // ny, rest % ny
        if i == goal[0] and j == goal[1]:
            found = s
            break
        t = when[s]
        here = cost[k, i, j]
        for di in range(-1, 2):
            for dj in range(-1, 2):
                ni, nj = i + di, j + dj
                if ni < 0 or nj < 0 or ni >= nx or nj >= ny:
                    continue
                if di == 0 and dj == 0:
                    if k == n_l - 1:
                        continue  # the last layer stands for all later times: no wait
                    nt = t + step
                    k2 = min(int(nt / step + 1e-9), n_l - 1)
                    add = speed * step * (1.0 + weight * here)
                else:
                    length = diag if di != 0 and dj != 0 else CELL
                    nt = t + length / speed
                    k2 = min(int(nt / step), n_l - 1)
                    add = length * (1.0 + weight * 0.5 * (here + cost[k2, ni, nj]))
                s2 = (k2 * nx + ni) * ny + nj
                c2 = c + add
                if c2 < best[s2]:
                    best[s2], when[s2], parent[s2] = c2, nt, s
                    size = _push(keys, vals, size, c2, s2)
    if found < 0:
        return 0
    m = 0
    s = found
    while s >= 0:
        rest = s % (nx * ny)
        out[m, 0], out[m, 1], out[m, 2] = rest // ny, rest % ny, when[s]
        m += 1
        s = parent[s]
    out[:m] = out[:m][::-1].copy()
    return m


def timed_way_point(
    position: FloatArray, goal: FloatArray, bodies: FloatArray, v_max: float, horizon: float,
    sigma: float, weight: float, ahead: float, speed: float, step: float, span: float,
) -> FloatArray:  # fmt: skip
    """The module docstring's way point [m], (2,), from the robot at ``position`` toward
    ``goal`` over ``bodies`` (:func:`~uvnav.controllers.crowd_grid.grid_bodies`); ``speed``: the
    planned speed as a share of ``v_max``."""
    px, py = float(position[0]), float(position[1])
    gx, gy = float(goal[0]), float(goal[1])
    dist = math.hypot(gx - px, gy - py)
    if dist > REACH:
        gx, gy = px + (gx - px) * (REACH / dist), py + (gy - py) * (REACH / dist)
    x0, y0 = min(px, gx) - PAD, min(py, gy) - PAD
    nx = math.ceil((max(px, gx) + PAD - x0) / CELL)
    ny = math.ceil((max(py, gy) + PAD - y0) / CELL)
    n_l = max(1, math.ceil(span / step))
    cost = np.empty((n_l, nx, ny))
    b = np.ascontiguousarray(bodies, dtype=float)
    moved = b.copy()
    for k in range(n_l):
        t = min((k + 0.5) * step, horizon)
        moved[:, :2] = b[:, :2] + b[:, 2:4] * t
        _exposure()(x0, y0, px, py, moved, 1e12, 1e-12, float(sigma), cost[k])

    def cell(x: float, y: float) -> np.ndarray:
        return np.array([min(int((x - x0) / CELL), nx - 1), min(int((y - y0) / CELL), ny - 1)])

    v = speed * v_max
    out = np.empty((n_l * nx * ny, 3))
    m = _search()(cost, float(step), float(v), cell(px, py), cell(gx, gy), float(weight), out)
    if m < 2:
        return np.array([gx, gy])
    tau = ahead / v
    path = out[:m]
    later = np.flatnonzero(path[:, 2] >= tau)
    if not len(later):
        return np.array([gx, gy])
    k = int(later[0])
    if k == 0:
        return np.array([px, py])
    a, b2 = path[k - 1], path[k]
    u = (tau - a[2]) / max(b2[2] - a[2], 1e-9)
    ca = np.array([px, py]) if k - 1 == 0 else np.array([x0, y0]) + (a[:2] + 0.5) * CELL
    cb = np.array([x0, y0]) + (b2[:2] + 0.5) * CELL
    return ca + u * (cb - ca)


_COMPILED: dict[str, Callable[..., Any]] = {}


def _search() -> Callable[..., Any]:
    """:func:`timed_search_py`, compiled by numba when it is enabled."""
    if not numba_enabled():
        return timed_search_py
    if not _COMPILED:
        _COMPILED.update(compile_family((_push, _pop, timed_search_py)))
    return _COMPILED["timed_search_py"]
