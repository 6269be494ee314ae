"""Where the sensed people will be: a short ORCA rollout of them among themselves, for the grid
route of a vehicle that cannot sidestep (:mod:`uvnav.controllers.crowd_grid`).

A constant-velocity forecast misses what a dense crowd does next: people converging on one
another slow down and swerve.  Here every sensed body (centre, velocity, radius; nothing else is
known to the law) is an ORCA agent (van den Berg et al., ISRR 2009; the project's port of RVO2,
:mod:`uvnav.controllers.orca_kernels`) among the other sensed bodies, the robot left out (the
people may not see it):

* **Preferred velocity.**  By default its current velocity, raised to ``FORECAST_SPEED``
  [m/s] along its heading when that is faster (0: never); a body slower than ``STILL`` [m/s]
  prefers to stand (its heading is unknown).  Its top speed is its preferred speed.  A caller
  may pass other preferred velocities (:func:`crowd_forecast`'s ``pref``).
* **ORCA.**  Time horizon ``FORECAST_TAU`` [s], neighbours within ``FORECAST_REACH`` [m], at most
  ``FORECAST_NEIGHBOURS`` of them, each agent taking half of the avoidance, its radius grown by
  ``FORECAST_MARGIN`` [m]; all decide at once from the same state every ``step`` [s], then move
  straight at their new velocities.

The result is each body's centre at ``0, step, 2 step, ...``; :func:`body_at` reads it at any
time in between (linear), the last forecast position beyond.

Measured on CrowdNav's circle with 20 humans (30 episodes, every 0.5 s, the humans' mean
displacement error): 0.336 m at 2 s and 1.04 m at 4 s against constant velocity's 0.355 and
1.05 m (0.274 against 0.298 m at 2 s for the humans within 2.5 m of the centre); raising the
preferred speed to 1 m/s (the humans' own) made it worse, 0.568 m at 2 s.  The grid route does
not gain from it (``docs/design-notes.md``), so it is off by default
(:class:`~uvnav.controllers.crowd_route.RouteParams`' ``route_forecast``).  Units: metres,
seconds.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from uvnav.controllers import orca_kernels
from uvnav.controllers.orca_kernels import agent_lines_py, neighbours_py, solve_lines_py
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.kernels3d import compile_family, numba_enabled

#: a body slower than this [m/s] is forecast to stand
STILL = 0.05
#: the speed [m/s] a walking body is forecast to regain (its own when faster; 0: its own)
FORECAST_SPEED = 0.0
#: the rollout's ORCA time horizon [s]
FORECAST_TAU = 5.0
#: the rollout's ORCA neighbour range [m]
FORECAST_REACH = 10.0
#: the rollout's ORCA neighbours per body, at most
FORECAST_NEIGHBOURS = 10
#: added to each body's radius [m] in the rollout
FORECAST_MARGIN = 0.01
#: the rollout's time step [s]
FORECAST_STEP = 0.25


def orca_rollout_py(
    bodies: FloatArray, pref: FloatArray, step: float, tau: float, reach: float,
    max_neighbors: int, margin: float, out: FloatArray,
) -> None:  # fmt: skip
    """The module docstring's rollout of ``bodies`` (N, 5: centre x, y [m], velocity x, y
    [m/s], radius [m]) toward their preferred velocities ``pref`` (N, 2) [m/s], each at most
    as fast as its preferred velocity, into ``out`` (K + 1, N, 2): the centres at ``0, step,
    ..., K step`` [s]; ``tau``, ``reach``, ``max_neighbors``, ``margin``: the module
    docstring's ``FORECAST_TAU``, ``FORECAST_REACH``, ``FORECAST_NEIGHBOURS``,
    ``FORECAST_MARGIN``.

    >>> out = np.zeros((3, 1, 2))  # one body alone walks on at its own speed
    >>> orca_rollout_py(np.array([[0.0, 0.0, 0.5, 0.0, 0.3]]), np.array([[0.5, 0.0]]), 0.25,
    ...                 5.0, 10.0, 10, 0.01, out)
    >>> out[:, 0, 0].tolist()
    [0.0, 0.125, 0.25]
    """
    n = bodies.shape[0]
    cap = max_neighbors if max_neighbors > 1 else 1
    pos = np.empty((n, 2))
    vel = np.empty((n, 2))
    new = np.empty((n, 2))
    top = np.empty(n)
    radii = np.empty(n)
    for i in range(n):
        pos[i, 0], pos[i, 1] = bodies[i, 0], bodies[i, 1]
        vel[i, 0], vel[i, 1] = bodies[i, 2], bodies[i, 3]
        radii[i] = bodies[i, 4] + margin
        top[i] = math.sqrt(pref[i, 0] ** 2 + pref[i, 1] ** 2)
        out[0, i, 0], out[0, i, 1] = pos[i, 0], pos[i, 1]
    idx = np.zeros(cap, dtype=np.int64)
    d2 = np.empty(cap)
    lines = np.empty((cap, 4))
    proj = np.empty((cap, 4))
    for k in range(1, out.shape[0]):
        for i in range(n):
            count = neighbours_py(i, pos, reach, cap, idx, d2)
            m = agent_lines_py(i, idx, count, pos, vel, radii, tau, step, 0.5, lines)
            x, y = solve_lines_py(lines, m, 0, top[i], pref[i, 0], pref[i, 1], proj)
            if not (math.isfinite(x) and math.isfinite(y)):
                x = y = 0.0
            new[i, 0], new[i, 1] = x, y
        for i in range(n):
            vel[i, 0], vel[i, 1] = new[i, 0], new[i, 1]
            pos[i, 0] += step * new[i, 0]
            pos[i, 1] += step * new[i, 1]
            out[k, i, 0], out[k, i, 1] = pos[i, 0], pos[i, 1]


def preferred_velocities(bodies: FloatArray) -> FloatArray:
    """Each body's preferred velocity [m/s], (N, 2), from what is sensed of it (module
    docstring): its heading at ``max(speed, FORECAST_SPEED)``, zero below ``STILL``.

    >>> preferred_velocities(np.array([[0.0, 0.0, 0.3, 0.4, 0.3], [1.0, 1.0, 0.0, 0.01, 0.3]]))
    array([[0.3, 0.4],
           [0. , 0. ]])
    """
    vel = np.asarray(bodies, dtype=float)[:, 2:4]
    speed = np.hypot(vel[:, 0], vel[:, 1])
    scale = np.divide(np.maximum(speed, FORECAST_SPEED), speed, out=np.zeros_like(speed),
                      where=speed >= STILL)  # fmt: skip
    return vel * scale[:, None]


def body_at(track: FloatArray, b: int, t: float, step: float) -> tuple[float, float]:
    """Body ``b``'s centre [m] at ``t`` >= 0 [s] on ``track`` (K + 1, N, 2), centres every
    ``step`` [s] (linear in between; the last beyond).

    >>> body_at(np.array([[[0.0, 0.0]], [[1.0, 2.0]]]), 0, 0.125, 0.25)
    (0.5, 1.0)
    """
    last = track.shape[0] - 1
    f = t / step
    k = int(f)
    if k >= last:
        return float(track[last, b, 0]), float(track[last, b, 1])
    a = f - k
    x = track[k, b, 0] + a * (track[k + 1, b, 0] - track[k, b, 0])
    y = track[k, b, 1] + a * (track[k + 1, b, 1] - track[k, b, 1])
    return float(x), float(y)


def crowd_forecast(
    bodies: FloatArray, horizon: float, pref: FloatArray | None = None
) -> FloatArray:
    """The sensed ``bodies`` (N, 5) rolled out (:func:`orca_rollout_py`, compiled when numba is
    enabled, with the module's constants) to ``horizon`` [s] in steps of ``FORECAST_STEP``:
    their centres (K + 1, N, 2), ``K = ceil(horizon / FORECAST_STEP)``; ``pref`` (N, 2): their
    preferred velocities (:func:`preferred_velocities` when ``None``)."""
    steps = max(math.ceil(horizon / FORECAST_STEP - 1e-9), 1)
    table = np.ascontiguousarray(bodies, dtype=float)
    out = np.empty((steps + 1, table.shape[0], 2))
    kernel("orca_rollout_py")(
        table, np.ascontiguousarray(preferred_velocities(table) if pref is None else pref),
        FORECAST_STEP, FORECAST_TAU, FORECAST_REACH, FORECAST_NEIGHBOURS, FORECAST_MARGIN, out,
    )  # fmt: skip
    return out


#: this module's kernels (they call :mod:`~uvnav.controllers.orca_kernels`' compiled ones)
FAMILY: tuple[Callable[..., Any], ...] = (orca_rollout_py, body_at)
#: the ORCA kernels the rollout calls
_ORCA_CALLEES = ("neighbours_py", "agent_lines_py", "solve_lines_py")
_KERNELS: dict[str, Callable[..., Any]] = {}


def kernel(name: str) -> Callable[..., Any]:
    """The function ``name`` of :data:`FAMILY`, compiled by numba on first use when it is
    enabled, else the Python function."""
    if not numba_enabled():
        return {f.__name__: f for f in FAMILY}[name]
    if not _KERNELS:
        bound = {c: orca_kernels.kernel(c) for c in _ORCA_CALLEES}
        _KERNELS.update(compile_family(FAMILY, bound=bound))
    return _KERNELS[name]
