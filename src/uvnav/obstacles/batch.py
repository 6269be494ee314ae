"""Many obstacles advanced together as arrays: the simulator's hot path for obstacle motion.

:class:`ObstacleBatch` holds the positions, headings and rates of an episode's obstacles as
(k, 2) / (k,) arrays and advances the common motion models in vectorised form:

* :class:`~uvnav.obstacles.motion.ConstantVelocity`: fixed rates, one array update;
* :class:`~uvnav.obstacles.motion.RandomTurn`: speeds and turn rates drawn from each obstacle's
  own generator with exactly the calls, in exactly the order, that ``RandomTurn.step`` makes
  (obstacles in index order), and the course, arena steering and pose updates done with the same
  floating-point operations, element by element;
* any other model (``Waypoints``, ``Replay``, subclasses, third-party models): its own
  ``step(state, t, dt)``, called per obstacle.

The result is bit for bit what calling ``obstacle.motion.step`` on every obstacle gives (the test
suite checks it), at a cost that hardly grows with the number of obstacles.  Each step makes new
arrays (a field built from them is a snapshot), and :meth:`ObstacleBatch.write_back` puts the final
states and the models' internal state back on the :class:`~uvnav.obstacles.Obstacle` objects.
One caveat: models that share one generator are advanced group by group (random-turn obstacles
first), so their draws interleave differently from the per-obstacle loop; give every obstacle its
own generator, as :func:`uvnav.scenarios.build_episode` does.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from uvnav.geometry.angles import FloatArray, wrap_scalar
from uvnav.obstacles.motion import ConstantVelocity, ObstacleState, RandomTurn
from uvnav.obstacles.obstacle import FieldTemplate, Obstacle, ObstacleField

_Rows = slice | np.ndarray


def wrap_array_inplace(a: FloatArray) -> FloatArray:
    """Wrap every element of ``a`` to (-pi, pi] in place, exactly as :func:`wrap_scalar` does.

    Elements already inside are untouched; the few outside go through :func:`wrap_scalar` itself,
    so both paths agree bit for bit (NaN included).
    """
    ok = np.abs(a) < math.pi
    if len(ok) and not ok[ok.argmin()]:
        for i in (~ok).nonzero()[0].tolist():
            a[i] = wrap_scalar(float(a[i]))
    return a


def _rows(idx: list[int], k: int) -> _Rows:
    return slice(None) if len(idx) == k else np.array(idx, dtype=np.intp)


class _ConstantGroup:
    """Obstacles moved by :class:`ConstantVelocity`."""

    def __init__(self, rows: _Rows, models: list[ConstantVelocity]) -> None:
        self.rows = rows
        self.velocity = np.array([np.asarray(m.velocity, dtype=float) for m in models]).reshape(
            -1, 2
        )
        self.omega = np.array([float(m.angular_velocity) for m in models])


class _RandomTurnGroup:
    """Obstacles moved by :class:`RandomTurn`, their draws and course as arrays."""

    def __init__(self, rows: _Rows, models: list[RandomTurn], states: list[ObstacleState]) -> None:
        self.rows = rows
        self.models = models
        m = len(models)
        course = np.empty(m)
        for i, (mod, st) in enumerate(zip(models, states, strict=True)):
            if mod.course is None:  # as RandomTurn.step does on its first call
                v = st.velocity
                course[i] = float(np.arctan2(v[1], v[0])) if np.hypot(*v) > 0 else st.heading
            else:
                course[i] = mod.course
        self.course = course
        self.speed = np.array([mod._speed for mod in models], dtype=float)
        self.turn = np.array([mod._turn for mod in models], dtype=float)
        self.next_change = np.array([mod._next_change for mod in models], dtype=float)
        self.threshold = self.next_change - 1e-12
        self.due_at = float(self.threshold.min())
        self.period = [float(mod.change_period) for mod in models]
        self.spin = np.array([mod.spin for mod in models], dtype=float)
        self.arena = [i for i, mod in enumerate(models) if mod.arena is not None]
        lo = np.full((m, 2), -np.inf)
        hi = np.full((m, 2), np.inf)
        for i in self.arena:
            x0, y0, x1, y1 = models[i].arena  # type: ignore[misc]
            lo[i] = (x0, y0)
            hi[i] = (x1, y1)
        self.lo = lo
        self.hi = hi

    def advance(
        self, t: float, dt: float, positions: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """New course; returns the step's velocity components and rotation rates."""
        if t >= self.due_at:
            due = (t >= self.threshold).nonzero()[0].tolist()
            for i in due:
                mod = self.models[i]
                self.speed[i] = float(mod.rng.uniform(*mod.speed))
                self.turn[i] = float(mod.rng.uniform(*mod.turn_rate))
                nc = t + self.period[i]
                self.next_change[i] = nc
                self.threshold[i] = nc - 1e-12
            self.due_at = float(self.threshold.min())
        turn = self.turn
        if self.arena:
            ok = (self.lo <= positions) & (positions <= self.hi)
            if not ok.flat[ok.argmin()]:
                turn = turn.copy()
                inside = ok[:, 0] & ok[:, 1]
                for i in (~inside).nonzero()[0].tolist():
                    mod = self.models[i]
                    if mod.arena is None:
                        continue
                    x0, y0, x1, y1 = mod.arena
                    p = positions[i]
                    to_centre = np.arctan2(0.5 * (y0 + y1) - p[1], 0.5 * (x0 + x1) - p[0])
                    err = wrap_scalar(float(to_centre) - float(self.course[i]))
                    limit = max(abs(mod.turn_rate[0]), abs(mod.turn_rate[1]))
                    turn[i] = float(np.clip(err / dt, -limit, limit))
        course = wrap_array_inplace(self.course + turn * dt)
        self.course = course
        mid = course - 0.5 * turn * dt
        return self.speed * np.cos(mid), self.speed * np.sin(mid), turn + self.spin

    def write_back(self) -> None:
        for i, mod in enumerate(self.models):
            mod.course = float(self.course[i])
            mod._speed = float(self.speed[i])
            mod._turn = float(self.turn[i])
            mod._next_change = float(self.next_change[i])


