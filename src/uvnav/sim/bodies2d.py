"""The bodies of a 2D world as one part (:class:`Bodies2D`): they move, measure the robot's
clearance, feed the exact sensor and give the poses of each step for the sweep.  Two
implementations with the same numbers (``tests/sim/test_sim_packed.py`` compares them bit for
bit): :class:`FieldBodies`, any bodies, moved together by :class:`ObstacleBatch` with one
:class:`ObstacleField` per step; :class:`PackedBodies`, polygons with constant-velocity or
random-turn motion (:func:`~uvnav.sim.packed.pack_check`), moved and measured in compiled calls.
:class:`~uvnav.sim.episode.World2D` composes one and never asks which.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.obstacles.batch import ObstacleBatch
from uvnav.obstacles.motion import RandomTurn
from uvnav.obstacles.obstacle import FieldTemplate, Obstacle, ObstacleField, ObstacleState
from uvnav.sensors.exact import beam_turns, sense_obstacles
from uvnav.sensors.observation import ObstacleReading, ReadingArrays, Readings
from uvnav.sim.packed import (
    BLOCK,
    I_RATIO,
    NR,
    O_UPOS,
    R_CENTRE,
    R_DIST,
    R_NEAR,
    R_OMEGA,
    R_VEL,
    ROW_BLOCKS,
    S_COURSE,
    S_HEADING,
    S_NEXT,
    S_OMEGA,
    S_SPEED,
    S_TURN,
    S_VX,
    S_VY,
    S_X,
    S_Y,
    PackedWorlds,
    direct,
    kernel,
)
from uvnav.sim.swept import StepPoses


class Bodies2D(Protocol):
    """What a 2D world asks of its bodies."""

    @property
    def template(self) -> FieldTemplate:
        """The bodies' packed geometry."""

    @property
    def sees_robot(self) -> bool:
        """Some body reacts to the robot (it is told where the robot is before each step)."""

    @property
    def shift(self) -> float | None:
        """The most any body point moved over the last step [m], where the bodies know it."""

    @property
    def present_before(self) -> np.ndarray | None:
        """Which bodies existed before the last step (``None``: all, always)."""

    def field(self) -> ObstacleField:
        """The bodies now."""

    def centres(self) -> tuple[FloatArray, np.ndarray | None]:
        """The bodies' centres now (k, 2) [m] (a view: copy to keep) and which exist (``None``:
        all)."""

    def see_robot(self, position: FloatArray, velocity: FloatArray, radius: float) -> None:
        """Tell the bodies that react to the robot where it is (before each step)."""

    def start(self, x: float, y: float, radius: float, sensing_range: float) -> tuple[float, int]:
        """The clearance [m] of the robot disc of ``radius`` [m] at ``(x, y)`` at t = 0 and its
        nearest body (-1 without any); the measure may also serve the sensors within
        ``sensing_range`` [m]."""

    def measure(
        self, t: float, dt: float, x: float, y: float, radius: float, sensing_range: float
    ) -> tuple[float, int | None]:
        """Move the bodies from ``t`` by ``dt`` [s]; the robot's clearance [m] at ``(x, y)``
        then (exact, or a lower bound >= 0 where it cannot matter) and its nearest body
        (``None``: not measured this step).  ``sensing_range`` >= 0 [m]: the sensors read at
        this step's end."""

    def readings(self, x: float, y: float, sensing_range: float) -> tuple[ObstacleReading, ...]:
        """The exact sensor's readings from ``(x, y)`` within ``sensing_range`` [m]."""

    def readings_later(
        self, x: float, y: float, sensing_range: float
    ) -> Callable[[], tuple[ObstacleReading, ...]]:
        """:meth:`readings` now, made when the returned function is called (the bodies may have
        moved on by then)."""

    def step_poses(self, p0: FloatArray, p1: FloatArray, slack: float) -> StepPoses:
        """The last step's start and end, with the robot's chord ``p0 -> p1``."""

    def step_poses_later(
        self, p0: tuple[float, float], p1: tuple[float, float], slack: float
    ) -> Callable[[], StepPoses]:
        """:meth:`step_poses` of the last step, made when the returned function is called (the
        bodies may have moved on by then)."""

    def ceiling(self, sampled_min: float, clearance: float) -> float:
        """An upper bound of the episode's sampled minimum clearance so far [m]."""

    def min_clearance(self, sampled_min: float) -> float:
        """The exact minimum of the sampled clearances [m], given the ledger's."""

    def write_back(self) -> None:
        """Leave the setup's obstacles (and their models) as the episode left them."""


