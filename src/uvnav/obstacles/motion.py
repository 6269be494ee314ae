"""Obstacle motion models (thesis Ch. 2 §2.2: translation with v_i(t), rotation about the mass
centre with u_i(t), bounded as in (2.6)-(2.8)).

Each model is a small stateful object built fresh for every episode; the only randomness comes from
the ``numpy.random.Generator`` handed to it, so the same seed replays the same motion bit for bit.
``step(state, t, dt)`` returns the state after ``dt`` [s] and sets ``velocity`` [m/s] and
``angular_velocity`` [rad/s] to the values used over that step.

A model may also say when its body exists: ``present(t) -> bool`` (optional; a model without it
is always present).  A body that is not present at ``t`` (a replayed pedestrian outside its
recorded interval) is left out of every query of the :class:`~uvnav.obstacles.ObstacleField` of
that instant: collision, clearance, sensing and ray casting never see it.  A
:class:`MotionGroup` says it with ``present(t) -> (m,) bool``.

``step`` is the reference definition of each model.  The simulator advances all obstacles of an
episode at once with :class:`uvnav.obstacles.batch.ObstacleBatch`, which reproduces it bit for bit
(vectorised for :class:`ConstantVelocity` and :class:`RandomTurn`, by calling ``step`` otherwise).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

from uvnav.core import load_plugins
from uvnav.geometry.angles import FloatArray, wrap_scalar


@dataclass(frozen=True, slots=True)
class ObstacleState:
    """Pose and rates of a rigid obstacle.

    Attributes:
        position: mass-centre position [m], shape (2,).
        heading: rotation of the body frame [rad].
        velocity: translational velocity v_i [m/s], shape (2,).
        angular_velocity: rotation rate u_i about the mass centre [rad/s].
    """

    position: FloatArray
    heading: float = 0.0
    velocity: FloatArray = field(default_factory=lambda: np.zeros(2))
    angular_velocity: float = 0.0


class MotionModel(Protocol):
    """Advances an obstacle's state; see the module docstring."""

    def step(self, state: ObstacleState, t: float, dt: float) -> ObstacleState: ...

    def speed_bound(self) -> float:
        """Largest speed ||v_i|| [m/s] the model can produce (for the (2.6) check)."""
        ...

    def turn_bound(self) -> float:
        """Largest |u_i| [rad/s] the model can produce (for the (2.7)-(2.8) checks)."""
        ...


#: Entry-point group of third-party motion models.  An entry point's name is the motion's; it
#: loads a factory ``make(rng, **params) -> MotionModel`` (``rng``: the obstacle's own generator,
#: the only source of its randomness).  Scenes use it as ``motion: {type: plugin, name: ...,
#: params: {...}}``.
MOTION_GROUP = "uvnav.motions"
#: motion types of the scenario schema (a plug-in may not take these names)
BUILTIN_MOTIONS: tuple[str, ...] = (
    "constant",
    "random_turn",
    "waypoints",
    "replay",
    "orca_crowd",
    "social_force",
    "plugin",
)


def motion_plugins() -> dict[str, Callable[..., Any]]:
    """The motion-model factories of the :data:`MOTION_GROUP` entry points (loaded once).

    Raises:
        RuntimeError: a plug-in takes a built-in name or another plug-in's.
    """
    return load_plugins(MOTION_GROUP, BUILTIN_MOTIONS, "motion")


