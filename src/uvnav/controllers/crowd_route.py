"""A route around the crowd: the way point a local law steers for, chosen by crowd exposure.

uvnav's own layer, beyond the thesis: ``zhang2019-holonomic-v2`` and ``zhang2019-v2`` (on by
default in both; the unicycle's searched every 0.75 s over the 12 nearest walkers) steer for the
way point it gives instead of the goal itself.
The idea is the layered social cost map of mobile-robot navigation stacks (Kollmitz, Hsiao,
Gaa, Burgard, "Time dependent planning on a layered social cost map for human-aware robot
navigation", ECMR 2015): a route is judged by its length plus what it costs the people it
passes, each person's cost a Gaussian of the distance to where they will be, and the local law
avoids collisions on the way.  Here the routes are a fan rather than a grid search, which
keeps a decision within tens of microseconds:

* **Routes.**  The direct one (robot -> goal) and, for each of ``FAN`` - 1 directions within
  +-90 degrees of the goal's, robot -> way point -> goal, the way point ``lookahead`` [m]
  ahead along that direction (the goal's distance when that is shorter); plus the way point
  held from the last decision, which pays ``hold`` [m] less (a route is not dropped for a
  marginally better one every decision).
* **Exposure.**  Each leg of a route is cut into equal pieces of at most ``SPACING`` m, sampled
  at their midpoints; a sample ``s`` reached at time ``t = arc length / V_max`` costs
  ``sum_i exp(-max(||s - c_i - v_i min(t, horizon)|| - r_i, 0)^2 / (2 sigma^2))`` per metre,
  over the bodies ``i`` that move at ``min_speed`` or faster (centre ``c_i``, velocity ``v_i``,
  radius ``r_i``: a polygon's bounding radius).  People standing still are left to the local
  law, which keeps clear of them; counting them would hold the robot off a goal beside which
  someone stands.  One loop over routes, samples and bodies (:func:`route_costs_py`, compiled
  by numba when it is enabled) visits each body's samples within its reach only and skips the
  pairs more than ``CUT`` sigmas apart.  ``route_bodies`` > 0 costs only the nearest that
  many walking people.
* **Choice.**  The route of least ``length + weight * exposure`` [m].  The robot steers for its
  way point, or for the goal when the direct route wins, the goal is within ``DIRECT_WITHIN``
  m, no moving body is sensed, or the way point is within ``REACHED`` m.  With
  ``route_period`` > 0 the fan is searched again only once that period has passed (or the way
  point is reached), the last choice held in between.

On a unicycle with acceleration limits (:meth:`CrowdRoute.reset` is told), and with
``route_grid="all"`` on every unicycle, the route is planned on a grid instead
(:mod:`uvnav.controllers.crowd_grid`, ``route_grid_weight``): a path that bends round a crowd of
any shape, standing people counted, for a vehicle that cannot sidestep once the crowd is upon
it.  ``route_grid_period`` holds its way point between searches as ``route_period`` holds the
fan's.

The bodies are those the robot senses (a person out of range costs nothing), with the rates the
readings give (true or estimated).  Measured on the harder crowd (``crowd-dynamic``, tuning
cases 0-99, holonomic): success 0.84 -> 0.98, intrusion ratio 0.205 -> 0.023, time to goal
26.4 -> 18.0 s; the design notes hold the held-out figures.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from uvnav.controllers.base import check_params
from uvnav.controllers.crowd_grid import GRID_AHEAD, GRID_SIGMA, grid_bodies, grid_way_point
from uvnav.controllers.zhang2019_v2_bodies import body_table
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.kernels3d import compile_family, numba_enabled
from uvnav.sensors.observation import ObstacleReading

#: routes in the fan: the direct one and ``FAN - 1`` way points (the goal's direction excluded)
FAN = 13
#: the longest distance between two samples of a route's leg [m]
SPACING = 0.25
#: the goal closer than this [m]: steer for it
DIRECT_WITHIN = 1.0
#: a way point closer than this [m]: steer for the goal
REACHED = 0.5
#: a body farther than this many sigmas from a sample adds nothing to it
CUT = 5.0
#: added to a body's reach [m] when its samples are culled (rounding never drops one in reach)
REACH_SLACK = 1e-6
#: :attr:`RouteParams.route_grid`'s values
GRID_VEHICLES = ("limited", "all")
#: the fan's directions [rad] from the goal's, the goal's own left out
_FAN_ANGLES = np.delete(np.linspace(-math.pi / 2, math.pi / 2, FAN), FAN // 2)


@dataclass(frozen=True)
class RouteParams:
    """A law's parameters of the route layer (module docstring; the law gives the speed below
    which a body costs nothing, :class:`CrowdRoute`'s ``min_speed``).

    Attributes:
        route_weight: metres a route may grow to spare one unit of exposure to walking people
            (a metre walked through one); 0 turns the route off (the law steers for the goal).
        route_sigma: spread [m] of a walking person's cost around where they will be.
        route_lookahead: distance [m] of the route's way points from the robot.
        route_hold: metres the way point held from the last decision is spared.
        route_horizon: how far ahead [s] the people's positions are forecast.
        route_period: the fan is searched at most once every ``route_period`` [s]; in between
            the law steers for the point the last search chose (while the goal is farther than
            ``DIRECT_WITHIN`` m and the way point than ``REACHED`` m); 0: every decision.
        route_bodies: only the nearest ``route_bodies`` walking people are costed; 0: all.
        route_grid_weight: on the unicycles ``route_grid`` names, the route is planned on a
            grid instead (:mod:`~uvnav.controllers.crowd_grid`, every body costed, walking or
            standing) with this weight [m per unit of exposure], whatever ``route_weight``
            says; 0: no grid route (the fan, as on the unicycles ``route_grid`` leaves out).
        route_grid: which unicycles plan on the grid: ``"limited"``, those with acceleration
            limits; ``"all"``, every one (the ideal unicycle too; with ``route_grid_period`` 1 s
            the design notes measure its gains and its cost).  The holonomic law plans no
            grid route.
        route_grid_period: the grid is searched at most once every ``route_grid_period`` [s],
            the way point held in between as ``route_period`` holds the fan's; 0: every
            decision.
    """

    route_weight: float = 0.0
    route_sigma: float = 0.8
    route_lookahead: float = 4.0
    route_hold: float = 0.5
    route_horizon: float = 2.0
    route_period: float = 0.0
    route_bodies: int = 0
    route_grid_weight: float = 3.0
    route_grid: str = "limited"
    route_grid_period: float = 0.0

    def __post_init__(self) -> None:
        check_params(self, positive=("route_sigma", "route_lookahead", "route_horizon"),
                     non_negative=("route_weight", "route_hold", "route_period",
                                   "route_grid_weight", "route_grid_period"))  # fmt: skip
        if not isinstance(self.route_bodies, int) or self.route_bodies < 0:
            raise ValueError(f"route_bodies must be an integer >= 0 (got {self.route_bodies!r})")
        if self.route_grid not in GRID_VEHICLES:
            raise ValueError(f"route_grid must be one of {', '.join(GRID_VEHICLES)} "
                             f"(got {self.route_grid!r})")  # fmt: skip


def fan_way_points(position: FloatArray, goal: FloatArray, lookahead: float) -> FloatArray:
    """The goal, then the ``FAN - 1`` way points of the fan, (FAN, 2) [m].

    >>> w = fan_way_points(np.zeros(2), np.array([10.0, 0.0]), 4.0)
    >>> w.shape, w[0].tolist(), np.round(w[1], 6).tolist(), np.round(w[-1], 6).tolist()
    ((13, 2), [10.0, 0.0], [0.0, -4.0], [0.0, 4.0])
    """
    gap = goal - position
    reach = min(lookahead, math.hypot(gap[0], gap[1]))
    angles = math.atan2(gap[1], gap[0]) + _FAN_ANGLES
    ways = position + reach * np.column_stack((np.cos(angles), np.sin(angles)))
    return np.vstack((goal[None], ways))


def _near_leg(ax: float, ay: float, dx: float, dy: float, n: int, bodies: FloatArray,
              horizon: float, cut: float, near: np.ndarray, span: np.ndarray) -> int:  # fmt: skip
    """The bodies (:func:`route_costs_py`'s) that may come within ``cut`` [m] of one of the
    ``n`` samples of the leg from ``(ax, ay)`` along ``(dx, dy)`` (at ``u = (j + 0.5) / n``)
    within ``horizon`` [s], into ``near``, and the first and last such sample of each into
    ``span`` (m, 2); returns how many.  A sample farther from a body's centre than its radius,
    ``cut`` and the way it walks in ``horizon`` together is out of its reach (the exposure
    adds nothing there), and a body with no sample in reach is left out."""
    dd = dx * dx + dy * dy
    m = 0
    for i in range(bodies.shape[0]):
        cx, cy = bodies[i, 0] - ax, bodies[i, 1] - ay
        walk = math.sqrt(bodies[i, 2] ** 2 + bodies[i, 3] ** 2) * horizon
        reach = bodies[i, 4] + cut + walk + REACH_SLACK
        along = cx * dx + cy * dy
        rest = cx * cx + cy * cy - reach * reach
        if dd <= 0.0:  # a leg of no length: its samples all lie at its start
            first, last = (0, n - 1) if rest <= 0.0 else (n, -1)
        else:
            disc = along * along - dd * rest
            if disc < 0.0:
                continue
            root = math.sqrt(disc)
            first = max(math.ceil((along - root) / dd * n - 0.5), 0)
            last = min(math.floor((along + root) / dd * n - 0.5), n - 1)
        if first <= last:
            near[m], span[m, 0], span[m, 1] = i, first, last
            m += 1
    return m


def route_costs_py(
    px: float,
    py: float,
    ways: FloatArray,
    gx: float,
    gy: float,
    bodies: FloatArray,
    v_max: float,
    sigma: float,
    horizon: float,
    weight: float,
    out: FloatArray,
) -> None:
    """Each route's length plus ``weight`` times its exposure [m] into ``out`` (K,): the routes
    robot ``(px, py)``
    -> ``ways[k]`` -> goal ``(gx, gy)``, each leg cut into ``ceil(length / SPACING)`` equal
    pieces sampled at their midpoints; the module docstring's exposure of each sample over the
    ``bodies`` (N, 5): centre x, y [m], velocity x, y [m/s], radius [m], the robot at ``v_max``
    [m/s]; a body more than ``CUT`` sigmas off a sample adds nothing to it (under 4e-6), and
    only the samples within its reach (:func:`_near_leg`) are visited.

    >>> out = np.zeros(2)
    >>> one = np.array([[2.0, 0.0, 0.0, 0.0, 0.3]])
    >>> ways = np.array([[4.0, 0.0], [0.0, 3.0]])
    >>> route_costs_py(0.0, 0.0, ways, 4.0, 0.0, one, 1.0, 0.8, 2.0, 1.0, out)
    >>> out.round(3).tolist()  # 4 m through the person (exposure 2.54), 8 m past it (1.26)
    [6.54, 9.263]
    """
    far = (CUT * sigma) ** 2
    near = np.empty(bodies.shape[0], dtype=np.int64)
    span = np.empty((bodies.shape[0], 2), dtype=np.int64)
    for k in range(ways.shape[0]):
        wx, wy = ways[k, 0], ways[k, 1]
        length = 0.0
        cost = 0.0
        for leg in range(2):
            ax, ay = (px, py) if leg == 0 else (wx, wy)
            bx, by = (wx, wy) if leg == 0 else (gx, gy)
            dx, dy = bx - ax, by - ay
            size = math.sqrt(dx * dx + dy * dy)
            n = max(math.ceil(size / SPACING), 1)
            m = _near_leg(ax, ay, dx, dy, n, bodies, horizon, CUT * sigma, near, span)
            piece = size / n
            lo = span[:m, 0].min() if m > 0 else n
            hi = span[:m, 1].max() if m > 0 else -1
            for j in range(lo, hi + 1):
                u = (j + 0.5) / n
                sx, sy = ax + dx * u, ay + dy * u
                t = min((length + piece * (j + 0.5)) / v_max, horizon)
                for q in range(m):
                    if j < span[q, 0] or j > span[q, 1]:
                        continue
                    i = near[q]
                    ex = sx - bodies[i, 0] - bodies[i, 2] * t
                    ey = sy - bodies[i, 1] - bodies[i, 3] * t
                    gap = math.sqrt(ex * ex + ey * ey) - bodies[i, 4]
                    if gap <= 0.0:
                        cost += piece
                    elif gap * gap < far:
                        cost += piece * math.exp(-0.5 * (gap / sigma) ** 2)
            length += size
        out[k] = length + weight * cost


def _as_tuple(readings: Sequence[ObstacleReading]) -> tuple[ObstacleReading, ...]:
    """``readings`` as a tuple: themselves when they are one (the sensor's
    :class:`~uvnav.sensors.observation.Readings` keep their arrays), else a copy."""
    return readings if isinstance(readings, tuple) else tuple(readings)


def moving_bodies(readings: Sequence[ObstacleReading], min_speed: float) -> FloatArray:
    """The ``readings`` that move at ``min_speed`` [m/s] or faster, finite, as
    :func:`route_costs_py`'s ``bodies`` (N, 5): centre, velocity, radius (a polygon's bounding
    radius) [m, m/s]; read as v2 reads them (:func:`body_table`: the sensor's arrays where it
    gives them)."""
    if not readings:
        return np.zeros((0, 5))
    scal, centres, velocities = body_table(_as_tuple(readings), 0.0)
    radii = np.where(scal[:, 2] > 0.0, scal[:, 2], scal[:, 3])
    table = np.column_stack((centres, velocities, radii))
    keep = np.hypot(velocities[:, 0], velocities[:, 1]) >= min_speed
    return table[keep & np.isfinite(table).all(axis=1)]


def nearest(bodies: FloatArray, position: FloatArray, count: int) -> FloatArray:
    """The ``count`` rows of ``bodies`` (:func:`moving_bodies`) whose centres lie nearest
    ``position`` [m] (nearest first), or all of them, as they are, when ``count`` is 0 or no
    fewer than the rows."""
    if count <= 0 or len(bodies) <= count:
        return bodies
    gap = np.hypot(bodies[:, 0] - position[0], bodies[:, 1] - position[1])
    return bodies[np.argsort(gap, kind="stable")[:count]]


def route_costs(
    position: FloatArray, goal: FloatArray, ways: FloatArray, bodies: FloatArray, v_max: float,
    params: RouteParams,
) -> FloatArray:  # fmt: skip
    """:func:`route_costs_py` (compiled when numba is enabled) of ``ways`` (K, 2), (K,) [m]."""
    out = np.empty(len(ways))
    fn = _compiled() if numba_enabled() else route_costs_py
    p = params
    fn(float(position[0]), float(position[1]), ways, float(goal[0]), float(goal[1]), bodies,
       float(v_max), p.route_sigma, p.route_horizon, p.route_weight, out)  # fmt: skip
    return out


_COMPILED: dict[str, Callable[..., Any]] = {}


def _compiled() -> Callable[..., Any]:
    """:func:`route_costs_py` compiled by numba (on the first call, or from numba's cache)."""
    if not _COMPILED:
        _COMPILED.update(compile_family((_near_leg, route_costs_py)))
    return _COMPILED["route_costs_py"]


class CrowdRoute:
    """The route layer of one law (module docstring): :meth:`aim` each decision, :meth:`reset`
    each episode."""

    def __init__(self, params: RouteParams, min_speed: float) -> None:
        self.params = params
        self.min_speed = min_speed
        self.way: FloatArray | None = None
        self.next_search = -math.inf
        self.grid = False

    def reset(self, limited: bool = False, unicycle: bool = False) -> None:
        """Forget the held way point and search at the next decision.  The route is planned on
        the grid (:attr:`grid`) on a ``unicycle`` that is ``limited`` (it has acceleration
        limits), or on any unicycle with ``route_grid="all"``, while ``route_grid_weight``
        > 0."""
        p = self.params
        self.way = None
        self.next_search = -math.inf
        on = limited or (unicycle and p.route_grid == "all")
        self.grid = on and p.route_grid_weight > 0.0

    def _held(self, position: FloatArray, goal: FloatArray, time: float) -> FloatArray | None:
        """The point the last search chose while ``route_period`` (the grid's:
        ``route_grid_period``) holds it (``None``: search)."""
        if time >= self.next_search or math.dist(goal, position) <= DIRECT_WITHIN:
            return None
        if self.way is None:
            return goal
        return None if math.dist(self.way, position) <= REACHED else self.way

    def aim(
        self,
        position: FloatArray,
        goal: FloatArray,
        readings: Sequence[ObstacleReading],
        v_max: float,
        time: float = 0.0,
    ) -> FloatArray:
        """The point to steer for [m], (2,) at ``time`` [s]: the goal or the chosen route's way
        point."""
        p = self.params
        position = np.asarray(position, dtype=float)[:2]
        finite = math.isfinite(position[0]) and math.isfinite(position[1])
        if not (self.grid or p.route_weight > 0.0) or not finite:
            return goal
        period = p.route_grid_period if self.grid else p.route_period
        held = self._held(position, goal, time) if period > 0.0 else None
        if held is not None:
            return held
        if self.grid:
            return self._grid_aim(position, goal, readings, v_max, time)
        bodies = nearest(moving_bodies(readings, self.min_speed), position, p.route_bodies)
        gap = goal - position
        if len(bodies) == 0 or math.hypot(gap[0], gap[1]) <= DIRECT_WITHIN:
            self.way = None
            return goal
        ways = fan_way_points(position, goal, p.route_lookahead)
        if self.way is not None:
            ways = np.vstack((ways, self.way[None]))
        cost = route_costs(position, goal, ways, bodies, v_max, p)
        if self.way is not None:
            cost[-1] -= p.route_hold
        k = int(np.argmin(cost))
        self.way = None if k == 0 else ways[k].copy()
        self.next_search = time + p.route_period
        if self.way is None or math.dist(self.way, position) <= REACHED:
            return goal
        return self.way

    def _grid_aim(self, position: FloatArray, goal: FloatArray,
                  readings: Sequence[ObstacleReading], v_max: float,
                  time: float) -> FloatArray:  # fmt: skip
        """The grid route's way point (:func:`~uvnav.controllers.crowd_grid.grid_way_point`
        over every sensed body, :func:`~uvnav.controllers.crowd_grid.grid_bodies`), held as
        :meth:`aim` holds the fan's, or the goal when it is within ``DIRECT_WITHIN`` m or
        nothing is sensed."""
        p = self.params
        self.way, self.next_search = None, time + p.route_grid_period
        if math.dist(goal, position) <= DIRECT_WITHIN:
            return goal
        bodies = grid_bodies(_as_tuple(readings))
        if len(bodies) == 0:
            return goal
        self.way = grid_way_point(position, goal, bodies, v_max, p.route_horizon, GRID_SIGMA,
                                  p.route_grid_weight, GRID_AHEAD)  # fmt: skip
        return self.way
