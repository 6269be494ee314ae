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
  ``CUT`` sigmas off adds nothing.  Optionally (``forecast`` > 0) each body is instead where a
  crowd rollout puts it (:mod:`~uvnav.controllers.crowd_forecast`, :func:`exposure_track_py`).
* **The path.**  Dijkstra over the 8-connected cells from the robot's cell to the goal's, a
  step between two cells costing its length times ``1 + weight * (mean of their costs)``
  (:func:`uvnav.planners.search.costed_dijkstra`, scipy's).
* **The way point.**  The cell centre ``ahead`` m along the path (path length counted from the
  robot), or the goal when the path is shorter.

Measured on CrowdNav's circle with 20 humans, the unicycle limited to 1 m/s^2 and 2 rad/s^2
(tuning cases 0-99): ``zhang2019-v2`` 0.57 without a route, 0.64-0.68 with the fan of
:mod:`~uvnav.controllers.crowd_route`, 0.75 with this grid; on held-out cases 100-499 0.531
without, 0.741 with it (``docs/design-notes.md``).  One search is the exposure map in one
compiled call (numba when enabled, plain Python otherwise) and scipy's Dijkstra: 0.56 ms CPU
for 20 people over a 16 x 8 m box.  Units: metres, seconds.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from uvnav.controllers.crowd_forecast import FORECAST_STEP, body_at, crowd_forecast
from uvnav.controllers.crowd_forecast import kernel as forecast_kernel
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.kernels3d import compile_family, numba_enabled
from uvnav.planners.search import costed_dijkstra

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


def exposure_track_py(x0: float, y0: float, px: float, py: float, track: FloatArray,
                      radii: FloatArray, step: float, v: float, horizon: float, sigma: float,
                      out: FloatArray) -> None:  # fmt: skip
    """:func:`exposure_map_py` with each body where ``track`` (K + 1, N, 2: centres every
    ``step`` [s], :func:`~uvnav.controllers.crowd_forecast.crowd_forecast`) puts it at the
    time the robot reaches the cell (capped at ``horizon`` [s]); ``radii`` (N,) [m].

    >>> out = np.zeros((3, 1))  # the body walks 1 m/s along +x: at 0.5 m by 0.5 s
    >>> track = np.array([[[0.0, 0.0]], [[0.25, 0.0]], [[0.5, 0.0]]])
    >>> exposure_track_py(-0.125, -0.125, 0.0, 0.0, track, np.array([0.1]), 0.25, 1.0, 2.0,
    ...                   0.5, out)
    >>> out.round(3).ravel().tolist()  # each cell reached as the body gets there
    [1.0, 1.0, 1.0]
    """
    far = CUT * sigma
    for i in range(out.shape[0]):
        cx = x0 + (i + 0.5) * CELL
        for j in range(out.shape[1]):
            cy = y0 + (j + 0.5) * CELL
            t = min(math.sqrt((cx - px) ** 2 + (cy - py) ** 2) / v, horizon)
            total = 0.0
            for b in range(track.shape[1]):
                bx, by = body_at(track, b, t, step)
                gap = math.sqrt((cx - bx) ** 2 + (cy - by) ** 2) - radii[b]
                if gap <= 0.0:
                    total += 1.0
                elif gap < far:
                    total += math.exp(-0.5 * (gap / sigma) ** 2)
            out[i, j] = total


def grid_way_point(
    position: FloatArray, goal: FloatArray, bodies: FloatArray, v_max: float, horizon: float,
    sigma: float, weight: float, ahead: float, forecast: float = 0.0,
) -> FloatArray:  # fmt: skip
    """The module docstring's way point [m], (2,), from the robot at ``position`` toward
    ``goal``: :func:`exposure_map_py` (compiled when numba is enabled), the cheapest path over it
    (:func:`uvnav.planners.search.costed_dijkstra`), then the cell centre ``ahead`` [m] along
    the path (the goal, or the sub-goal ``REACH`` m toward it, when the path is shorter).
    ``forecast`` > 0: the bodies are forecast by a crowd rollout over ``forecast`` [s]
    (:func:`~uvnav.controllers.crowd_forecast.crowd_forecast`, :func:`exposure_track_py`)
    instead of at constant velocity over ``horizon``."""
    px, py = float(position[0]), float(position[1])
    gx, gy = float(goal[0]), float(goal[1])
    dist = math.hypot(gx - px, gy - py)
    if dist > REACH:
        gx, gy = px + (gx - px) * (REACH / dist), py + (gy - py) * (REACH / dist)
    x0, y0 = min(px, gx) - PAD, min(py, gy) - PAD
    nx = math.ceil((max(px, gx) + PAD - x0) / CELL)
    ny = math.ceil((max(py, gy) + PAD - y0) / CELL)
    cost = np.empty((nx, ny))
    table = np.ascontiguousarray(bodies, dtype=float)
    if forecast > 0.0:
        _kernel("exposure_track_py")(x0, y0, px, py, crowd_forecast(table, forecast),
                                     np.ascontiguousarray(table[:, 4]), FORECAST_STEP,
                                     float(v_max), float(forecast), float(sigma), cost)  # fmt: skip
    else:
        _kernel("exposure_map_py")(x0, y0, px, py, table, float(v_max), float(horizon),
                                   float(sigma), cost)  # fmt: skip

    def cell(x: float, y: float) -> tuple[int, int]:
        return min(int((x - x0) / CELL), nx - 1), min(int((y - y0) / CELL), ny - 1)

    path = costed_dijkstra(cost, cell(px, py), cell(gx, gy), weight=weight).cells
    centres = np.array([x0, y0]) + (path[1:] + 0.5) * CELL
    walked = np.cumsum(np.hypot(*np.diff(np.vstack(([px, py], centres)), axis=0).T))
    far = np.flatnonzero(walked >= ahead)
    return centres[far[0]].copy() if len(far) else np.array([gx, gy])


_COMPILED: dict[str, Callable[..., Any]] = {}


def _kernel(name: str) -> Callable[..., Any]:
    """:func:`exposure_map_py` or :func:`exposure_track_py` by ``name``, compiled by numba when
    it is enabled (on the first call, or from numba's cache)."""
    if not numba_enabled():
        plain: dict[str, Callable[..., Any]] = {
            "exposure_map_py": exposure_map_py, "exposure_track_py": exposure_track_py,
        }  # fmt: skip
        return plain[name]
    if not _COMPILED:
        _COMPILED.update(compile_family((exposure_map_py,)))
        bound = {"body_at": forecast_kernel("body_at")}
        _COMPILED.update(compile_family((exposure_track_py,), bound=bound))
    return _COMPILED[name]
