"""A route around the crowd: the way point a local law steers for, chosen by crowd exposure.

uvnav's own layer, beyond the thesis: ``zhang2019-holonomic-v2`` (on by default) and
``zhang2019-v2`` (off by default) steer for the way point it gives instead of the goal itself.
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
* **Exposure.**  Each route is sampled every ``SPACING`` m along its two legs; a sample ``s``
  reached at time ``t = arc length / V_max`` costs ``sum_i exp(-max(||s - c_i - v_i
  min(t, horizon)|| - r_i, 0)^2 / (2 sigma^2))`` per metre, over the bodies ``i`` that move at
  ``min_speed`` or faster (centre ``c_i``, velocity ``v_i``, radius ``r_i``: a polygon's
  bounding radius).  People standing still are left to the local law, which keeps clear of
  them; counting them would hold the robot off a goal beside which someone stands.
* **Choice.**  The route of least ``length + weight * exposure`` [m].  The robot steers for its
  way point, or for the goal when the direct route wins, the goal is within ``DIRECT_WITHIN``
  m, no moving body is sensed, or the way point is within ``REACHED`` m.

The bodies are those the robot senses (a person out of range costs nothing), with the rates the
readings give (true or estimated).  Measured on the harder crowd (``crowd-dynamic``, tuning
cases 0-99, holonomic): success 0.84 -> 0.98, intrusion ratio 0.205 -> 0.023, time to goal
26.4 -> 18.0 s; the design notes hold the held-out figures.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from uvnav.controllers.base import check_params
from uvnav.geometry.angles import FloatArray
from uvnav.sensors.observation import ObstacleReading

#: routes in the fan: the direct one and ``FAN - 1`` way points (the goal's direction excluded)
FAN = 13
#: distance between the samples of a route [m]
SPACING = 0.25
#: the goal closer than this [m]: steer for it
DIRECT_WITHIN = 1.0
#: a way point closer than this [m]: steer for the goal
REACHED = 0.5


@dataclass(frozen=True)
class RouteSettings:
    """The route layer's settings.

    Attributes:
        weight: metres a route's length may grow to spare one unit of exposure; 0 turns the
            layer off (the law steers for the goal).
        sigma: spread [m] of a person's cost around where they will be.
        lookahead: distance [m] of the way points from the robot.
        hold: what the way point held from the last decision is spared [m].
        horizon: how far ahead [s] the people's positions are forecast (constant velocity);
            a later sample meets them where they are then.
        min_speed: bodies slower than this [m/s] cost nothing.
    """

    weight: float = 0.0
    sigma: float = 0.8
    lookahead: float = 4.0
    hold: float = 0.5
    horizon: float = 2.0
    min_speed: float = 0.1


@dataclass(frozen=True)
class RouteParams:
    """A law's parameters of the route layer (:class:`RouteSettings`, named ``route_*``; the
    law gives ``min_speed``).

    Attributes:
        route_weight: :attr:`RouteSettings.weight` [m per unit of exposure]; 0: off.
        route_sigma: :attr:`RouteSettings.sigma` [m].
        route_lookahead: :attr:`RouteSettings.lookahead` [m].
        route_hold: :attr:`RouteSettings.hold` [m].
        route_horizon: :attr:`RouteSettings.horizon` [s].
    """

    route_weight: float = 0.0
    route_sigma: float = 0.8
    route_lookahead: float = 4.0
    route_hold: float = 0.5
    route_horizon: float = 2.0

    def __post_init__(self) -> None:
        check_params(self, positive=("route_sigma", "route_lookahead", "route_horizon"),
                     non_negative=("route_weight", "route_hold"))  # fmt: skip

    def route_settings(self, min_speed: float) -> RouteSettings:
        """These parameters as the layer's settings (``min_speed`` [m/s])."""
        return RouteSettings(self.route_weight, self.route_sigma, self.route_lookahead,
                             self.route_hold, self.route_horizon, min_speed)  # fmt: skip


def fan_way_points(position: FloatArray, goal: FloatArray, lookahead: float) -> FloatArray:
    """The goal, then the ``FAN - 1`` way points of the fan, (FAN, 2) [m].

    >>> w = fan_way_points(np.zeros(2), np.array([10.0, 0.0]), 4.0)
    >>> w.shape, w[0].tolist(), np.round(w[1], 6).tolist(), np.round(w[-1], 6).tolist()
    ((13, 2), [10.0, 0.0], [0.0, -4.0], [0.0, 4.0])
    """
    gap = goal - position
    reach = min(lookahead, math.hypot(gap[0], gap[1]))
    angles = np.linspace(-math.pi / 2, math.pi / 2, FAN)
    angles = math.atan2(gap[1], gap[0]) + angles[angles != 0.0]
    ways = position + reach * np.column_stack((np.cos(angles), np.sin(angles)))
    return np.vstack((goal[None], ways))