class _MinClearance:
    """Exact minimum clearance over an unrecorded episode, without the exact kernel every step.

    A step's clearance (gap between the robot's disc and the nearest obstacle set [m]) matters to
    an unrecorded run only through the episode minimum and the collision test (gap < 0).  Each
    step the field's query bounds it by bounding discs (``NearestQuery.bounds``, the same pass
    that culls for the sensors), and:

    * a step that may overlap (lower bound <= 0) gets its exact clearance now;
    * a step whose sensor query already contains the nearest obstacle gives it exactly for free;
    * any other step is kept (its field and robot position: a few references) only while its
      lower bound is below the best upper bound of the minimum seen so far, and the kept steps
      are evaluated exactly in batches and at the end, in increasing lower-bound order.

    The result is the minimum of the exact clearances of all steps, bit for bit what evaluating
    every step gives: a step that is dropped has a lower bound above the exact clearance of some
    other step.
    """

    __slots__ = ("_best", "_kept", "_radius")

    #: evaluate the kept steps once there are this many (bounds memory and work)
    BATCH = 64

    def __init__(self, robot_radius: float, initial: float) -> None:
        self._radius = robot_radius
        self._best = initial  # exact minimum so far
        self._kept: list[tuple[float, ObstacleField, float, float]] = []

    def _exact(self, fld: ObstacleField, px: float, py: float, radius: float = 0.0) -> float:
        q = fld.query((px, py), radius, nearest=True)
        return float((q.signed - self._radius).min())

    @property
    def best(self) -> float:
        """The least exact clearance evaluated so far [m] (an upper bound of the minimum)."""
        return self._best

    def step(self, fld: ObstacleField, px: float, py: float, radius: float) -> float:
        """Account for the robot at ``(px, py)`` in ``fld``; the query also covers ``radius`` [m]
        for the sensors.  Returns the step's exact clearance, or a lower bound of it that is
        >= 0 (no collision) when it was deferred or not needed."""
        q = fld.query((px, py), radius, nearest=False)
        low = q.bounds[0] - self._radius
        if low <= 0.0:  # possible overlap: the collision test needs the exact value now
            gap = self._exact(fld, px, py, radius)
        elif len(q.ids) and float(q.distance.min()) <= radius:
            # the nearest obstacle is within the sensors' radius, hence in the query
            gap = float((q.signed - self._radius).min())
        else:
            if low < self._best:
                self._kept.append((low, fld, px, py))
                if len(self._kept) >= self.BATCH:
                    self._flush()
            return max(low, 0.0)
        if gap < self._best:
            self._best = gap
        return gap

    def _flush(self) -> None:
        for low, fld, px, py in sorted(self._kept, key=lambda e: e[0]):
            if low >= self._best:
                break
            gap = self._exact(fld, px, py)
            if gap < self._best:
                self._best = gap
        self._kept.clear()

    def finish(self) -> float:
        """The exact minimum clearance of the episode [m]."""
        self._flush()
        return self._best


