"""A route around the crowd on a grid: the way point along the least-cost path over a map of
where people will be, for a vehicle that cannot sidestep at once.

uvnav's own layer, beyond the thesis, used by ``zhang2019-v2`` on a unicycle with acceleration
limits, and on every unicycle with ``route_grid="all"``
(:class:`~uvnav.controllers.crowd_route.CrowdRoute`, ``route_grid_weight``).  It is
the time-dependent planning on a social cost map of Kollmitz, Hsiao, Gaa and Burgard ("Time
dependent planning on a layered social cost map for human-aware robot navigation", ECMR 2015)
in its simplest form:

* **The map.**  Square cells of ``CELL`` m over the box around the robot and its (sub)goal,
  grown by ``PAD`` m; the goal farther than ``REACH`` m is replaced by the point ``REACH`` m
  toward it.  A cell whose centre lies ``d`` m from the robot is reached at ``t = d / V_max``
  (straight-line time: no path search per time); it costs
  ``sum_i exp(-max(||c - q_i - w_i min(t, horizon)|| - r_i, 0)^2 / (2 sigma^2))`` over every
  sensed body ``i`` (centre ``q_i``, velocity ``w_i``, radius ``r_i``), walking or standing:
  a crowd that has come to a halt is what a slow vehicle must go around.  A polygon (a wall)
  counts as discs along its outline (:func:`grid_bodies`): its bounding disc would cover a
  corridor or a doorway whole.  A body more than ``CUT`` sigmas off adds nothing.
* **The path.**  Dijkstra over the 8-connected cells from the robot's cell to the goal's, a
  step between two cells costing its length times ``1 + weight * (mean of their costs)``
  (:func:`uvnav.planners.search.costed_dijkstra`, scipy's).
* **The way point.**  The cell centre ``ahead`` m along the path (path length counted from the
  robot), or the goal when the path is shorter.

Measured on CrowdNav's circle with 20 humans, the unicycle limited to 1 m/s^2 and 2 rad/s^2
(tuning cases 0-99): ``zhang2019-v2`` 0.57 without a route, 0.64-0.68 with the fan of
:mod:`~uvnav.controllers.crowd_route`, 0.75 with this grid; on held-out cases 100-499 0.531
without, 0.741 with it, 0.831 with it and the law's capped spread for standing people
(``Zhang2019V2Params.still_cap``), 0.908 once the turn-then-move vehicle turned as its arc would
by each decision and the law checked its paths so (``docs/design-notes.md``).  One search is the
exposure map in one compiled call (numba when enabled, plain Python otherwise) and scipy's
Dijkstra: 0.31 ms CPU for 20 people on CrowdNav's circle (an 8 x 16 m box), 1.1 ms for 100
people over 15 x 15 m.
Units: metres, seconds.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from uvnav.controllers.zhang2019_v2_bodies import boundary_discs
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.kernels3d import compile_family, numba_enabled
from uvnav.planners.search import costed_dijkstra
from uvnav.sensors.observation import ObstacleReading

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
#: a polygon's outline is read as discs this far apart [m]
OUTLINE_SPACING = 2 * CELL


def grid_bodies(readings: tuple[ObstacleReading, ...]) -> FloatArray:
    """The sensed bodies as :func:`exposure_map_py`'s ``bodies`` (N, 5), finite rows only: a
    disc as itself, a polygon as discs along its outline ``OUTLINE_SPACING`` m apart, each of
    half that radius, moving with the body (:func:`~uvnav.controllers.zhang2019_v2_bodies.
    boundary_discs`, as v2 reads bodies), so that a wall costs where it stands, not over its
    bounding disc.

    >>> from uvnav.sensors.observation import ObstacleReading
    >>> z = np.zeros(2)
    >>> wall = np.array([[0.0, -2.0], [0.2, -2.0], [0.2, 2.0], [0.0, 2.0]])
    >>> rd = ObstacleReading(0, 1.0, z, np.array([0.1, 0.0]), z, 0.0, wall, 0.0, 2.0)
    >>> b = grid_bodies((rd,))
    >>> len(b), float(b[:, 4].max()), float(np.abs(b[:, 0] - 0.1).max())
    (18, 0.25, 0.1)
    """
    if not readings:
        return np.zeros((0, 5))
    centres, velocities, radii, _, _ = boundary_discs(readings, OUTLINE_SPACING)
    table = np.column_stack((centres, velocities, radii))
    return table[np.isfinite(table).all(axis=1)]


def exposure_map_py(x0: float, y0: float, px: float, py: float, bodies: FloatArray, v: float,
                    horizon: float, sigma: float, out: FloatArray) -> None:  # fmt: skip
    """The module docstring's cost of each cell of ``out`` (nx, ny), cell ``(i, j)`` centred
    at ``(x0 + (i + 0.5) CELL, y0 + (j + 0.5) CELL)``, reached from the robot ``(px, py)`` at
    ``v`` [m/s]; ``bodies`` (N, 5): centre x, y [m], velocity x, y [m/s], radius [m].

    A body is costed only in the cells of the box round its forecast track (from its centre to
    where it is at ``horizon``) grown by its radius and ``CUT`` sigmas: farther cells it adds
    nothing to, and the sum over the others, in body order, is the sum over all.

    >>> out = np.zeros((3, 1))  # cells centred at x = 0, 0.25 and 0.5 m
    >>> exposure_map_py(-0.125, -0.125, 0.0, 0.0, np.array([[0.0, 0.0, 0.0, 0.0, 0.3]]), 1.0,
    ...                 2.0, 0.5, out)
    >>> out.round(3).ravel().tolist()  # within the body: 1; 0.2 m past its edge: exp(-0.08)
    [1.0, 1.0, 0.923]
    """
    far = CUT * sigma
    n = bodies.shape[0]
    box = np.empty((n, 4))  # x low, x high, y low, y high [m]
    for b in range(n):
        grow = bodies[b, 4] + far + 1e-6 * (1.0 + abs(bodies[b, 0]) + abs(bodies[b, 1]))
        ex, ey = bodies[b, 0] + bodies[b, 2] * horizon, bodies[b, 1] + bodies[b, 3] * horizon
        box[b, 0], box[b, 1] = min(bodies[b, 0], ex) - grow, max(bodies[b, 0], ex) + grow
        box[b, 2], box[b, 3] = min(bodies[b, 1], ey) - grow, max(bodies[b, 1], ey) + grow
    row = np.empty(n, dtype=np.int64)
    for i in range(out.shape[0]):
        cx = x0 + (i + 0.5) * CELL
        m = 0
        for b in range(n):
            if box[b, 0] <= cx <= box[b, 1]:
                row[m] = b
                m += 1
        for j in range(out.shape[1]):
            cy = y0 + (j + 0.5) * CELL
            t = min(math.sqrt((cx - px) ** 2 + (cy - py) ** 2) / v, horizon)
            total = 0.0
            for k in range(m):
                b = row[k]
                if not box[b, 2] <= cy <= box[b, 3]:
                    continue
                ex = cx - bodies[b, 0] - bodies[b, 2] * t
                ey = cy - bodies[b, 1] - bodies[b, 3] * t
                gap = math.sqrt(ex * ex + ey * ey) - bodies[b, 4]
                if gap <= 0.0:
                    total += 1.0
                elif gap < far:
                    total += math.exp(-0.5 * (gap / sigma) ** 2)
            out[i, j] = total


def grid_way_point(
    position: FloatArray, goal: FloatArray, bodies: FloatArray, v_max: float, horizon: float,
    sigma: float, weight: float, ahead: float,
) -> FloatArray:  # fmt: skip
    """The module docstring's way point [m], (2,), from the robot at ``position`` toward
    ``goal``: :func:`exposure_map_py` (compiled when numba is enabled), the cheapest path over it
    (:func:`uvnav.planners.search.costed_dijkstra`), then the cell centre ``ahead`` [m] along
    the path (the goal, or the sub-goal ``REACH`` m toward it, when the path is shorter)."""
    px, py = float(position[0]), float(position[1])
    gx, gy = float(goal[0]), float(goal[1])
    dist = math.hypot(gx - px, gy - py)
    if dist > REACH:
        gx, gy = px + (gx - px) * (REACH / dist), py + (gy - py) * (REACH / dist)
    x0, y0 = min(px, gx) - PAD, min(py, gy) - PAD
    nx = math.ceil((max(px, gx) + PAD - x0) / CELL)
    ny = math.ceil((max(py, gy) + PAD - y0) / CELL)
    cost = np.empty((nx, ny))
    _exposure()(x0, y0, px, py, np.ascontiguousarray(bodies, dtype=float), float(v_max),
                float(horizon), float(sigma), cost)  # fmt: skip

    def cell(x: float, y: float) -> tuple[int, int]:
        return min(int((x - x0) / CELL), nx - 1), min(int((y - y0) / CELL), ny - 1)

    path = costed_dijkstra(cost, cell(px, py), cell(gx, gy), weight=weight).cells
    centres = np.array([x0, y0]) + (path[1:] + 0.5) * CELL
    walked = np.cumsum(np.hypot(*np.diff(np.vstack(([px, py], centres)), axis=0).T))
    far = np.flatnonzero(walked >= ahead)
    return centres[far[0]].copy() if len(far) else np.array([gx, gy])


_COMPILED: dict[str, Callable[..., Any]] = {}


def _exposure() -> Callable[..., Any]:
    """:func:`exposure_map_py`, compiled by numba when it is enabled (on the first call, or from
    numba's cache)."""
    if not numba_enabled():
        return exposure_map_py
    if not _COMPILED:
        _COMPILED.update(compile_family((exposure_map_py,)))
    return _COMPILED["exposure_map_py"]
