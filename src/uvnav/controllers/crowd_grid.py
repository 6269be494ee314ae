"""A route around the crowd on a grid: the way point along the least-cost path over a map of
where people will be, for a vehicle that cannot sidestep at once.

uvnav's own layer, beyond the thesis, used by ``zhang2019-v2`` on a unicycle with acceleration
limits (:class:`~uvnav.controllers.crowd_route.CrowdRoute`, ``route_limited_weight``).  It is
the time-dependent planning on a social cost map of Kollmitz, Hsiao, Gaa and Burgard ("Time
dependent planning on a layered social cost map for human-aware robot navigation", ECMR 2015)
in its simplest form:

* **The map.**  Square cells of ``CELL`` m over the box around the robot and its (sub)goal,
  grown by ``PAD`` m; the goal farther than ``REACH`` m is replaced by the point ``REACH`` m
  toward it.  A cell whose centre lies ``d`` m from the robot is reached at ``t = d / V_max``
  (straight-line time: no path search per time); it costs
  ``sum_i exp(-max(||c - q_i - w_i min(t, horizon)|| - r_i, 0)^2 / (2 sigma^2))`` over every
  sensed body ``i`` (centre ``q_i``, velocity ``w_i``, radius ``r_i``), walking or standing:
  a crowd that has come to a halt is what a slow vehicle must go around.  A body more than
  ``CUT`` sigmas off adds nothing.
* **The path.**  Dijkstra over the 8-connected cells from the robot's cell to the goal's, a
  step between two cells costing its length times ``1 + weight * (mean of their costs)``.
* **The way point.**  The cell centre ``ahead`` m along the path (path length counted from the
  robot), or the goal when the path is shorter.

Measured on CrowdNav's circle with 20 humans, the unicycle limited to 1 m/s^2 and 2 rad/s^2
(tuning cases 0-99): ``zhang2019-v2`` 0.57 without a route, 0.64-0.68 with the fan of
:mod:`~uvnav.controllers.crowd_route`, 0.75 with this grid; on held-out cases 100-499 0.531
without, 0.741 with it (``docs/design-notes.md``).  One search is one compiled call (numba when
enabled, plain Python otherwise), about 0.24 ms for 20 people over a 16 x 8 m box.  Units:
metres, seconds.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.kernels3d import compile_family, numba_enabled

#: the side of a cell [m]
CELL = 0.25
#: the margin [m] of the map around the robot and the (sub)goal
PAD = 4.0
#: a goal farther than this [m] is planned to the point this far toward it
REACH = 10.0
#: a body farther than this many sigmas from a cell adds nothing to it
CUT = 5.0
#: the spread [m] of a body's cost around where it will be, for the law's route
GRID_SIGMA = 0.6
#: how far along the path [m] the law's way point lies
GRID_AHEAD = 2.0


def exposure_map_py(x0: float, y0: float, px: float, py: float, bodies: FloatArray, v: float,
                    horizon: float, sigma: float, out: FloatArray) -> None:  # fmt: skip
    """The module docstring's cost of each cell of ``out`` (nx, ny), cell ``(i, j)`` centred
    at ``(x0 + (i + 0.5) CELL, y0 + (j + 0.5) CELL)``, reached from the robot ``(px, py)`` at
    ``v`` [m/s]; ``bodies`` (N, 5): centre x, y [m], velocity x, y [m/s], radius [m].

    >>> out = np.zeros((3, 1))  # cells centred at x = 0, 0.25 and 0.5 m
    >>> exposure_map_py(-0.125, -0.125, 0.0, 0.0, np.array([[0.0, 0.0, 0.0, 0.0, 0.3]]), 1.0,
    ...                 2.0, 0.5, out)
    >>> out.round(3).ravel().tolist()  # within the body: 1; 0.2 m past its edge: exp(-0.08)
    [1.0, 1.0, 0.923]
    """
    far = CUT * sigma
    for i in range(out.shape[0]):
        cx = x0 + (i + 0.5) * CELL
        for j in range(out.shape[1]):
            cy = y0 + (j + 0.5) * CELL
            t = min(math.sqrt((cx - px) ** 2 + (cy - py) ** 2) / v, horizon)
            total = 0.0
            for b in range(bodies.shape[0]):
                ex = cx - bodies[b, 0] - bodies[b, 2] * t
                ey = cy - bodies[b, 1] - bodies[b, 3] * t
                gap = math.sqrt(ex * ex + ey * ey) - bodies[b, 4]
                if gap <= 0.0:
                    total += 1.0
                elif gap < far:
                    total += math.exp(-0.5 * (gap / sigma) ** 2)
            out[i, j] = total


def least_cost_path_py(cost: FloatArray, si: int, sj: int, gi: int, gj: int, weight: float,
                       path: np.ndarray) -> int:  # fmt: skip
    """Dijkstra over the 8-connected cells of ``cost`` (nx, ny) from ``(si, sj)`` to ``(gi,
    gj)``, a step costing its length (in cells) times ``1 + weight * (mean of the two cells'
    costs)``: the cells of the cheapest path, robot first, as flat indices ``i * ny + j`` in
    ``path`` (nx * ny,); returns how many.

    >>> cost = np.zeros((3, 3)); cost[1, :2] = 10.0  # a wall with a gap at the top
    >>> path = np.zeros(9, dtype=np.int64)
    >>> n = least_cost_path_py(cost, 0, 0, 2, 0, 1.0, path)
    >>> [divmod(int(k), 3) for k in path[:n]]
    [(0, 0), (0, 1), (1, 2), (2, 1), (2, 0)]
    """
    nx, ny = cost.shape
    dist = np.full(nx * ny, np.inf)
    prev = np.full(nx * ny, -1, dtype=np.int64)
    start, goal = si * ny + sj, gi * ny + gj
    dist[start] = 0.0
    heap = [(0.0, start)]
    while heap:
        d, k = heapq.heappop(heap)
        if k == goal:
            break
        if d > dist[k]:
            continue
        i, j = k // ny, k % ny
        for di in range(-1, 2):
            for dj in range(-1, 2):
                a, b = i + di, j + dj
                if (di == 0 and dj == 0) or a < 0 or b < 0 or a >= nx or b >= ny:
                    continue
                step = math.sqrt(di * di + dj * dj)
                nd = d + step * (1.0 + weight * 0.5 * (cost[i, j] + cost[a, b]))
                if nd < dist[a * ny + b]:
                    dist[a * ny + b] = nd
                    prev[a * ny + b] = k
                    heapq.heappush(heap, (nd, a * ny + b))
    n = 0
    k = goal
    while k >= 0:
        path[n] = k
        n += 1
        k = prev[k] if k != start else -1
    path[:n] = path[:n][::-1].copy()
    return n


def grid_way_point_py(px: float, py: float, gx: float, gy: float, bodies: FloatArray, v: float,
                      horizon: float, sigma: float, weight: float, ahead: float,
                      out: FloatArray) -> None:  # fmt: skip
    """The module docstring's way point from the robot ``(px, py)`` toward the goal ``(gx,
    gy)`` [m] into ``out`` (2,): :func:`exposure_map_py`, :func:`least_cost_path_py`, then the
    cell centre ``ahead`` [m] along the path (the goal, or the sub-goal ``REACH`` m toward it,
    when the path is shorter)."""
    dx, dy = gx - px, gy - py
    dist = math.sqrt(dx * dx + dy * dy)
    if dist > REACH:
        gx, gy = px + dx * (REACH / dist), py + dy * (REACH / dist)
    x0, y0 = min(px, gx) - PAD, min(py, gy) - PAD
    nx = int(math.ceil((max(px, gx) + PAD - x0) / CELL))  # noqa: RUF046 (numba: a float)
    ny = int(math.ceil((max(py, gy) + PAD - y0) / CELL))  # noqa: RUF046
    cost = np.empty((nx, ny))
    exposure_map_py(x0, y0, px, py, bodies, v, horizon, sigma, cost)
    si, sj = min(int((px - x0) / CELL), nx - 1), min(int((py - y0) / CELL), ny - 1)
    gi, gj = min(int((gx - x0) / CELL), nx - 1), min(int((gy - y0) / CELL), ny - 1)
    path = np.empty(nx * ny, dtype=np.int64)
    n = least_cost_path_py(cost, si, sj, gi, gj, weight, path)
    out[0], out[1] = gx, gy
    walked, lx, ly = 0.0, px, py
    for q in range(1, n):
        cx = x0 + (path[q] // ny + 0.5) * CELL
        cy = y0 + (path[q] % ny + 0.5) * CELL
        walked += math.sqrt((cx - lx) ** 2 + (cy - ly) ** 2)
        lx, ly = cx, cy
        if walked >= ahead:
            out[0], out[1] = cx, cy
            return


_COMPILED: dict[str, Callable[..., Any]] = {}


def grid_way_point(
    position: FloatArray, goal: FloatArray, bodies: FloatArray, v_max: float, horizon: float,
    sigma: float, weight: float, ahead: float,
) -> FloatArray:  # fmt: skip
    """:func:`grid_way_point_py` (compiled when numba is enabled): the way point [m], (2,)."""
    if not _COMPILED and numba_enabled():
        fam = (exposure_map_py, least_cost_path_py, grid_way_point_py)
        _COMPILED.update(compile_family(fam))
    fn = _COMPILED["grid_way_point_py"] if numba_enabled() else grid_way_point_py
    out = np.empty(2)
    fn(float(position[0]), float(position[1]), float(goal[0]), float(goal[1]),
       np.ascontiguousarray(bodies, dtype=float), float(v_max), float(horizon), float(sigma),
       float(weight), float(ahead), out)  # fmt: skip
    return out