class FieldBodies:
    """Any bodies (:class:`Bodies2D`): moved together by :class:`ObstacleBatch` (bit for bit
    their models' own ``step``), one :class:`ObstacleField` per step whose one nearest-point
    query serves the collision check and, before a decision, the sensors.  Without ``exact``
    the clearance of a step that can neither collide nor hold the episode's minimum is not
    computed (:class:`_MinClearance`).

    Args:
        obstacles: the episode's obstacles (advanced in place through the batch).
        template: their bodies' template.
        exact: the exact clearance and nearest body at every step (recorded runs).
    """

    shift: float | None = None

    def __init__(self, obstacles: list[Obstacle], template: FieldTemplate, exact: bool) -> None:
        self.template = template
        self.exact = exact
        self.batch = ObstacleBatch(obstacles)
        self._field = self.batch.field(template)
        self._before = self._field
        self._tracker: _MinClearance | None = None

    @property
    def sees_robot(self) -> bool:
        return self.batch.sees_robot

    @property
    def present_before(self) -> np.ndarray | None:
        return self._before.present

    def field(self) -> ObstacleField:
        return self._field

    def centres(self) -> tuple[FloatArray, np.ndarray | None]:
        return self._field.centres, self._field.present

    def see_robot(self, position: FloatArray, velocity: FloatArray, radius: float) -> None:
        self.batch.see_robot(position, velocity, radius)

    def _gap(self, x: float, y: float, radius: float, reach: float) -> tuple[float, int]:
        """Exact gap [m] to the nearest body (negative on overlap) and its index; the query
        also covers ``reach`` [m] for the sensors, which reuse it."""
        if not len(self.template):
            return float("inf"), -1
        q = self._field.query((x, y), reach, nearest=True)
        if len(q.ids) == 0:
            return float("inf"), -1
        gaps = q.signed - radius
        j = int(gaps.argmin())
        return float(gaps[j]), int(q.ids[j])

    def start(self, x: float, y: float, radius: float, sensing_range: float) -> tuple[float, int]:
        gap, at = self._gap(x, y, radius, sensing_range)
        self._tracker = (
            _MinClearance(radius, gap) if len(self.template) and not self.exact else None
        )
        return gap, at

    def measure(
        self, t: float, dt: float, x: float, y: float, radius: float, sensing_range: float
    ) -> tuple[float, int | None]:
        self._before = self._field
        self.batch.step(t, dt)
        self._field = self.batch.field(self.template)
        reach = max(sensing_range, 0.0)
        if self._tracker is not None:
            return self._tracker.step(self._field, x, y, reach), None
        return self._gap(x, y, radius, reach)

    def readings(self, x: float, y: float, sensing_range: float) -> tuple[ObstacleReading, ...]:
        return sense_obstacles(np.array((x, y)), self._field, sensing_range=sensing_range)

    def readings_later(
        self, x: float, y: float, sensing_range: float
    ) -> Callable[[], tuple[ObstacleReading, ...]]:
        got = self.readings(x, y, sensing_range)
        return lambda: got

    def step_poses(self, p0: FloatArray, p1: FloatArray, slack: float) -> StepPoses:
        b, f = self._before, self._field
        return StepPoses(b.centres, b.headings, f.centres, f.headings, b.present, f.present,
                         p0, p1, slack)  # fmt: skip

    def step_poses_later(
        self, p0: tuple[float, float], p1: tuple[float, float], slack: float
    ) -> Callable[[], StepPoses]:
        """:meth:`step_poses` made now (its arrays are the fields' own, which stay as they
        are), returned by the function."""
        poses = self.step_poses(np.array(p0), np.array(p1), slack)
        return lambda: poses

    def ceiling(self, sampled_min: float, clearance: float) -> float:
        if self._tracker is not None:
            return self._tracker.best
        return min(sampled_min, clearance)

    def min_clearance(self, sampled_min: float) -> float:
        """The tracker's exact minimum (and the exact measure from now on), else
        ``sampled_min``."""
        if self._tracker is None:
            return sampled_min
        best = self._tracker.finish()
        self._tracker = None
        return best

    def write_back(self) -> None:
        self.batch.write_back()