class ObstacleBatch:
    """Array state of an episode's obstacles, advanced together (see the module docstring).

    Attributes:
        obstacles: the obstacles, in field order.
        positions: (k, 2) mass centres [m].
        headings: (k,) body rotations [rad].
        velocities: (k, 2) [m/s] and angular_velocities (k,) [rad/s] used over the last step.

    The arrays are replaced, never modified, by :meth:`step`.
    """

    __slots__ = (
        "_const",
        "_other",
        "_random",
        "_states",
        "_stepped",
        "angular_velocities",
        "headings",
        "obstacles",
        "positions",
        "velocities",
    )

    def __init__(self, obstacles: Sequence[Obstacle]) -> None:
        self.obstacles = list(obstacles)
        k = len(self.obstacles)
        self.positions = np.empty((k, 2))
        self.velocities = np.empty((k, 2))
        self.headings = np.empty(k)
        self.angular_velocities = np.empty(k)
        cv: list[int] = []
        rt: list[int] = []
        other: list[int] = []
        for j, ob in enumerate(self.obstacles):
            st = ob.state
            self.positions[j] = st.position
            self.velocities[j] = st.velocity
            self.headings[j] = st.heading
            self.angular_velocities[j] = st.angular_velocity
            kind = type(ob.motion)
            (cv if kind is ConstantVelocity else rt if kind is RandomTurn else other).append(j)
        obs = self.obstacles
        self._const = (
            _ConstantGroup(_rows(cv, k), [obs[j].motion for j in cv])  # type: ignore[misc]
            if cv
            else None
        )
        self._random = (
            _RandomTurnGroup(
                _rows(rt, k),
                [obs[j].motion for j in rt],  # type: ignore[misc]
                [obs[j].state for j in rt],
            )
            if rt
            else None
        )
        self._other = other
        self._states = {j: obs[j].state for j in other}
        self._stepped = False

    @classmethod
    def from_obstacles(cls, obstacles: Sequence[Obstacle]) -> ObstacleBatch:
        return cls(obstacles)

    def __len__(self) -> int:
        return len(self.obstacles)

    def step(self, t: float, dt: float) -> None:
        """Advance every obstacle from time ``t`` [s] by ``dt`` [s]."""
        k = len(self.obstacles)
        if k == 0:
            return
        self._stepped = True
        vel = np.empty((k, 2)) if not self._other else np.zeros((k, 2))
        omega = np.empty(k) if not self._other else np.zeros(k)
        if self._const is not None:
            vel[self._const.rows] = self._const.velocity
            omega[self._const.rows] = self._const.omega
        rnd = self._random
        if rnd is not None:
            rows = rnd.rows
            vx, vy, om = rnd.advance(t, dt, self.positions[rows])
            if isinstance(rows, slice):
                vel[:, 0] = vx
                vel[:, 1] = vy
                omega[:] = om
            else:
                vel[rows, 0] = vx
                vel[rows, 1] = vy
                omega[rows] = om
        pos = self.positions + vel * dt
        heading = wrap_array_inplace(self.headings + omega * dt)
        for j in self._other:
            st = self.obstacles[j].motion.step(self._states[j], t, dt)
            self._states[j] = st
            pos[j] = st.position
            heading[j] = st.heading
            vel[j] = st.velocity
            omega[j] = st.angular_velocity
        self.positions = pos
        self.headings = heading
        self.velocities = vel
        self.angular_velocities = omega

    def field(self, template: FieldTemplate | None = None) -> ObstacleField:
        """The :class:`ObstacleField` of the current state (shares this step's arrays)."""
        tpl = (
            template
            if template is not None
            else FieldTemplate.from_bodies([o.body for o in self.obstacles])
        )
        return tpl.field(self.positions, self.headings, self.velocities, self.angular_velocities)

    def state(self, j: int) -> ObstacleState:
        """Current state of obstacle ``j`` as an :class:`ObstacleState`."""
        if j in self._states:
            return self._states[j]
        return ObstacleState(
            position=self.positions[j].copy(),
            heading=float(self.headings[j]),
            velocity=self.velocities[j].copy(),
            angular_velocity=float(self.angular_velocities[j]),
        )

    def write_back(self) -> None:
        """Store the current states, and the random-turn models' draws and course, on the
        obstacles (as the per-obstacle ``step`` loop would have left them)."""
        if not self._stepped:
            return
        for j, ob in enumerate(self.obstacles):
            ob.state = self.state(j)
        if self._random is not None:
            self._random.write_back()
