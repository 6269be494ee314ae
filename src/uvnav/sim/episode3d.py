"""The Chapter-3 world: sensing, exact integration, exact collision checks, metrics (DESIGN §2,
§4; thesis Chapter 3), stepped by the one loop :func:`uvnav.core.run_loop` (which times each
decision in CPU time).

The controller is asked every ``control_period`` [s] (a whole multiple of ``dt``); the robot
(:func:`uvnav.dynamics.vehicle3d.vehicle3d_advance`, exact on the sphere of headings) and the
obstacles (exact translation and rotation) are integrated every ``dt`` [s] with the last command
held.  Collisions are judged along the whole of every step by conservative advancement
(:func:`~uvnav.sim.swept.first_contact`: the robot's arc and each body's pose, moved by the rates
held over the step, are exact at any fraction of it), so a contact between two samples deeper
than 0.1 mm is a collision.  At the end of every integration step the clearance between the
robot's sphere and every obstacle is checked exactly: obstacles are culled by bounding spheres
(a lower bound of their distance), and the exact signed distance (mesh kernel with pseudo-normal
sign, or the sphere's closed form) is computed for those whose lower bound is below the step's
best value or may overlap.  The minimum clearance is the exact minimum over the steps' ends and
the samples the advancement took.

The metrics are those of :mod:`uvnav.sim.metrics` (same names).  The simulator clips nothing
silently: a command outside (3.4)-(3.6) is made physical (:meth:`Vehicle3DCommand.clipped`) and
counted in ``limit_violations``.  Obstacle rates given to the controller are the true ones
(``velocities="known"``, an oracle: the thesis's "known motion" case) or finite differences of what
is sensed (``"estimated"``, :class:`uvnav.sensors.sensing3d.FiniteDifference3D`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar, Literal

import numpy as np

from uvnav.core import AgentLog, BaseProbe
from uvnav.dynamics.vehicle3d import Vehicle3DCommand, Vehicle3DSpec, vehicle3d_advance
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.frames3d import check_unit, rotation_from_vector
from uvnav.obstacles.motion3d import Obstacle3D
from uvnav.sensors.sensing3d import FiniteDifference3D, Observation3D, sense_obstacles3d
from uvnav.sim.ledger import Clock, Ledger, OneVehicle
from uvnav.sim.metrics import EpisodeMetrics
from uvnav.sim.swept import first_contact


@dataclass(frozen=True)
class Sensing3DConfig:
    """How 3D observations are made.

    Attributes:
        sensing_range: obstacles whose surface is farther [m] are not reported.
        velocities: ``"known"`` (true v_i, u_i; oracle) or ``"estimated"`` (finite differences).
        position_noise: std [m] of noise on the sensed centre when estimating.
    """

    sensing_range: float = 8.0
    velocities: Literal["known", "estimated"] = "estimated"
    position_noise: float = 0.0


@dataclass
class Episode3DSetup:
    """A fully instantiated 3D episode.

    Attributes:
        spec: robot limits and radius.
        start: initial position S [m], (3,).
        heading: initial unit heading a_R(0), (3,).
        goal: end point E [m], (3,).
        obstacles: the obstacles (their states are advanced in place).
        dt: integration step [s].
        control_period: decision period [s], a whole multiple of ``dt``.
        t_max: time limit [s].
        goal_tolerance: E is reached within this distance [m].
        sensing: sensing configuration.
    """

    spec: Vehicle3DSpec
    start: FloatArray
    heading: FloatArray
    goal: FloatArray
    obstacles: list[Obstacle3D]
    dt: float = 0.05
    control_period: float = 0.1
    t_max: float = 120.0
    goal_tolerance: float = 0.3
    sensing: Sensing3DConfig = field(default_factory=Sensing3DConfig)


@dataclass
class Trajectory3D:
    """Recorded episode (one row per integration step, plus the final state).

    Attributes:
        time: (T,) [s]; position: (T, 3) [m]; heading: (T, 3); speed: (T,) [m/s];
        turn: (T, 3) u_R [rad/s]; mode: (T,) strings; clearance: (T,) [m]; nearest: (T,) ids;
        obstacle_centres: (T, n, 3) [m]; obstacle_velocity: (T, n, 3) [m/s];
        obstacle_rotation_rate: (T, n, 3) [rad/s];
        predicted_velocity: (T, n, 3) the controller's prediction of v_i (nan where none);
        obstacle_outlines: per obstacle, its body-frame spanning points (n_k, 3);
        obstacle_rotations: (T, n, 3, 3).
    """

    time: FloatArray
    position: FloatArray
    heading: FloatArray
    speed: FloatArray
    turn: FloatArray
    mode: np.ndarray
    clearance: FloatArray
    nearest: np.ndarray
    obstacle_centres: FloatArray
    obstacle_velocity: FloatArray
    obstacle_rotation_rate: FloatArray
    predicted_velocity: FloatArray
    obstacle_rotations: FloatArray
    obstacle_outlines: list[FloatArray]
    obstacle_faces: list[np.ndarray | None]


def clearance3d(
    position: FloatArray, obstacles: list[Obstacle3D], robot_radius: float
) -> tuple[float, int]:
    """Exact gap [m] between the robot's sphere and the nearest obstacle (negative on overlap) and
    that obstacle's index (``(inf, -1)`` without obstacles).

    Bounding spheres give lower bounds; exact distances are computed in increasing order of the
    bound until the bound exceeds the best exact gap."""
    if not obstacles:
        return math.inf, -1
    p = position
    lows = []
    for i, ob in enumerate(obstacles):
        g = p - ob.state.centre
        lows.append((math.sqrt(float(g @ g)) - ob.body.bounding_radius - robot_radius, i))
    lows.sort()
    best, best_i = math.inf, -1
    for low, i in lows:
        if low >= best:
            break
        _, d = obstacles[i].nearest(p)
        gap = d - robot_radius
        if gap < best:
            best, best_i = gap, i
    return best, best_i


class _GapTracker:
    """Exact minimum clearance and collision test without an exact query every step.

    The distance between the robot's centre and a body changes by at most
    ``(V_R + ||v_i|| + ||u_i|| R_i) dt`` over a step (robot speed plus the fastest boundary point of
    the body), with the rates held over the step known to the simulator.  Each obstacle keeps a
    lower bound of its gap, lowered by that amount every step and replaced by the exact gap
    whenever the bound falls below the episode's minimum so far (the only case in which the step
    could set a new minimum or collide, since the minimum is >= 0 while there is no collision).
    The returned clearance is exact when it matters and a lower bound above the minimum otherwise,
    so the minimum clearance and the collision test equal those of the exact check every step.
    """

    def __init__(self, obstacles: list[Obstacle3D], robot_radius: float, pos: FloatArray) -> None:
        self.obstacles = obstacles
        self.radius = robot_radius
        self.low = [obstacles[i].nearest(pos)[1] - robot_radius for i in range(len(obstacles))]
        # per obstacle: (velocity bytes, rotation-rate bytes) -> boundary speed bound [m/s]
        self._speed: list[tuple[bytes, bytes, float]] = [(b"", b"", 0.0)] * len(obstacles)

    def _boundary_speed(self, i: int, ob: Obstacle3D) -> float:
        """||v_i|| + ||u_i|| R_i, recomputed only when the rates change (they are held for
        whole sampling periods)."""
        st = ob.state
        kv, ku = st.velocity.tobytes(), st.rotation_rate.tobytes()
        cached = self._speed[i]
        if cached[0] == kv and cached[1] == ku:
            return cached[2]
        speed = (
            math.sqrt(float(st.velocity @ st.velocity))
            + math.sqrt(float(st.rotation_rate @ st.rotation_rate)) * ob.body.bounding_radius
        )
        self._speed[i] = (kv, ku, speed)
        return speed

    def step(self, pos: FloatArray, v_robot: float, dt: float, best: float) -> tuple[float, int]:
        out, out_i = math.inf, -1
        for i, ob in enumerate(self.obstacles):
            drift = (abs(v_robot) + self._boundary_speed(i, ob)) * dt
            low = self.low[i] - drift * (1.0 + 1e-9) - 1e-12
            if low < best:
                low = ob.nearest(pos)[1] - self.radius
            self.low[i] = low
            if low < out:
                out, out_i = low, i
        return out, out_i


class Vehicle3DWorld(OneVehicle):
    """The Chapter-3 world: one 3D vehicle among moving, rotating bodies
    (:class:`uvnav.core.World`), run by :func:`~uvnav.sim.run.run_episode` and stepped by the
    Gymnasium env ``uvnav/Nav3D-v0`` (:mod:`uvnav.envs.nav3d`).

    The bookkeeping (path, effort, limit violations, clearance, status) is the one
    :class:`~uvnav.sim.ledger.Ledger`'s, so both users get the same numbers.

    Args:
        setup: the episode (its obstacles are advanced in place).
        rng: the episode generator; two independent children feed the law and the sensing noise
            (the estimator's).
        exact: exact clearance every step (:func:`clearance3d`); otherwise the
            :class:`_GapTracker`'s bound, exact whenever it can set a new minimum.

    Raises:
        ValueError: a non-unit initial heading, or a control period that is not a whole multiple
            of ``dt``.
    """

    vehicle: ClassVar[str] = "vehicle3d"
    sensing: ClassVar[str] = "exact"

    def __init__(self, setup: Episode3DSetup, rng: np.random.Generator, *, exact: bool) -> None:
        self.setup = setup
        self._law_rng, self.sense_rng = rng.spawn(2)
        self.spec = setup.spec
        self.clock = Clock(setup.dt, setup.control_period, setup.t_max)
        self.dt, self.ratio = self.clock.dt, self.clock.ratio
        self.goal = np.asarray(setup.goal, dtype=float)
        self.pos = np.asarray(setup.start, dtype=float).copy()
        self.a = check_unit(setup.heading, name="heading").copy()
        self.obstacles = setup.obstacles
        self.sensing_range = float(setup.sensing.sensing_range)
        self.exact = exact
        self.t = 0.0
        self.done = False

    def law_setup(self, agent: int = 0) -> tuple[Vehicle3DSpec, FloatArray, np.random.Generator]:
        """The law's limits, goal and generator."""
        return self.spec, self.goal, self._law_rng

    def start(self, oracles: Sequence[bool] = (False,)) -> None:
        """Rates of the first step, clearance and status at t = 0 (after the law's reset).  The
        obstacles' true rates are sensed when the velocities are known or the law is an oracle,
        finite differences otherwise (see :class:`Sensing3DConfig`)."""
        spec = self.spec
        obstacles = self.obstacles
        sensing = self.setup.sensing
        self.known = sensing.velocities == "known" or bool(oracles[0])
        self.estimator = (
            None if self.known else FiniteDifference3D(self.sense_rng, sensing.position_noise)
        )
        # obstacle rates of the first step (so that the first sensing sees them)
        for ob in obstacles:
            ob.state.velocity, ob.state.rotation_rate = ob.motion.rates(0.0, ob.state)
        self.clearance, self.nearest = clearance3d(self.pos, obstacles, spec.radius)
        self.tracker = (
            None if self.exact or not obstacles else _GapTracker(obstacles, spec.radius, self.pos)
        )
        self.applied = Vehicle3DCommand(0.0, np.zeros(3))
        self.u_held = np.zeros(3)
        self.t = 0.0
        self.book = Ledger(self.setup.goal_tolerance)
        gd = float(np.linalg.norm(self.goal - self.pos))
        self.done = self.book.begin(self.clearance, gd) or self.clock.up

    def observe(self, agent: int = 0) -> Observation3D:
        """What the robot senses now (rates known or estimated; see :class:`Sensing3DConfig`)."""
        readings = sense_obstacles3d(
            self.pos, self.obstacles, sensing_range=self.sensing_range, known=self.known
        )
        if self.estimator is not None:
            readings = self.estimator.update(self.t, readings)
        return Observation3D(
            time=self.t, position=self.pos.copy(), heading=self.a.copy(), speed=self.applied.v,
            goal=self.goal, obstacles=readings,
        )  # fmt: skip

    def apply(self, cmd: Vehicle3DCommand, agent: int = 0) -> Vehicle3DCommand:
        """Hold ``cmd`` from now on: counted in ``limit_violations`` when outside (3.4)-(3.6),
        made physical (:meth:`Vehicle3DCommand.clipped`); returns what is applied."""
        if cmd.violates(self.spec, self.a):
            self.book.violations += 1
        new = cmd.clipped(self.spec, self.a)
        if self.clock.step_index > 0:
            self.book.effort += (new.v - self.applied.v) ** 2 / (self.ratio * self.dt)
        self.applied = new
        self.u_held = new.u
        return new

    def advance(self) -> None:
        """One integration step ``dt``: robot, obstacles, clearance, collision and arrival."""
        dt, book = self.dt, self.book
        u_held = self.u_held
        book.effort += float(u_held @ u_held) * dt
        start, head, v, g0 = self.pos, self.a, self.applied.v, self.clearance
        new_pos, self.a, self.u_held = vehicle3d_advance(start, head, v, u_held, dt)
        book.path += float(np.linalg.norm(new_pos - start))
        self.pos = new_pos
        t = t0 = self.t
        poses = [(ob.state.centre, ob.state.rotation) for ob in self.obstacles]
        for ob in self.obstacles:
            ob.step(t, dt)
        # the rates held over the step (the next step's are set below)
        rates = [(ob.state.velocity.copy(), ob.state.rotation_rate.copy()) for ob in self.obstacles]
        self.t = t = self.clock.tick()
        if self.tracker is None:
            self.clearance, self.nearest = clearance3d(self.pos, self.obstacles, self.spec.radius)
        else:  # (uses the rates held over the step just done)
            self.clearance, self.nearest = self.tracker.step(
                self.pos, self.applied.v, dt, book.min_clear
            )
        for ob in self.obstacles:  # rates of the next step, visible to the next sensing
            ob.state.velocity, ob.state.rotation_rate = ob.motion.rates(t, ob.state)
        contact_at = None
        if self.obstacles:

            def gap_at(s: float) -> float:
                p = vehicle3d_advance(start, head, v, u_held, s * dt)[0]
                return min(
                    ob.body.nearest_world(p, c + vel * (s * dt),
                                          rotation_from_vector(w * (s * dt)) @ rot)[1]
                    for ob, (c, rot), (vel, w) in zip(self.obstacles, poses, rates, strict=True)
                ) - self.spec.radius  # fmt: skip

            reach = dt * (abs(v) + max(
                float(np.linalg.norm(vel)) + float(np.linalg.norm(w)) * ob.body.bounding_radius
                for ob, (vel, w) in zip(self.obstacles, rates, strict=True)
            ))  # fmt: skip
            s_hit, least = first_contact(gap_at, g0, self.clearance, reach)
            book.min_clear = min(book.min_clear, least)
            if not math.isnan(s_hit):
                contact_at = t0 + s_hit * dt
        gd = float(np.linalg.norm(self.goal - self.pos))
        self.done = book.judge(t, self.clearance, gd, contact_at) or self.clock.up

    def close(self) -> None:
        """Nothing to write back (the obstacles were advanced in place)."""

    def metrics(self, log: AgentLog, agent: int = 0) -> EpisodeMetrics:
        """The episode's metrics (:mod:`uvnav.sim.metrics`) so far."""
        return self.book.metrics(log, top_speed=self.spec.v_max)

    def recorder(self) -> Trajectory3DProbe:
        """The probe that records this world's trajectory."""
        return Trajectory3DProbe()


class Trajectory3DProbe(BaseProbe):
    """Records a :class:`Vehicle3DWorld` at every integration step and at the end.

    Besides the world's state it keeps a trace of the law's state: its mode at its last decision
    and its predicted obstacle velocities (the law's ``predictions`` attribute, ``{obstacle id:
    (v_i, ...)}``, when it has one), read at every step.
    """

    def __init__(self) -> None:
        self.rows: list[tuple[Any, ...]] = []
        self.outlines: list[FloatArray] = []
        self.faces: list[np.ndarray | None] = []
        self.mode = ""  # the law's mode at its last decision

    def on_start(self, world: Any, laws: Sequence[Any]) -> None:
        self.outlines = [o.body.outline_points() for o in world.obstacles]
        self.faces = [getattr(o.body, "faces", None) for o in world.obstacles]

    def on_decision(self, world: Any, agent: int, law: Any, obs: Any, applied: Any) -> None:
        self.mode = law.mode

    def on_step(self, world: Any, laws: Sequence[Any]) -> None:
        obstacles = world.obstacles
        n = len(obstacles)
        pred = np.full((n, 3), np.nan)
        for i, val in (getattr(laws[0], "predictions", None) or {}).items():
            if 0 <= i < n:
                pred[i] = val[0]
        states = [o.state for o in obstacles]
        self.rows.append(
            (
                world.t, world.pos.copy(), world.a.copy(), world.applied.v, world.u_held.copy(),
                self.mode, world.clearance, world.nearest,
                np.array([s.centre for s in states]).reshape(n, 3),
                np.array([s.velocity for s in states]).reshape(n, 3),
                np.array([s.rotation_rate for s in states]).reshape(n, 3),
                pred,
                np.array([s.rotation for s in states]).reshape(n, 3, 3),
            )
        )  # fmt: skip

    on_end = on_step

    def finish(self) -> Trajectory3D:
        cols = list(zip(*self.rows, strict=True))
        return Trajectory3D(
            time=np.array(cols[0]),
            position=np.array(cols[1]),
            heading=np.array(cols[2]),
            speed=np.array(cols[3]),
            turn=np.array(cols[4]),
            mode=np.array(cols[5]),
            clearance=np.array(cols[6]),
            nearest=np.array(cols[7]),
            obstacle_centres=np.array(cols[8]),
            obstacle_velocity=np.array(cols[9]),
            obstacle_rotation_rate=np.array(cols[10]),
            predicted_velocity=np.array(cols[11]),
            obstacle_rotations=np.array(cols[12]),
            obstacle_outlines=self.outlines,
            obstacle_faces=self.faces,
        )
