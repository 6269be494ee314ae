"""Many obstacles advanced together as arrays: the simulator's hot path for obstacle motion.

:class:`ObstacleBatch` holds the positions, headings and rates of an episode's obstacles as arrays
and advances the common motion models in vectorised form:

* :class:`~uvnav.obstacles.motion.ConstantVelocity`: fixed rates, one array update;
* :class:`~uvnav.obstacles.motion.RandomTurn`: speeds and turn rates drawn from each obstacle's
  own generator with exactly the calls, in exactly the order, that ``RandomTurn.step`` makes
  (obstacles in index order), and the course, arena steering and pose updates done with the same
  floating-point operations, element by element;
* a model class with a ``batch_group(models)`` classmethod (for instance the pedestrian replays
  of :mod:`uvnav.scenarios.pedestrians` and the ORCA pedestrians of :mod:`uvnav.obstacles.crowd`,
  joined into their crowds here by :func:`~uvnav.obstacles.crowd.join_crowds`): one
  :class:`~uvnav.obstacles.motion.MotionGroup` call per class and step;
* any other model (``Waypoints``, ``Replay``, third-party models): its own
  ``step(state, t, dt)``, called per obstacle.

The result is bit for bit what calling ``obstacle.motion.step`` on every obstacle gives (the test
suite checks it), at a cost that hardly grows with the number of obstacles.  Each step makes new
arrays (a field built from them is a snapshot), and :meth:`ObstacleBatch.write_back` puts the final
states and the models' internal state back on the :class:`~uvnav.obstacles.Obstacle` objects.
Presence: a model (or :class:`~uvnav.obstacles.motion.MotionGroup`) with a ``present(t)`` method
says when its body exists; :attr:`ObstacleBatch.present` holds the answers for the current time and
:meth:`ObstacleBatch.field` hands them to the field, whose queries skip absent bodies.
One caveat: models that share one generator are advanced group by group (random-turn obstacles
first), so their draws interleave differently from the per-obstacle loop; give every obstacle its
own generator, as :func:`uvnav.scenarios.build_episode` does.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from uvnav.geometry.angles import FloatArray, wrap_scalar
from uvnav.obstacles.crowd import crowds_seeing_robot, join_crowds
from uvnav.obstacles.motion import (
    ConstantVelocity,
    MotionGroup,
    ObstacleState,
    RandomTurn,
    uniform_draw,
)
from uvnav.obstacles.obstacle import FieldTemplate, Obstacle, ObstacleField, model_present

_Rows = slice | np.ndarray
#: at most this many obstacles outside their arena are steered one by one, more in array form
_FEW = 4


def wrap_array_inplace(a: FloatArray) -> FloatArray:
    """Wrap every element of the C-contiguous array ``a`` to (-pi, pi] in place, exactly as
    :func:`wrap_scalar` does.

    Elements already inside are untouched; the few outside go through :func:`wrap_scalar` itself,
    so both paths agree bit for bit (NaN included).
    """
    ok = np.abs(a) < math.pi
    if ok.size and not ok.flat[ok.argmin()]:
        flat = a.reshape(-1)
        for i in (~ok).reshape(-1).nonzero()[0].tolist():
            flat[i] = wrap_scalar(float(flat[i]))
    return a


def wrap_array(a: FloatArray) -> FloatArray:
    """:func:`wrap_scalar` on every element of ``a`` in array operations (a new array).

    The same operations as :func:`wrap_scalar` (numpy's ``mod`` is Python's ``%`` on floats),
    hence bit for bit its results, NaN included.
    """
    w = math.pi - np.mod(math.pi - a, 2.0 * math.pi)
    w = np.where(w > -math.pi, w, math.pi)
    return np.where((a > -math.pi) & (a <= math.pi), a, w)


def _rows(idx: list[int], k: int) -> _Rows:
    return slice(None) if len(idx) == k else np.array(idx, dtype=np.intp)


class _RandomTurnGroup:
    """The :class:`RandomTurn` obstacles: their parameters, draws and arena boxes as arrays."""

    def __init__(self, rows: _Rows, models: list[RandomTurn]) -> None:
        self.rows = rows
        self.models = models
        m = len(models)
        self.speed = np.array([mod._speed for mod in models], dtype=float)
        self.turn = np.array([mod._turn for mod in models], dtype=float)
        self.next_change = np.array([mod._next_change for mod in models], dtype=float)
        self.threshold = self.next_change - 1e-12
        self.due_at = float(self.threshold.min())
        self.period = [float(mod.change_period) for mod in models]
        self.spin = np.array([mod.spin for mod in models], dtype=float)
        self.has_arena = np.array([mod.arena is not None for mod in models], dtype=bool)
        self.any_arena = bool(self.has_arena.any())
        lo = np.full((2, m), -np.inf)
        hi = np.full((2, m), np.inf)
        mid = np.zeros((2, m))
        for i, mod in enumerate(models):
            if mod.arena is not None:
                x0, y0, x1, y1 = mod.arena
                lo[:, i] = (x0, y0)
                hi[:, i] = (x1, y1)
                mid[:, i] = (0.5 * (x0 + x1), 0.5 * (y0 + y1))
        self.lo = lo
        self.hi = hi
        self.mid = mid
        self.limit = np.array(
            [max(abs(mod.turn_rate[0]), abs(mod.turn_rate[1])) for mod in models], dtype=float
        )
        # per obstacle as Python floats, for the one-by-one steering
        self.steer_consts = [
            (float(mid[0, i]), float(mid[1, i]), float(self.limit[i]), float(self.spin[i]))
            for i in range(m)
        ]
        self.half = np.zeros(m)  # 0.5 * turn * dt, refreshed with the batch's increments

    def draw(self, t: float) -> None:
        """New speeds and turn rates for the obstacles whose change period is over at ``t``."""
        for i in (t >= self.threshold).nonzero()[0].tolist():
            mod = self.models[i]
            self.speed[i] = uniform_draw(mod.rng, mod.speed)
            self.turn[i] = uniform_draw(mod.rng, mod.turn_rate)
            nc = t + self.period[i]
            self.next_change[i] = nc
            self.threshold[i] = nc - 1e-12
        self.due_at = float(self.threshold.min())

    def steer(
        self, x: FloatArray, dt: float, inc: FloatArray, omega: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray] | None:
        """Arena steering (``RandomTurn.step``): this step's ``(inc, omega, half)`` with the
        steered obstacles' turn rates, or None when every obstacle is inside its arena.

        ``x`` is the batch's (4, k) state (x, y, heading, course); ``inc`` (2, k) the heading and
        course increments and ``omega`` (k,) the rotation rates for the drawn turn rates, and
        ``half`` is ``0.5 * turn * dt`` (group order).  A few obstacles outside are steered one by
        one with the very calls of ``RandomTurn.step``; many, in array operations that are the
        same element by element.
        """
        rows = self.rows
        p = x[0:2, rows]
        ok = (self.lo <= p) & (p <= self.hi)
        if ok.flat[ok.argmin()]:
            return None
        m = len(self.models)
        flat = (~ok).reshape(-1).nonzero()[0].tolist()
        out = sorted({i % m for i in flat if self.has_arena[i % m]})
        if not out:
            return None
        course = x[3, rows]
        inc = inc.copy()
        omega = omega.copy()
        if len(out) <= _FEW:
            half = self.half.copy()
            consts = self.steer_consts
            for i in out:
                mid_x, mid_y, lim, spin = consts[i]
                # the operations of RandomTurn.step, on the same values
                to_c = math.atan2(mid_y - float(p[1, i]), mid_x - float(p[0, i]))  # libm's
                e = wrap_scalar(to_c - float(course[i]))
                tr = min(max(e / dt, -lim), lim)  # np.clip(e / dt, -lim, lim)
                om_i = tr + spin
                j = i if isinstance(rows, slice) else int(rows[i])
                omega[j] = om_i
                inc[0, j] = om_i * dt
                inc[1, j] = tr * dt
                half[i] = 0.5 * tr * dt
            return inc, omega, half
        dy = self.mid[1] - p[1]
        dx = self.mid[0] - p[0]
        to_centre = np.zeros(m)
        for i in out:  # libm's atan2, as RandomTurn.step
            to_centre[i] = math.atan2(float(dy[i]), float(dx[i]))
        err = wrap_array(to_centre - course)
        steer = np.minimum(np.maximum(err / dt, -self.limit), self.limit)
        outside = np.zeros(m, dtype=bool)
        outside[out] = True
        turn = np.where(outside, steer, self.turn)
        om = turn + self.spin
        omega[rows] = om
        inc[0, rows] = om * dt
        inc[1, rows] = turn * dt
        return inc, omega, 0.5 * turn * dt


class ObstacleBatch:
    """Array state of an episode's obstacles, advanced together (see the module docstring).

    Attributes:
        obstacles: the obstacles, in field order.
        positions: (k, 2) mass centres [m].
        headings: (k,) body rotations [rad].
        velocities: (k, 2) [m/s] and angular_velocities (k,) [rad/s] used over the last step.
        present: (k,) bool, the bodies that exist now, or ``None`` when no model can be absent.

    The arrays are views of storage that :meth:`step` replaces, never modifies.
    """

    __slots__ = (
        "_const",
        "_crowds",
        "_dt",
        "_groups",
        "_inc",
        "_omega",
        "_omega_base",
        "_other",
        "_present",
        "_present_groups",
        "_present_other",
        "_random",
        "_states",
        "_stepped",
        "_v",
        "_x",
        "obstacles",
    )

    def __init__(self, obstacles: Sequence[Obstacle], *, t: float = 0.0) -> None:
        """Batch ``obstacles`` in their current states, which are those of time ``t`` [s]."""
        self.obstacles = list(obstacles)
        join_crowds(self.obstacles)  # crowd pedestrians not yet in a crowd: one per crowd id
        self._crowds = crowds_seeing_robot(self.obstacles)
        k = len(self.obstacles)
        # rows: x, y, heading, course (random-turn obstacles only, else 0)
        x = np.zeros((4, k))
        v = np.zeros((2, k))
        omega = np.zeros(k)
        cv: list[int] = []
        rt: list[int] = []
        other: list[int] = []
        grouped: dict[type, list[int]] = {}
        for j, ob in enumerate(self.obstacles):
            st = ob.state
            x[0:2, j] = st.position
            x[2, j] = st.heading
            v[:, j] = st.velocity
            omega[j] = st.angular_velocity
            kind = type(ob.motion)
            if kind is RandomTurn:
                mod: RandomTurn = ob.motion  # type: ignore[assignment]
                x[3, j] = mod.course_at(st)
                rt.append(j)
            elif kind is ConstantVelocity:
                cv.append(j)
            elif callable(getattr(kind, "batch_group", None)):
                grouped.setdefault(kind, []).append(j)
            else:
                other.append(j)
        self._x = x
        self._v = v
        self._omega = omega
        obs = self.obstacles
        self._const: tuple[_Rows, FloatArray, FloatArray] | None = None
        if cv:
            models: list[ConstantVelocity] = [obs[j].motion for j in cv]  # type: ignore[misc]
            vel = np.array([np.asarray(m.velocity, dtype=float) for m in models]).reshape(-1, 2)
            om = np.array([float(m.angular_velocity) for m in models])
            self._const = (_rows(cv, k), vel.T.copy(), om)
        self._random = (
            _RandomTurnGroup(_rows(rt, k), [obs[j].motion for j in rt])  # type: ignore[misc]
            if rt
            else None
        )
        self._other = other
        self._states = {j: obs[j].state for j in other}
        self._groups: list[tuple[np.ndarray, MotionGroup]] = [
            (np.array(idx, dtype=np.intp), kind.batch_group([obs[j].motion for j in idx]))  # type: ignore[attr-defined]
            for kind, idx in grouped.items()
        ]
        self._present_groups = [
            (idx, group) for idx, group in self._groups if callable(getattr(group, "present", None))
        ]
        self._present_other = [
            j for j in other if callable(getattr(obs[j].motion, "present", None))
        ]
        self._present: np.ndarray | None = None
        if self._present_groups or self._present_other:
            self._present = np.array([model_present(o.motion, t) for o in obs], dtype=bool)
        self._stepped = False
        self._dt = math.nan
        self._inc = np.zeros((2, k))
        self._omega_base = np.zeros(k)

    @classmethod
    def from_obstacles(cls, obstacles: Sequence[Obstacle]) -> ObstacleBatch:
        return cls(obstacles)

    def __len__(self) -> int:
        return len(self.obstacles)

    @property
    def positions(self) -> FloatArray:
        return self._x[0:2].T

    @property
    def headings(self) -> FloatArray:
        return self._x[2]

    @property
    def velocities(self) -> FloatArray:
        return self._v.T

    @property
    def angular_velocities(self) -> FloatArray:
        return self._omega

    @property
    def present(self) -> np.ndarray | None:
        return self._present

    def _update_presence(self, t: float) -> None:
        """:attr:`present` at ``t`` [s] from the models (and groups) that can be absent."""
        if self._present is None:
            return
        pres = np.ones(len(self.obstacles), dtype=bool)
        for idx, group in self._present_groups:
            pres[idx] = group.present(t)  # type: ignore[attr-defined]
        for j in self._present_other:
            pres[j] = model_present(self.obstacles[j].motion, t)
        self._present = pres

    def _refresh(self, dt: float) -> None:
        """Per-step increments of heading and course, and rotation rates, for the current draws."""
        k = len(self.obstacles)
        omega = np.zeros(k)
        inc = np.zeros((2, k))
        if self._const is not None:
            rows, _, om = self._const
            omega[rows] = om
        rnd = self._random
        if rnd is not None:
            omega[rnd.rows] = rnd.turn + rnd.spin
            inc[1, rnd.rows] = rnd.turn * dt
            rnd.half = 0.5 * rnd.turn * dt
        inc[0] = omega * dt
        self._dt = dt
        self._inc = inc
        self._omega_base = omega

    @property
    def sees_robot(self) -> bool:
        """Whether some obstacle reacts to the robot (a crowd with a visible robot)."""
        return bool(self._crowds)

    def see_robot(self, position: FloatArray, velocity: FloatArray, radius: float) -> None:
        """Tell the obstacles that react to the robot where it is: position [m], velocity
        [m/s], disc radius [m] (the world calls it before every :meth:`step`)."""
        for crowd in self._crowds:
            crowd.see_robot(position, velocity, radius)

    def step(self, t: float, dt: float) -> None:
        """Advance every obstacle from time ``t`` [s] by ``dt`` [s]."""
        k = len(self.obstacles)
        if k == 0:
            return
        self._stepped = True
        rnd = self._random
        refresh = dt != self._dt
        if rnd is not None and t >= rnd.due_at:
            rnd.draw(t)
            refresh = True
        if refresh:
            self._refresh(dt)
        x = self._x
        inc = self._inc
        omega = self._omega_base
        half = rnd.half if rnd is not None else None
        if rnd is not None and rnd.any_arena:
            steered = rnd.steer(x, dt, inc, omega)
            if steered is not None:
                inc, omega, half = steered
        xn = np.empty((4, k))
        np.add(x[2:4], inc, out=xn[2:4])
        wrap_array_inplace(xn[2:4])
        v = np.empty((2, k)) if not (self._other or self._groups) else np.zeros((2, k))
        if self._const is not None:
            rows, vel, _ = self._const
            v[:, rows] = vel
        if rnd is not None:
            rows = rnd.rows
            if isinstance(rows, slice):
                mid = xn[3] - half
                np.cos(mid, out=v[0])
                np.sin(mid, out=v[1])
                v *= rnd.speed
            else:
                mid = xn[3, rows] - half
                v[0, rows] = rnd.speed * np.cos(mid)
                v[1, rows] = rnd.speed * np.sin(mid)
        np.add(x[0:2], v * dt, out=xn[0:2])
        if self._other or self._groups:
            omega = omega.copy()
            for idx, group in self._groups:
                p, h, vel, om = group.step(x[0:2, idx], x[2, idx], t, dt)
                xn[0:2, idx] = p
                xn[2, idx] = h
                v[:, idx] = vel
                omega[idx] = om
            for j in self._other:
                st = self.obstacles[j].motion.step(self._states[j], t, dt)
                self._states[j] = st
                xn[0:2, j] = st.position
                xn[2, j] = st.heading
                v[:, j] = st.velocity
                omega[j] = st.angular_velocity
        self._x = xn
        self._v = v
        self._omega = omega
        self._update_presence(t + dt)

    def field(self, template: FieldTemplate | None = None) -> ObstacleField:
        """The :class:`ObstacleField` of the current state (shares this step's arrays)."""
        tpl = (
            template
            if template is not None
            else FieldTemplate.from_bodies([o.body for o in self.obstacles])
        )
        return tpl.field(
            self.positions, self.headings, self.velocities, self.angular_velocities, self._present
        )

    def state(self, j: int) -> ObstacleState:
        """Current state of obstacle ``j`` as an :class:`ObstacleState`."""
        if j in self._states:
            return self._states[j]
        return ObstacleState(
            position=self._x[0:2, j].copy(),
            heading=float(self._x[2, j]),
            velocity=self._v[:, j].copy(),
            angular_velocity=float(self._omega[j]),
        )

    def write_back(self) -> None:
        """Store the current states, and the random-turn models' draws and course, on the
        obstacles (as the per-obstacle ``step`` loop would have left them)."""
        if not self._stepped:
            return
        for j, ob in enumerate(self.obstacles):
            ob.state = self.state(j)
        rnd = self._random
        if rnd is not None:
            course = self._x[3, rnd.rows]
            for i, mod in enumerate(rnd.models):
                mod.course = float(course[i])
                mod._speed = float(rnd.speed[i])
                mod._turn = float(rnd.turn[i])
                mod._next_change = float(rnd.next_change[i])