class PackedBodies:
    """One episode's obstacles in a packed slot (:class:`Bodies2D`, compiled).  The obstacles
    move, the clearance is measured and the exact sensor reads them in compiled calls
    (:func:`~uvnav.sim.packed.advance_one_py`, :func:`~uvnav.sim.packed.sense_one_py`), with the
    numbers of :class:`FieldBodies`, bit for bit; :meth:`field` builds the field of the moment
    for whatever reads one (lidar, plug-in sensors, the recorder, the collision's blame).

    Unlike :class:`PackedWorlds`, :meth:`write_back` leaves the models exactly as the numpy
    path does, their generators included: each is set back to its state at the start and moved
    on by the numbers the episode read.

    Args:
        obstacles: the episode's obstacles, packable (:func:`pack_check`).
        template: their bodies' template (the world's).
        ratio: integration steps per decision (the rows hold a decision's draws).
    """

    def __init__(self, obstacles: list[Obstacle], template: FieldTemplate, ratio: int) -> None:
        self.obstacles = obstacles
        self.template = template
        self.n = n = len(obstacles)
        self._start = [
            ob.motion.rng.bit_generator.state if isinstance(ob.motion, RandomTurn) else None
            for ob in obstacles
        ]
        self._pw = pw = PackedWorlds(1)
        pw.load_obstacles(0, obstacles, template, max(ROW_BLOCKS * BLOCK, 4 * ratio))
        pw.wi[0, I_RATIO] = 1  # a call of step() is one integration step
        self._oi, self._prm, self._st = pw.oi[0], pw.params[0], pw.state[0]
        self._ubuf, self._rings = pw.ubuf[0], pw.rings[0]
        w = self._rings.shape[2]
        self._ids = np.zeros(n, dtype=np.int64)
        self._rows = np.zeros((n, NR))
        self._outlines = np.zeros((n, w, 2))
        self._counts = [int(template.counts[template.poly_row[j]]) for j in range(n)]
        self._bounds = template.bounding_radii.tolist()
        self._stepped = False
        #: ``(x, y, range, m)`` of the readings the last step took, if it took any
        self._sensed: tuple[float, float, float, int] | None = None
        # the kernels called at every step, without numba's dispatch after their first call
        self._advance = self._direct("_advance", kernel("advance_one"))
        self._sense = self._direct("_sense", kernel("sense_one"))
        self._lidar, self._vector = kernel("lidar"), kernel("vector_one")
        self._ring = np.empty((2, w))  # the lidar's scratch
        self._beams = np.empty((2, 0))
        #: the beams' offsets last read (a read-only array) and their rotations (beam_turns)
        self._turns_of: FloatArray | None = None
        self._turns = np.empty((2, 0))
        self._field: ObstacleField | None = None  # (before any step: the obstacles' own)
        self._prev = np.zeros((3, n))  # the poses before the last step: x, y, heading
        #: the most any body point moved over the last step [m]
        self.shift = 0.0

    def _direct(self, name: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        """``fn``, called through :func:`~uvnav.sim.packed.direct` at its first call, which
        then sets the attribute ``name`` to the function that skips the dispatch (every call
        passes the same buffers and the same kinds of numbers)."""

        def first(*args: Any) -> Any:
            out, fast = direct(fn, *args)
            setattr(self, name, fast)
            return out

        return first

    #: the compiled bodies react to no robot (:func:`~uvnav.sim.packed.pack_check`)
    sees_robot = False
    #: every body exists at every step
    present_before: np.ndarray | None = None

    def see_robot(self, position: FloatArray, velocity: FloatArray, radius: float) -> None:
        """Nothing: no packed body reacts to the robot."""

    def start(self, x: float, y: float, radius: float, sensing_range: float) -> tuple[float, int]:
        """The clearance [m] at t = 0 and the nearest body (:meth:`clearance`)."""
        return self.clearance(x, y, radius)

    def step_poses(self, p0: FloatArray, p1: FloatArray, slack: float) -> StepPoses:
        """The last step's start and end (the poses it kept): views of one copy of each, the
        centres (k, 2) and headings (k,) of :meth:`poses_before` and :meth:`poses`."""
        return self.step_poses_later(p0, p1, slack)()

    def step_poses_later(
        self, p0: tuple[float, float] | FloatArray, p1: tuple[float, float] | FloatArray,
        slack: float,
    ) -> Callable[[], StepPoses]:  # fmt: skip
        """:meth:`step_poses` from copies of the poses taken now, made when the returned
        function is called (the robot's chord as arrays then)."""
        before = self._prev.copy()
        now = self._st[S_X : S_HEADING + 1, : self.n].copy()  # (x, y, heading: rows in a row)
        return lambda: StepPoses(before[:2].T, before[2], now[:2].T, now[2], None, None,
                                 np.array(p0), np.array(p1), slack)  # fmt: skip

    def ceiling(self, sampled_min: float, clearance: float) -> float:
        """An upper bound of the episode's sampled minimum so far [m] (every step's clearance is
        exact)."""
        return min(sampled_min, clearance)

    def min_clearance(self, sampled_min: float) -> float:
        """The exact minimum of the sampled clearances: ``sampled_min`` itself."""
        return sampled_min

    def step(
        self, t: float, dt: float, x: float, y: float, radius: float, sensing_range: float = -1.0
    ) -> tuple[float, int]:
        """Move the obstacles from ``t`` by ``dt`` [s]; the clearance [m] of the robot disc of
        ``radius`` [m] at ``(x, y)`` then, and its nearest obstacle (-1 without any).  With a
        ``sensing_range`` >= 0 [m] the readings from there are taken in the same call, for
        :meth:`readings` to return."""
        pw = self._pw
        if pw.safe_calls <= 0:  # (PackedWorlds.ensure_draws, inline)
            pw.refill()
        pw.safe_calls -= 1
        self._stepped = True
        self._field = None
        gap, at, m, self.shift = self._advance(
            x, y, radius, t, dt, self.n, self._oi, self._prm, self._st, self._ubuf, self._rings,
            sensing_range, self._ids, self._rows, self._outlines, self._prev,
        )  # fmt: skip
        self._sensed = (x, y, sensing_range, m) if m >= 0 else None
        return float(gap), int(at)

    #: (:class:`Bodies2D`) :meth:`step`: the exact clearance after the step, the nearest body
    measure = step

    def clearance(self, x: float, y: float, radius: float) -> tuple[float, int]:
        """The clearance [m] of the robot disc of ``radius`` [m] at ``(x, y)`` now, and its
        nearest obstacle (-1 without any): :meth:`step`'s measure, without moving anything."""
        gap, at = kernel("clearance_one")(x, y, radius, self.n, self._prm, self._st, self._rings)
        return float(gap), int(at)

    def poses(self) -> tuple[FloatArray, FloatArray]:
        """The obstacles' centres (k, 2) [m] and headings (k,) [rad] now (copies)."""
        st, n = self._st, self.n
        return st[S_X : S_Y + 1, :n].T.copy(), st[S_HEADING, :n].copy()

    def poses_before(self) -> tuple[FloatArray, FloatArray]:
        """The obstacles' centres (k, 2) [m] and headings (k,) [rad] before the last
        :meth:`step` (copies)."""
        return self._prev[:2].T.copy(), self._prev[2].copy()

    def readings(self, x: float, y: float, sensing_range: float) -> tuple[ObstacleReading, ...]:
        """:func:`uvnav.sensors.exact.sense_obstacles` from ``(x, y)``: the readings within
        ``sensing_range`` [m], nearest first (ties in obstacle order).  Their arrays are views
        of one block copied for this call."""
        m = self._sense_count(x, y, sensing_range)
        if m == 0:
            return ()
        return self._make_readings(self._ids[:m].tolist(), self._rows[:m].copy(),
                                   self._outlines[:m].copy())  # fmt: skip

    def readings_later(
        self, x: float, y: float, sensing_range: float
    ) -> Callable[[], tuple[ObstacleReading, ...]]:
        """:meth:`readings` now, as a function: the block the last step sensed from ``(x, y)``
        is copied now, or else the obstacles' state, sensed on the call; the reading objects are
        made on the call."""
        got = self._sensed
        if got is None or got[:3] != (x, y, sensing_range):
            state = self._st.copy()
            return lambda: self._sensed_from(state, x, y, sensing_range)
        m = got[3]
        if m == 0:
            return tuple
        # whole buffers: copying them is cheaper than slicing them first
        ids, rows, outlines = self._ids.copy(), self._rows.copy(), self._outlines.copy()
        return lambda: self._make_readings(ids[:m].tolist(), rows[:m], outlines[:m])

    def _sensed_from(
        self, state: FloatArray, x: float, y: float, sensing_range: float
    ) -> tuple[ObstacleReading, ...]:
        """The readings from ``(x, y)`` within ``sensing_range`` [m] of the obstacles in
        ``state`` (a copy of the state array of a moment), in buffers of their own."""
        ids, rows = np.empty_like(self._ids), np.empty_like(self._rows)
        outlines = np.empty_like(self._outlines)
        m = self._sense(x, y, sensing_range, self.n, self._prm, state, self._rings, ids, rows,
                        outlines)  # fmt: skip
        return self._make_readings(ids[:m].tolist(), rows[:m], outlines[:m]) if m else ()

    def _sense_count(self, x: float, y: float, sensing_range: float) -> int:
        """The number of readings from ``(x, y)`` within ``sensing_range`` [m], written to the
        sensed block (taken by the last step when it sensed from there)."""
        got = self._sensed
        if got is not None and got[:3] == (x, y, sensing_range):
            return got[3]
        return int(self._sense(x, y, sensing_range, self.n, self._prm, self._st, self._rings,
                               self._ids, self._rows, self._outlines))  # fmt: skip

    def _make_readings(
        self, ids: list[int], rows: FloatArray, outlines: FloatArray
    ) -> tuple[ObstacleReading, ...]:
        """The reading objects of a sensed block (``ids``, and copies of its rows and
        outlines: the readings' arrays are views of them)."""
        vals = rows.tolist()
        counts, bounds, make = self._counts, self._bounds, ObstacleReading.known
        out = []
        for i, j in enumerate(ids):
            r = rows[i]
            reading = make(
                j, vals[i][R_DIST], r[R_NEAR : R_NEAR + 2], r[R_CENTRE : R_CENTRE + 2],
                r[R_VEL : R_VEL + 2], vals[i][R_OMEGA], outlines[i, : counts[j]], 0.0, bounds[j],
            )  # fmt: skip
            out.append(reading)
        return Readings.lazy(out, lambda: self._arrays(ids, rows), all_known=True)

    def _arrays(self, ids: list[int], rows: FloatArray) -> ReadingArrays:
        """A sensed block (``ids`` and its rows, copies) as the readings' arrays."""
        scal = np.zeros((len(ids), 4))
        scal[:, 0], scal[:, 1] = rows[:, R_DIST], rows[:, R_OMEGA]
        scal[:, 3] = self.template.bounding_radii[ids]
        return scal, rows[:, R_CENTRE : R_CENTRE + 2], rows[:, R_VEL : R_VEL + 2]

    def centres(self) -> tuple[FloatArray, np.ndarray | None]:
        """The obstacles' centres (k, 2) [m] now (a view) and ``None`` (every body exists)."""
        return self._st[S_X : S_Y + 1, : self.n].T, None

    def lidar(
        self, x: float, y: float, th: float, rel: FloatArray, max_range: float, out: FloatArray
    ) -> None:
        """The ranges [m] of :func:`uvnav.sensors.lidar_scan` (no noise) from ``(x, y, th)``,
        beams at ``rel`` [rad] from the heading, into ``out`` (R,), in one compiled call
        (:func:`~uvnav.sim.packed._lidar`; no field is built)."""
        turns, dirs = self._beams_of(rel)
        self._lidar(x, y, th, turns, max_range, self.n, self._prm, self._st, self._rings,
                    self._ring, dirs, out)  # fmt: skip

    def vector(
        self, pose: tuple[float, float, float], goal: tuple[float, float], goal_scale: float,
        speed: float, v_max: float, rel: FloatArray, max_range: float, ranges: FloatArray,
        out: np.ndarray,
    ) -> None:  # fmt: skip
        """An env's observation vector from ``pose`` ``(x, y, theta)`` into ``out`` (4 + R,)
        float32 and its lidar ranges [m] into ``ranges`` (R,), in one compiled call
        (:func:`~uvnav.sim.packed.vector_one_py`: goal ``(x, y)`` [m] and ``goal_scale`` [m],
        ``speed`` and ``v_max`` [m/s], beams at heading + ``rel`` [rad] to ``max_range`` [m])."""
        x, y, th = pose
        turns, dirs = self._beams_of(rel)
        self._vector(x, y, th, goal[0], goal[1], goal_scale, speed, v_max, turns, max_range,
                     self.n, self._prm, self._st, self._rings, self._ring, dirs, ranges,
                     out)  # fmt: skip

    def _beams_of(self, rel: FloatArray) -> tuple[FloatArray, FloatArray]:
        """The beams' rotations (:func:`~uvnav.sensors.exact.beam_turns`, (2, R)) for ``rel``
        (R,) [rad], kept while the same read-only array comes back (an env's
        :func:`~uvnav.sensors.exact.beam_offsets`), and the lidar's scratch for their
        directions, (2, R)."""
        if rel is not self._turns_of:
            self._turns = beam_turns(rel)
            self._turns_of = None if rel.flags.writeable else rel
        if self._beams.shape[1] != rel.shape[0]:
            self._beams = np.empty((2, rel.shape[0]))
        return self._turns, self._beams

    def field(self) -> ObstacleField:
        """The :class:`ObstacleField` of now (built on first use after a step)."""
        if self._field is None:
            self._field = (
                self._make_field()
                if self._stepped
                else ObstacleBatch(self.obstacles).field(self.template)
            )
        return self._field

    def _make_field(self) -> ObstacleField:
        st, n = self._st, self.n
        return self.template.field(
            st[S_X : S_Y + 1, :n].T.copy(), st[S_HEADING, :n].copy(),
            st[S_VX : S_VY + 1, :n].T.copy(), st[S_OMEGA, :n].copy(),
        )  # fmt: skip

    def write_back(self) -> None:
        """Leave the obstacles and their models as :meth:`ObstacleBatch.write_back` does: the
        states and the random-turn models' draws and course, and each generator moved on by
        the numbers read (from its state at the start)."""
        st, upos, read = self._st, self._oi[O_UPOS], self._pw.read[0]
        for o, ob in enumerate(self.obstacles):
            rng, start = self._pw.rngs[0][o], self._start[o]
            if rng is not None and start is not None:
                rng.bit_generator.state = start
                rng.random(int(read[o] + upos[o]))
            if not self._stepped:
                continue
            ob.state = ObstacleState(
                position=np.array((st[S_X, o], st[S_Y, o])),
                heading=float(st[S_HEADING, o]),
                velocity=np.array((st[S_VX, o], st[S_VY, o])),
                angular_velocity=float(st[S_OMEGA, o]),
            )
            mod = ob.motion
            if isinstance(mod, RandomTurn):
                mod.course = float(st[S_COURSE, o])
                mod._speed = float(st[S_SPEED, o])
                mod._turn = float(st[S_TURN, o])
                mod._next_change = float(st[S_NEXT, o])