class MotionGroup(Protocol):
    """Several obstacles with the same motion model, advanced together as arrays.

    A model class opts in by defining a classmethod ``batch_group(models) -> MotionGroup``;
    :class:`~uvnav.obstacles.ObstacleBatch` then advances all obstacles of that class with one
    :meth:`step` call instead of one ``model.step`` each.  The group must give, bit for bit, what
    the models' own ``step`` gives (the state it needs beyond position and heading it keeps itself).
    """

    def step(
        self, position: FloatArray, heading: FloatArray, t: float, dt: float
    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Advance from time ``t`` [s] by ``dt`` [s].

        Args:
            position: (2, m) mass centres at ``t`` [m], in the order the group was made.
            heading: (m,) headings at ``t`` [rad].

        Returns:
            ``(position (2, m) [m], heading (m,) [rad], velocity (2, m) [m/s],
            angular_velocity (m,) [rad/s])`` at ``t + dt`` (rates used over the step).
        """
        ...


def uniform_draw(rng: np.random.Generator, bounds: Sequence[float]) -> float:
    """``float(rng.uniform(lo, hi))`` for ``bounds = (lo, hi)``: the same draw from the stream and
    the same number (numpy computes ``lo + (hi - lo) * random()``), several times faster for one
    scalar.  The test suite checks the equality against ``Generator.uniform``.
    """
    lo = float(bounds[0])
    span = float(bounds[1]) - lo
    if not math.isfinite(span):  # Generator.uniform's own checks
        raise OverflowError("high - low range exceeds valid bounds")
    if span < 0.0:
        raise ValueError("high - low < 0")
    return lo + span * rng.random()


def _advance(state: ObstacleState, velocity: FloatArray, omega: float, dt: float) -> ObstacleState:
    return ObstacleState(
        position=state.position + velocity * dt,
        heading=wrap_scalar(state.heading + omega * dt),
        velocity=velocity,
        angular_velocity=omega,
    )


@dataclass
class ConstantVelocity:
    """Straight-line motion at constant ``velocity`` [m/s], constant spin ``angular_velocity``
    [rad/s]."""

    velocity: FloatArray
    angular_velocity: float = 0.0

    def step(self, state: ObstacleState, t: float, dt: float) -> ObstacleState:
        return _advance(state, np.asarray(self.velocity, dtype=float), self.angular_velocity, dt)

    def speed_bound(self) -> float:
        return float(np.hypot(*self.velocity))

    def turn_bound(self) -> float:
        return abs(self.angular_velocity)


@dataclass
class RandomTurn:
    """Random wandering: every ``change_period`` [s] a new speed and turn rate are drawn uniformly.

    The course (direction of travel) turns at the drawn turn rate and the body turns with it, so the
    obstacle both changes direction and rotates about its mass centre, with ``u_i`` equal to the
    turn rate plus an optional constant ``spin`` [rad/s].  An optional ``arena`` box
    ``[xmin, ymin, xmax, ymax]`` [m] keeps the obstacle inside: outside it, the course turns back
    toward the arena centre at the largest admissible turn rate.

    Attributes:
        speed: (min, max) speed [m/s].
        turn_rate: (min, max) course turn rate [rad/s].
        rng: the episode's generator for this obstacle.
    """

    speed: tuple[float, float]
    turn_rate: tuple[float, float]
    rng: np.random.Generator
    change_period: float = 1.0
    spin: float = 0.0
    arena: tuple[float, float, float, float] | None = None
    course: float | None = None
    _speed: float = field(default=0.0, init=False)
    _turn: float = field(default=0.0, init=False)
    _next_change: float = field(default=-np.inf, init=False)

    def step(self, state: ObstacleState, t: float, dt: float) -> ObstacleState:
        if self.course is None:
            self.course = self.course_at(state)
        if t >= self._next_change - 1e-12:
            self._speed = uniform_draw(self.rng, self.speed)
            self._turn = uniform_draw(self.rng, self.turn_rate)
            self._next_change = t + self.change_period
        turn = self._turn
        if self.arena is not None:
            x0, y0, x1, y1 = self.arena
            p = state.position
            if not (x0 <= p[0] <= x1 and y0 <= p[1] <= y1):
                # libm's atan2 (math), not numpy's: numpy dispatches arctan2 to SIMD code on
                # some CPUs (1 ulp apart), libm is the same everywhere and in compiled kernels
                to_centre = math.atan2(0.5 * (y0 + y1) - float(p[1]), 0.5 * (x0 + x1) - float(p[0]))
                err = wrap_scalar(to_centre - self.course)
                limit = max(abs(self.turn_rate[0]), abs(self.turn_rate[1]))
                turn = float(np.clip(err / dt, -limit, limit))
        self.course = wrap_scalar(self.course + turn * dt)
        mid = self.course - 0.5 * turn * dt
        velocity = self._speed * np.array([np.cos(mid), np.sin(mid)])
        return _advance(state, velocity, turn + self.spin, dt)

    def course_at(self, state: ObstacleState) -> float:
        """The course [rad] a step from ``state`` starts on: the model's, or before its first
        step the direction of the state's velocity (its heading when at rest)."""
        if self.course is not None:
            return self.course
        v = state.velocity
        return float(np.arctan2(v[1], v[0])) if np.hypot(*v) > 0 else state.heading

    def speed_bound(self) -> float:
        return float(max(abs(self.speed[0]), abs(self.speed[1])))

    def turn_bound(self) -> float:
        return float(max(abs(self.turn_rate[0]), abs(self.turn_rate[1])) + abs(self.spin))


@dataclass
class Waypoints:
    """Scripted path: go from waypoint to waypoint at ``speed`` [m/s], body facing the course.

    With ``loop`` the path restarts at the first waypoint; otherwise the obstacle stops at the last.
    Turning at a waypoint is instantaneous, the rotation rate reported over that step being
    ``turn / dt``; set ``turn_with_course=False`` for a body that keeps its orientation.
    """

    points: FloatArray
    speed: float
    loop: bool = False
    turn_with_course: bool = True
    _target: int = field(default=0, init=False)

    def step(self, state: ObstacleState, t: float, dt: float) -> ObstacleState:
        pts = np.asarray(self.points, dtype=float)
        pos = state.position.copy()
        budget = self.speed * dt
        while budget > 1e-12 and self._target < len(pts):
            goal = pts[self._target]
            gap = goal - pos
            dist = float(np.hypot(*gap))
            if dist <= budget:
                pos = goal.copy()
                budget -= dist
                self._target += 1
                if self._target == len(pts) and self.loop:
                    self._target = 0
            else:
                pos = pos + gap / dist * budget
                budget = 0.0
        velocity = (pos - state.position) / dt
        heading = state.heading
        if self.turn_with_course and np.hypot(*velocity) > 1e-9:
            heading = float(np.arctan2(velocity[1], velocity[0]))
        omega = wrap_scalar(heading - state.heading) / dt
        return ObstacleState(
            position=pos, heading=heading, velocity=velocity, angular_velocity=omega
        )

    def speed_bound(self) -> float:
        return float(self.speed)

    def turn_bound(self) -> float:
        return 0.0 if not self.turn_with_course else np.inf


@dataclass
class Replay:
    """Replays a recorded trajectory: positions (m, 2) [m] at increasing ``times`` (m,) [s].

    Positions are interpolated linearly between samples (velocity piecewise constant).  Before the
    first and after the last sample the obstacle holds still.  Headings follow the course.
    """

    times: FloatArray
    positions: FloatArray

    def position_at(self, t: float) -> FloatArray:
        tt = np.asarray(self.times, dtype=float)
        pp = np.asarray(self.positions, dtype=float)
        return np.array([np.interp(t, tt, pp[:, 0]), np.interp(t, tt, pp[:, 1])])

    def step(self, state: ObstacleState, t: float, dt: float) -> ObstacleState:
        new = self.position_at(t + dt)
        velocity = (new - state.position) / dt
        heading = state.heading
        if np.hypot(*velocity) > 1e-9:
            heading = float(np.arctan2(velocity[1], velocity[0]))
        omega = wrap_scalar(heading - state.heading) / dt
        return ObstacleState(
            position=new, heading=heading, velocity=velocity, angular_velocity=omega
        )

    def speed_bound(self) -> float:
        tt = np.asarray(self.times, dtype=float)
        pp = np.asarray(self.positions, dtype=float)
        if len(tt) < 2:
            return 0.0
        return float(np.max(np.hypot(*np.diff(pp, axis=0).T) / np.maximum(np.diff(tt), 1e-12)))

    def turn_bound(self) -> float:
        return np.inf
