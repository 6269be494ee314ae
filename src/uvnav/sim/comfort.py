"""Comfort metrics of a 2D episode: pure numpy functions of the robot's trajectory and the
pedestrians' states, and the tracker :class:`MotionTracker` that feeds them.

Every function takes arrays and returns numbers; :class:`~uvnav.sim.social.SocialTracker` and
:class:`MotionTracker` call them at every integration step or at the end of the episode
(:class:`uvnav.sim.episode.World2D`); the tracker counts the personal-space steps itself, as it
counts its other distance thresholds.  The metrics, with their units and sources:

``personal_space_time`` [s]
    ``dt`` times the number of integration steps whose end state has a *gap* (disc to disc:
    centre distance minus both radii, as everywhere in :mod:`uvnav.sim.social`) below
    :data:`PERSONAL_DISTANCE` = 0.5 m to some pedestrian: the personal-space violation time of
    the crowd-navigation benchmarks (e.g. the 0.5 m personal zone of Gao and Huang, "Evaluation of
    socially-aware robot navigation", *Frontiers in Robotics and AI* 8, 2022).  Pedestrians only.
``min_time_to_collision`` [s]
    the smallest constant-velocity time to collision (:func:`time_to_collision`) between the
    robot's disc and any pedestrian's over the integration steps' end states (0 while they
    overlap); ``None`` when no step was on a collision course.  This is the time to collision at
    the episode's closest approach *in time*: at the step of smallest gap the gap stops
    shrinking, so the constant-velocity time to collision there is infinite unless the discs
    already touch, which would make a closest-gap TTC a duplicate of the collision flag.
    Pedestrians only.
``heading_irregularity`` [rad]
    mean over the integration steps' end states of the absolute angle between the robot's
    heading and the direction from its centre to the goal (:func:`heading_irregularity`): the
    "path irregularity" of SocNavBench (Biswas et al., "SocNavBench: a grounded simulation testing
    framework for evaluating social navigation", *ACM THRI* 2022; its ``path_irregularity``
    averages the per-step angle away from the straight line to the goal).  The heading is the
    world's (a unicycle's orientation; a holonomic robot's last direction of motion).  Every 2D
    episode; ``None`` when no step has a defined direction to the goal.
``jerk`` [m/s^3]
    mean over the steps of ``|d a / dt|``, the robot's velocity differentiated twice by finite
    differences at the integration step (:func:`mean_jerk`); the velocity of a step is its
    displacement over ``dt`` and the robot starts from its velocity at ``t = 0`` (at rest), so
    starting to move counts.  A law whose commands jump once per decision period has a jerk that
    grows as ``dt`` shrinks (a velocity step of ``Δv`` gives ``2 Δv / dt^2`` over two steps):
    compare laws at the same ``dt``.  Every 2D episode; ``None`` below two steps.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

#: the personal-space distance of ``personal_space_time`` [m], disc to disc
PERSONAL_DISTANCE = 0.5
#: a centre this close to the goal has no direction to it [m]
_ON_GOAL = 1e-9


def time_to_collision(
    rel_pos: np.ndarray, rel_vel: np.ndarray, radius_sum: np.ndarray | float
) -> np.ndarray:
    """Constant-velocity time to collision of pairs of discs [s].

    Args:
        rel_pos: (n, 2) the other disc's centre minus the robot's [m].
        rel_vel: (n, 2) the other disc's velocity minus the robot's [m/s].
        radius_sum: (n,) or scalar, the sum of the two radii [m].

    Returns:
        (n,) the first ``t >= 0`` with ``|rel_pos + rel_vel t| = radius_sum``: 0 where the discs
        already overlap or touch, ``inf`` where the straight relative motion never reaches
        contact (diverging, parallel, at rest, or passing wide).

    >>> time_to_collision(np.array([[4.0, 0.0]]), np.array([[-2.0, 0.0]]), 1.0).tolist()
    [1.5]
    >>> time_to_collision(np.array([[0.5, 0.0]]), np.array([[1.0, 0.0]]), 1.0).tolist()
    [0.0]
    >>> time_to_collision(np.array([[4.0, 0.0], [4.0, 0.0]]),
    ...                   np.array([[1.0, 0.0], [0.0, 0.0]]), 1.0).tolist()
    [inf, inf]
    >>> time_to_collision(np.array([[4.0, 2.0]]), np.array([[-1.0, 0.0]]), 1.0).tolist()
    [inf]
    >>> time_to_collision(np.zeros((0, 2)), np.zeros((0, 2)), 1.0).shape
    (0,)
    """
    p = np.asarray(rel_pos, dtype=float).reshape(-1, 2)
    w = np.asarray(rel_vel, dtype=float).reshape(-1, 2)
    r = np.broadcast_to(np.asarray(radius_sum, dtype=float), (len(p),))
    c = p[:, 0] ** 2 + p[:, 1] ** 2 - r**2  # > 0: apart
    # along the unit direction of the relative motion (the distance to contact, then over the
    # speed): squaring a tiny speed would lose it to underflow
    speed = np.hypot(w[:, 0], w[:, 1])
    moving = speed > 0.0
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        u = w / np.where(moving, speed, 1.0)[:, None]
        b = p[:, 0] * u[:, 0] + p[:, 1] * u[:, 1]  # < 0: closing
        disc = b * b - c
        hit = (b < 0.0) & (disc >= 0.0) & moving
        reach = -b - np.sqrt(np.maximum(disc, 0.0))
        t = np.where(hit, reach / np.where(moving, speed, 1.0), np.inf)
    return np.where(c <= 0.0, 0.0, np.maximum(t, 0.0))


def heading_irregularity(
    positions: np.ndarray, headings: np.ndarray, goal: np.ndarray
) -> float | None:
    """Mean absolute angle [rad] between the heading and the direction to ``goal``.

    Args:
        positions: (n, 2) robot centres [m].
        headings: (n,) headings [rad].
        goal: (2,) the goal [m].

    Returns:
        The mean over the states whose centre is farther than 1e-9 m from the goal (the
        direction is undefined on it) of ``|wrap(heading - atan2(goal - position))|``, in
        [0, pi]; ``None`` when no state counts.

    >>> heading_irregularity(np.array([[0.0, 0.0], [1.0, 0.0]]), np.array([0.0, math.pi / 2]),
    ...                      np.array([2.0, 0.0])) == math.pi / 4
    True
    >>> round(heading_irregularity(np.zeros((1, 2)), np.array([3 * math.pi]), np.ones(2)), 6)
    2.356194
    >>> heading_irregularity(np.array([[1.0, 1.0]]), np.array([0.0]), np.array([1.0, 1.0])) is None
    True
    """
    p = np.asarray(positions, dtype=float).reshape(-1, 2)
    h = np.asarray(headings, dtype=float).reshape(-1)
    to_goal = np.asarray(goal, dtype=float).reshape(2) - p
    ok = np.hypot(to_goal[:, 0], to_goal[:, 1]) > _ON_GOAL
    if not ok.any():
        return None
    diff = h[ok] - np.arctan2(to_goal[ok, 1], to_goal[ok, 0])
    wrapped = np.remainder(diff + math.pi, 2.0 * math.pi) - math.pi  # in [-pi, pi)
    return float(np.abs(wrapped).mean())


def mean_jerk(velocities: np.ndarray, dt: float) -> float | None:
    """Mean norm of the jerk [m/s^3] of a velocity sequence sampled every ``dt`` [s].

    Args:
        velocities: (n, 2) velocities [m/s], one every ``dt``.
        dt: the sampling step [s], > 0.

    Returns:
        ``mean_k |v_k - 2 v_(k-1) + v_(k-2)| / dt^2`` over ``k = 2 .. n-1``; ``None`` for fewer
        than three velocities.

    >>> mean_jerk(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0]]), 0.5)
    4.0
    >>> mean_jerk(np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]]), 0.1)
    0.0
    >>> mean_jerk(np.array([[0.0, 0.0], [1.0, 0.0]]), 0.1) is None
    True
    """
    v = np.asarray(velocities, dtype=float).reshape(-1, 2)
    if len(v) < 3:
        return None
    j = (v[2:] - 2.0 * v[1:-1] + v[:-2]) / (float(dt) ** 2)
    return float(np.hypot(j[:, 0], j[:, 1]).mean())


class MotionTracker:
    """The robot's states at every integration step, for ``heading_irregularity`` and ``jerk``.

    Args:
        goal: (2,) the goal [m].
        dt: integration step [s].
        x, y, heading, velocity: the state at ``t = 0`` [m], [rad], [m/s].
    """

    __slots__ = ("_goal", "_rows", "_v0", "dt")

    def __init__(
        self,
        goal: np.ndarray,
        dt: float,
        x: float,
        y: float,
        heading: float,
        velocity: tuple[float, float],
    ) -> None:
        self._goal = np.asarray(goal, dtype=float).reshape(2)
        self.dt = float(dt)
        self._v0 = (float(velocity[0]), float(velocity[1]))
        self._rows: list[tuple[float, float, float]] = [(float(x), float(y), float(heading))]

    def observe(self, x: float, y: float, heading: float) -> None:
        """The state at the end of an integration step: centre [m], heading [rad]."""
        self._rows.append((x, y, heading))

    def track(self) -> Callable[[tuple[float, float, float]], None]:
        """:meth:`observe` as a function of one ``(x, y, heading)`` tuple (for a world that
        observes at every step: one call, no method lookup)."""
        return self._rows.append

    def metrics(self) -> dict[str, float | None]:
        """``heading_irregularity`` [rad] over the steps' end states and ``jerk`` [m/s^3]
        (module docstring)."""
        rows = np.asarray(self._rows, dtype=float)
        p = rows[:, :2]
        steps = np.diff(p, axis=0) / self.dt
        velocities = np.vstack((np.asarray(self._v0).reshape(1, 2), steps))
        return {
            "heading_irregularity": heading_irregularity(p[1:], rows[1:, 2], self._goal),
            "jerk": mean_jerk(velocities, self.dt),
        }