def route_samples(
    position: FloatArray, ways: FloatArray, goal: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Samples of the routes robot -> ``ways[k]`` -> goal: points (K, S, 2) [m], their arc
    lengths (K, S) [m], the length each stands for (K, S) [m] and the routes' lengths (K,).

    Each leg is cut into as many equal pieces as the longest leg of its kind needs at
    :data:`SPACING`, and sampled at the pieces' midpoints.

    >>> p, s, w, n = route_samples(np.zeros(2), np.array([[1.0, 0.0]]), np.array([1.0, 0.0]))
    >>> p.shape, float(w.sum()), n.tolist()
    ((1, 5, 2), 1.0, [1.0])
    """
    first = ways - position
    second = goal - ways
    a = np.hypot(first[:, 0], first[:, 1])
    b = np.hypot(second[:, 0], second[:, 1])
    na = max(math.ceil(float(a.max()) / SPACING), 1)
    nb = max(math.ceil(float(b.max()) / SPACING), 1)
    ua = (np.arange(na) + 0.5) / na
    ub = (np.arange(nb) + 0.5) / nb
    points = np.concatenate(
        (
            position + first[:, None] * ua[None, :, None],
            ways[:, None] + second[:, None] * ub[None, :, None],
        ),
        axis=1,
    )
    arc = np.concatenate((a[:, None] * ua, a[:, None] + b[:, None] * ub), axis=1)
    weights = np.concatenate(
        (np.repeat(a[:, None] / na, na, axis=1), np.repeat(b[:, None] / nb, nb, axis=1)), axis=1
    )
    return points, arc, weights, a + b


def exposure(
    points: FloatArray,
    arc: FloatArray,
    weights: FloatArray,
    bodies: tuple[FloatArray, FloatArray, FloatArray],
    v_max: float,
    settings: RouteSettings,
) -> FloatArray:
    """Each route's exposure (K,) [m]: the module docstring's sum over its samples (``points``
    (K, S, 2) at ``arc`` lengths (K, S), standing for ``weights`` (K, S) metres) and over the
    ``bodies`` (centres (N, 2), velocities (N, 2), radii (N,)), the robot at ``v_max`` [m/s].

    >>> one = (np.array([[2.0, 0.0]]), np.zeros((1, 2)), np.array([0.3]))
    >>> pts = np.array([[[2.0, 0.0]], [[2.0, 5.0]]])
    >>> np.round(exposure(pts, np.ones((2, 1)), np.ones((2, 1)), one, 1.0, RouteSettings()), 6)
    array([1., 0.])
    """
    centres, velocities, radii = bodies
    t = np.minimum(arc / v_max, settings.horizon)
    where = centres + velocities * t[..., None, None]  # (K, S, N, 2)
    gap = np.hypot(*np.moveaxis(points[:, :, None, :] - where, -1, 0)) - radii
    cost = np.exp(-0.5 * np.square(np.maximum(gap, 0.0) / settings.sigma)).sum(axis=2)
    return np.asarray((cost * weights).sum(axis=1))


def moving_bodies(
    readings: Sequence[ObstacleReading], min_speed: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The centres (N, 2) [m], velocities (N, 2) [m/s] and radii (N,) [m] (a polygon's bounding
    radius) of the ``readings`` that move at ``min_speed`` [m/s] or faster."""
    if not readings:
        return np.zeros((0, 2)), np.zeros((0, 2)), np.zeros(0)
    centres = np.array([r.centre for r in readings], dtype=float).reshape(-1, 2)
    velocities = np.array([r.velocity for r in readings], dtype=float).reshape(-1, 2)
    radii = np.array([r.radius if r.radius > 0 else r.bounding_radius for r in readings])
    keep = np.hypot(velocities[:, 0], velocities[:, 1]) >= min_speed
    ok = keep & np.isfinite(centres).all(axis=1) & np.isfinite(velocities).all(axis=1)
    return centres[ok], velocities[ok], radii[ok]


class CrowdRoute:
    """The route layer of one law (module docstring): :meth:`aim` each decision, :meth:`reset`
    each episode."""

    def __init__(self, settings: RouteSettings) -> None:
        self.settings = settings
        self.way: FloatArray | None = None

    def reset(self) -> None:
        """Forget the held way point."""
        self.way = None

    def aim(
        self,
        position: FloatArray,
        goal: FloatArray,
        readings: Sequence[ObstacleReading],
        v_max: float,
    ) -> FloatArray:
        """The point to steer for [m], (2,): the goal or the chosen route's way point."""
        s = self.settings
        position = np.asarray(position, dtype=float)[:2]
        if s.weight <= 0.0 or not np.isfinite(position).all():
            return goal
        bodies = moving_bodies(readings, s.min_speed)
        gap = goal - position
        if len(bodies[2]) == 0 or math.hypot(gap[0], gap[1]) <= DIRECT_WITHIN:
            self.way = None
            return goal
        ways = fan_way_points(position, goal, s.lookahead)
        if self.way is not None:
            ways = np.vstack((ways, self.way[None]))
        points, arc, weights, length = route_samples(position, ways, goal)
        cost = length + s.weight * exposure(points, arc, weights, bodies, v_max, s)
        if self.way is not None:
            cost[-1] -= s.hold
        k = int(np.argmin(cost))
        self.way = None if k == 0 else ways[k].copy()
        if self.way is None or math.dist(self.way, position) <= REACHED:
            return goal
        return self.way
