"""Several robots in one world: each with its own goal, law and sensing, each seeing the others
as moving obstacles (thesis Ch. 8's "next step": robots as a networked system, each
avoiding the others).

Every robot is a unicycle (thesis (2.1)-(2.4)) with a disc body.  At a decision time robot i
senses, with its own :class:`~uvnav.sim.SensingConfig`, the world's obstacles *and the other
robots* — each other robot is a disc obstacle (its radius) whose observed motion is its current
velocity ``V_R [cos theta, sin theta]`` (``velocities="known"``) or, with ``"estimated"``
sensing, the finite-difference estimate of robot i's own
:class:`~uvnav.prediction.FiniteDifferenceEstimator`.  The robots do not communicate: nothing
else passes between them.  Obstacle ids in the observations are the world's obstacles first
(0..k-1), then the robots (k + j).

The world is :class:`MultiUnicycleWorld` (N agents of :class:`uvnav.core.World`), stepped by
the one loop :func:`uvnav.core.run_loop` (:func:`~uvnav.sim.run.run_episode`; the PettingZoo env
:mod:`uvnav.envs.multi_robot` steps the same world): at each decision time the active robots
decide in index order, each reading the world as it is before anyone moves.

Integration, collision checks and the per-robot metrics follow :func:`uvnav.sim.run_episode`
(same names, :data:`uvnav.sim.metrics.METRIC_NAMES`): the robot's clearance is the gap to the
nearest obstacle *or other robot*.  Collisions and the minimum clearance are judged along each
step: against the world's obstacles as the 2D world judges them
(:class:`~uvnav.sim.swept.SweptClearance`), and between robots on the robots' chords
(:func:`~uvnav.geometry.sweep.segment_gaps`: exact for robots that do not turn; a turning
robot's arc stays within ``|v u| dt^2 / 8`` of its chord, 1.25 mm at 1 m/s, 1 rad/s and 0.1 s,
which this judgement does not add: two robots meant to pass exactly touching, as ORCA without a
margin plans them, would otherwise collide on that bound alone).  A robot that reaches its
goal stops there and stays in the world as a parked disc (it is physically there); a robot
that collides stops where it is (a wreck, also still there); its own metrics stop there, as a
single-robot episode's do.  The episode ends when every robot has arrived or collided, or at
``t_max``.

Group metrics (:class:`GroupMetrics`): ``all_arrived``, ``robot_collisions`` (pairs of robots
whose discs ever overlapped), ``obstacle_collisions`` (robots that hit a world obstacle),
``makespan`` [s] (arrival time of the last robot when all arrived, else ``None``), ``deadlocks``
(robots neither arrived nor collided at the end that moved less than ``deadlock_distance`` [m]
over the last ``deadlock_window`` [s]: stuck, not merely slow), ``arrived`` (count) and
``sum_of_times`` [s] (sum of arrival times when all arrived).

Speed: when the world holds only the robots (no world obstacles: the antipodal swap, crossing
flows), the robots live in the arrays of :class:`~uvnav.sim.packed_swarm.SwarmState` and a step
is its compiled step (the unicycles, the robot pairs along the step, the arrivals: the packed
swarm's own kernel); :meth:`MultiUnicycleWorld.apply` holds commands into those arrays, and the
field, the exact readings (:class:`_DiscPairs`, (N, N) arrays with the field's disc-kernel
arithmetic) and the ledgers are made from them only when asked.  The results are identical to
the per-robot path (``vectorised=False``: one :meth:`ObstacleField.query` per robot; tested
against the packed swarm, bit for bit).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, ClassVar

import numpy as np

from uvnav.core import AgentLog, BaseProbe, DiscAgents
from uvnav.dynamics.unicycle import UnicycleCommand, UnicycleSpec, unicycle_advance
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.sweep import disc_sweep, segment_gaps
from uvnav.obstacles.batch import ObstacleBatch
from uvnav.obstacles.bodies import Body, DiscBody
from uvnav.obstacles.obstacle import (
    _CULL_ABS,
    _CULL_REL,
    _X_AXIS,
    FieldTemplate,
    ObstacleField,
)
from uvnav.sensors.exact import sense_obstacles
from uvnav.sensors.observation import Observation, ObstacleReading
from uvnav.sensors.suite2d import Sensors2D
from uvnav.sim.ledger import Clock, Ledger, group_outcome
from uvnav.sim.metrics import EpisodeMetrics
from uvnav.sim.packed_swarm import (
    I_DONE,
    R_CLEAR,
    R_EFFORT,
    R_TH,
    R_U,
    R_V,
    R_VIOL,
    R_VX,
    R_VY,
    R_W,
    R_X,
    R_Y,
    RUNNING,
    SwarmState,
    hold_kernel,
)
from uvnav.sim.setup import (
    GroupMetrics,
    MultiResult,
    MultiSetup,
)
from uvnav.sim.swept import StepPoses, SweptClearance

_NO_OUTLINE = np.zeros((0, 2))  # a disc's outline in a reading (as sense_obstacles gives it)
#: a :class:`~uvnav.sim.packed_swarm.SwarmState` status code's name (a :class:`Ledger`'s)
_STATUS = ("timeout", "success", "collision", "timeout")


def _robot_velocity(v: float, th: float) -> tuple[float, float]:
    return v * math.cos(th), v * math.sin(th)


class _DiscPairs:
    """Every robot's exact nearest points, distances and signed gaps to every robot's disc, at
    once: (N, N) arrays, row i seen from robot i.

    The arithmetic is that of :meth:`ObstacleField.query`'s disc kernel element by element
    (centre offsets, ``hypot``, the unit direction with the x axis at zero distance, the nearest
    boundary point, ``max(r - R, 0)``, the depth of a centre inside a disc), and ``within`` is its
    culling test (bounding disc within ``reach`` plus the same slack), so a row equals what the
    field's query from that robot returns for the robots it keeps.  Used only when the world holds
    no other obstacle.
    """

    def __init__(self, fld: ObstacleField, points: FloatArray, reach: FloatArray) -> None:
        cen = fld.centres
        px = points[:, 0:1]
        py = points[:, 1:2]
        dc = np.hypot(cen[None, :, 0] - px, cen[None, :, 1] - py)
        lower = dc - fld.template.bounding_radii[None, :]
        slack = _CULL_ABS * (1.0 + np.abs(px) + np.abs(py))
        with np.errstate(invalid="ignore"):
            limit = reach[:, None] * (1.0 + _CULL_REL) + slack
        self.within = np.isinf(limit) | (lower <= limit)
        rad = fld.template.radii[None, :]
        offx = px - cen[None, :, 0]
        offy = py - cen[None, :, 1]
        r = np.hypot(offx, offy)
        pos = r > 0
        safe = np.where(pos, r, 1.0)
        ux = np.where(pos, offx / safe, _X_AXIS[0])
        uy = np.where(pos, offy / safe, _X_AXIS[1])
        self.near = np.stack((cen[None, :, 0] + ux * rad, cen[None, :, 1] + uy * rad), axis=-1)
        self.dist = np.maximum(r - rad, 0.0)
        inside = r < rad
        depth = np.hypot(self.near[..., 0] - px, self.near[..., 1] - py)
        self.signed = np.where(inside, -depth, self.dist)

    def readings(
        self, i: int, fld: ObstacleField, sensing_range: float
    ) -> tuple[ObstacleReading, ...]:
        """What :func:`~uvnav.sensors.exact.sense_obstacles` returns from robot i, robot i's own
        disc left out (nearest first, ties in robot order)."""
        dist = self.dist[i]
        order = np.argsort(dist, kind="stable")
        sel = order[dist[order] <= sensing_range]
        sel = sel[sel != i]
        if len(sel) == 0:
            return ()
        # one gather per quantity (fresh arrays: each reading's rows belong to this robot alone)
        near = self.near[i, sel]
        centres = fld.centres[sel]
        velocities = fld.velocities[sel]
        d = dist[sel].tolist()
        omega = fld.angular_velocities[sel].tolist()
        rad = fld.radii[sel].tolist()
        bound = fld.bounding_radii[sel].tolist()
        return tuple(
            ObstacleReading(
                obstacle_id=j,
                distance=d[m],
                nearest_point=near[m],
                centre=centres[m],
                velocity=velocities[m],
                angular_velocity=omega[m],
                outline=_NO_OUTLINE,
                radius=rad[m],
                bounding_radius=bound[m],
            )
            for m, j in enumerate(sel.tolist())
        )


class MultiUnicycleWorld:
    """N unicycles (and the world's obstacles) in one world (:class:`uvnav.core.World`, see the
    module docstring), stepped by :func:`uvnav.core.run_loop`
    (:func:`~uvnav.sim.run.run_episode`) or, one decision at a time, by the PettingZoo env
    :mod:`uvnav.envs.multi_robot`.

    Agent i is robot i.  Per-robot bookkeeping (path, effort, limit violations, clearance,
    status) is robot i's :class:`~uvnav.sim.ledger.Ledger` (``books[i]``), the group's (robot
    pairs that overlapped, obstacle hits, the deadlock window) lives here.  ``clearance[i]`` is
    robot i's gap after the last step [m] (``inf`` when nothing is within its reach, or once it
    is done).

    Args:
        setup: the scene; its obstacles are advanced in place and written back by :meth:`close`.
        rng: the episode generator: ``rng.spawn(2 N)``, robot i's law gets child 2i and its
            sensors (:class:`~uvnav.sensors.suite2d.Sensors2D`: the estimator, the lidar, the
            plug-ins) child 2i + 1.
        vectorised: check and sense all robots at once (:class:`_DiscPairs`) when the world holds
            only robots (identical results; ``False`` forces one field query per robot).

    Raises:
        ValueError: no robot, or ``control_period`` is not a whole multiple of ``dt``.
    """

    vehicle: ClassVar[str] = "unicycle"
    sensing: ClassVar[str] = "exact"

    def __init__(
        self, setup: MultiSetup, rng: np.random.Generator, *, vectorised: bool = True
    ) -> None:
        robots = setup.robots
        n = len(robots)
        if n == 0:
            raise ValueError("a multi-robot episode needs at least one robot")
        for i, r in enumerate(robots):
            if r.spec.kinematics != "arc" or not r.spec.ideal:
                raise ValueError(
                    f"robot {i}: multi-robot worlds hold ideal arc unicycles (no acceleration "
                    "limits, no turn-then-move)"
                )
        self.setup = setup
        self.robots = robots
        self.clock = Clock(setup.dt, setup.control_period, setup.t_max)
        self.dt, self.ratio = self.clock.dt, self.clock.ratio
        self.tol = float(setup.goal_tolerance)
        self._children = rng.spawn(2 * n)
        self.sensors = [
            Sensors2D(r.sensing, self._children[2 * i + 1]) for i, r in enumerate(robots)
        ]
        self._seen: dict[int, tuple[FieldTemplate, np.ndarray]] = {}
        self.obstacles = setup.obstacles
        self.k = k = len(setup.obstacles)
        bodies: list[Body] = [o.body for o in setup.obstacles]
        bodies += [DiscBody(max(float(r.spec.radius), 1e-6)) for r in robots]
        self.template = FieldTemplate.from_bodies(bodies)
        self._bodies = bodies
        self.batch = ObstacleBatch(setup.obstacles)
        self.radii = np.array([float(r.spec.radius) for r in robots])
        floor = 4.0 * float(self.radii.max()) + 1.0  # the reach covers any robot that can touch
        self.reach = np.array([max(float(r.sensing.sensing_range), floor) for r in robots])
        self.state = np.array([np.asarray(r.start, dtype=float)[:3] for r in robots])
        self.goals = np.array([np.asarray(r.goal, dtype=float)[:2] for r in robots])
        self.batched = vectorised and k == 0
        self.core: SwarmState | None = None  # the robots' arrays on the kernel path
        self.t = 0.0
        self.done = False

    @property
    def n_agents(self) -> int:
        return len(self.robots)

    def law_setup(self, agent: int) -> tuple[UnicycleSpec, FloatArray, np.random.Generator]:
        """Robot ``agent``'s limits, goal and generator."""
        return self.robots[agent].spec, self.goals[agent], self._children[2 * agent]

    def _field(self) -> ObstacleField:
        """The obstacles and the robots (discs moving at their held commands; done robots
        still)."""
        n, k, active, state = self.n_agents, self.k, self._active, self.state
        vel = np.array([_robot_velocity(self.speeds[i], state[i, 2]) for i in range(n)])
        vel[~active] = 0.0
        omegas = np.where(active, self.turns, 0.0)
        if not k:
            return self.template.field(state[:, :2].copy(), state[:, 2].copy(), vel, omegas)
        b = self.batch
        return self.template.field(
            np.vstack((b.positions, state[:, :2])),
            np.concatenate((b.headings, state[:, 2])),
            np.vstack((b.velocities, vel)),
            np.concatenate((b.angular_velocities, omegas)),
            None if b.present is None else np.concatenate((b.present, np.ones(n, dtype=bool))),
        )

    def start(self, oracles: Sequence[bool]) -> None:
        """Clearances, collisions and arrivals at t = 0; robot i's finite-difference estimator
        unless its law is an oracle or its velocities are known."""
        n = self.n_agents
        for sensors, oracle in zip(self.sensors, oracles, strict=True):
            sensors.reset(oracle)
        self._applied: list[UnicycleCommand] | None = [UnicycleCommand(0.0, 0.0)] * n
        self.obstacle_hits = 0
        self._exact = np.array([sensors.true_rates for sensors in self.sensors])
        self._sensing = np.array([float(r.sensing.sensing_range) for r in self.robots])
        self._at = -1  # the step of the cached field and robot pairs (kernel path)
        self._pairs: _DiscPairs | None = None
        if self.batched:
            self._start_kernel()
            return
        self.core = None
        self.speeds = np.zeros(n)
        self.turns = np.zeros(n)
        self._active = np.ones(n, dtype=bool)  # neither arrived nor collided
        self._books = [Ledger(self.tol) for _ in range(n)]
        self.clearance = np.full(n, np.inf)
        self._pair_set: set[tuple[int, int]] = set()
        obstacles = FieldTemplate.from_bodies([o.body for o in self.obstacles]) if self.k else None
        self._obstacle_sweeps = (
            [SweptClearance(obstacles, float(r)) for r in self.radii] if obstacles else []
        )
        self.window = max(1, round(self.setup.deadlock_window / self.dt))
        self.history: list[FloatArray] = []
        self._fld = self._field()
        self._check()
        for i, gd in enumerate(self._goal_dists()):
            self._active[i] = not self._books[i].begin(float(self.clearance[i]), gd)
        self.done = not self._active.any() or self.clock.up

    def _start_kernel(self) -> None:
        """The robots in a :class:`~uvnav.sim.packed_swarm.SwarmState` (a world of robots only):
        its arrays are the state, and each step is its compiled kernel."""
        self.core = core = SwarmState(self.setup)
        rob = core.rob
        self.state = rob[:, R_X : R_TH + 1]  # views, valid for the episode
        self.clearance = rob[:, R_CLEAR]
        self._obstacle_sweeps = []
        self._rows = list(rob)  # each robot's row (a view)
        self._views = (rob[:, R_X : R_Y + 1], rob[:, R_TH], rob[:, R_VX : R_VY + 1])
        self._advance = core.advance_kernel
        self._advance_args = (rob, core.status, core.pairs, core.ints, core.flt, core.hist)
        self._stepped, self._rdt = self.clock.step_index > 0, self.ratio * self.dt
        self._hold = hold_kernel()
        self._many: tuple[list[int], np.ndarray] = ([], np.zeros(0, dtype=np.int64))
        self._acting: tuple[bytes, list[int]] = (b"", [])
        self._running: tuple[bytes, np.ndarray] = (b"", np.zeros(0, dtype=bool))
        self._vmax = [float(r.spec.v_max) for r in self.robots]
        self._umax = [float(r.spec.u_max) for r in self.robots]
        self.done = bool(core.ints[I_DONE]) or self.clock.up

    @property
    def active(self) -> np.ndarray:
        """(N,) the robots neither arrived nor collided."""
        if self.core is None:
            return self._active
        status = self.core.status
        key = status.tobytes()  # made again only when a robot ended
        if key != self._running[0]:
            self._running = (key, status == RUNNING)
        return self._running[1]

    @property
    def books(self) -> list[Ledger]:
        """Each robot's :class:`~uvnav.sim.ledger.Ledger` (made from the arrays on the kernel
        path)."""
        return self.core.ledgers(self.status) if self.core is not None else self._books

    @property
    def pairs(self) -> set[tuple[int, int]]:
        """The robot pairs (i < j) whose discs overlapped."""
        return set(self.core.collided_pairs()) if self.core is not None else self._pair_set

    @property
    def field(self) -> ObstacleField:
        """The obstacles and the robots now (discs moving at their held commands)."""
        if self.core is None:
            return self._fld
        if self._at != self.clock.step_index:  # made once per step, when asked
            self._at = self.clock.step_index
            rob = self.core.rob
            self._fld = self.template.field(
                rob[:, R_X : R_Y + 1].copy(), rob[:, R_TH].copy(),
                rob[:, R_VX : R_VY + 1].copy(), rob[:, R_W].copy(),
            )  # fmt: skip
            self._pairs = _DiscPairs(self._fld, self.state[:, :2], self.reach)
        return self._fld

    @property
    def status(self) -> list[str]:
        """Each robot's ``success``, ``collision`` or ``timeout`` (also while running)."""
        if self.core is not None:
            return [_STATUS[c] for c in self.core.status.tolist()]
        return [b.status for b in self._books]

    @property
    def reached(self) -> list[float | None]:
        """Each robot's arrival time [s] (``None`` before)."""
        if self.core is not None:
            return self.core.reached()
        return [b.reached_at for b in self._books]

    def _goal_dists(self) -> list[float]:
        """Each robot's distance to its goal now [m]."""
        return np.hypot(*(self.goals - self.state[:, :2]).T).tolist()

    def _check(self) -> None:
        """Clearances (``inf`` for a robot that is done) and the collisions' pairs and obstacle
        hits, after a step or at t = 0; the ledgers judge them."""
        n, k, fld, active = self.n_agents, self.k, self._fld, self._active
        self._hit: set[int] = set()  # robots that hit an obstacle at this sample
        self.clearance = np.full(n, np.inf)
        for i in range(n):
            if not active[i]:
                continue  # an arrived or wrecked robot's episode is over (as in run_episode)
            # the own disc is always nearest: ask for everything within the reach instead
            # (clearances beyond it are not tracked: min_clearance is exact when below it)
            q = fld.query(self.state[i, :2], float(self.reach[i]), nearest=False)
            own = q.ids == k + i
            gaps = (q.signed - self.radii[i])[~own]
            ids = q.ids[~own]
            if len(gaps) == 0:
                continue
            self.clearance[i] = float(gaps.min())
            for j in ids[gaps < 0].tolist():
                if j >= k:
                    self._pair_set.add((min(i, j - k), max(i, j - k)))
                else:
                    self.obstacle_hits += 1
                    self._hit.add(i)

    def acting(self) -> list[int]:
        """The active robots, in index order, at a decision time (every ``control_period``)."""
        if not self.clock.due:
            return []
        if self.core is None:
            return np.flatnonzero(self._active).tolist()
        status = self.core.status
        key = status.tobytes()  # the list is made again only when a robot ended
        if key != self._acting[0]:
            self._acting = (key, np.flatnonzero(self.active).tolist())
        return self._acting[1].copy()

    def observe(self, agent: int = 0) -> Observation:
        """Robot ``agent``'s readings of the obstacles and the other robots (its own disc left
        out; estimated rates unless known)."""
        i = agent
        sensing_range = float(self.robots[i].sensing.sensing_range)
        pose = self.state[i].copy()

        def exact() -> tuple[ObstacleReading, ...]:
            fld = self.field
            if self._pairs is not None:
                return self._pairs.readings(i, fld, sensing_range)
            readings = sense_obstacles(pose[:2], fld, sensing_range=sensing_range)
            return tuple(rd for rd in readings if rd.obstacle_id != self.k + i)

        return self.sensors[i].observe(
            self.t, pose, self.applied[i].v, self.goals[i], exact, lambda: self.field_seen_by(i)
        )

    def field_seen_by(self, agent: int) -> ObstacleField:
        """The bodies robot ``agent``'s lidar and plug-in sensors see: the obstacles and the
        other robots (its own disc left out)."""
        if agent not in self._seen:
            keep = np.array([m for m in range(len(self._bodies)) if m != self.k + agent], dtype=int)
            tpl = FieldTemplate.from_bodies([self._bodies[m] for m in keep])
            self._seen[agent] = (tpl, keep)
        tpl, keep = self._seen[agent]
        f = self.field
        return tpl.field(
            f.centres[keep], f.headings[keep], f.velocities[keep], f.angular_velocities[keep],
            None if f.present is None else f.present[keep],
        )  # fmt: skip

    def disc_agents(self) -> DiscAgents:
        """Every robot's disc now, for a group law (:class:`uvnav.core.DiscAgents`; velocities
        as the other robots' readings give them; ``exact`` where a robot's readings carry the
        true velocities).  On the kernel path (a world of robots only) the arrays are views of
        the world's, valid until the next :meth:`advance`; they must not be written.

        Raises:
            ValueError: the world holds obstacles besides the robots (not covered yet).
        """
        if self.k:
            raise ValueError(
                f"a group law reads a world of robots only; this one holds {self.k} obstacle(s)"
            )
        if self.core is not None:  # views of the arrays: read them before the next step
            pos, th, vel = self._views
            return DiscAgents(
                self.t, pos, th, vel, self.radii, self.active, self._sensing, self._exact
            )
        return DiscAgents(
            time=self.t,
            positions=self.state[:, :2].copy(),
            headings=self.state[:, 2].copy(),
            velocities=np.array(self._fld.velocities, dtype=float),
            radii=self.radii.copy(),
            active=self._active.copy(),
            sensing_range=self._sensing.copy(),
            exact=self._exact.copy(),
        )

    def apply(self, cmd: UnicycleCommand, agent: int = 0) -> UnicycleCommand:
        """Hold ``cmd`` for robot ``agent``: counted in its ``limit_violations`` when outside
        (2.4), saturated."""
        i = agent
        if self.core is not None:  # the kernel path: the same rules, into the arrays
            v, u = cmd.v, cmd.u
            vmax, umax = self._vmax[i], self._umax[i]
            if not (
                type(v) is float and type(u) is float and 0.0 <= v <= vmax and -umax <= u <= umax
            ):
                self._count_violation(cmd, i)
                cmd = cmd.clipped(self.robots[i].spec)
                v, u = cmd.v, cmd.u
            row = self._rows[i]
            if self._stepped:
                row[R_EFFORT] += ((v - row[R_V]) ** 2) / self._rdt
            row[R_V], row[R_U] = v, u
            self.applied[i] = cmd
            return cmd
        spec = self.robots[i].spec
        book = self._books[i]
        if cmd.violates(spec):
            book.violations += 1
        new = cmd.clipped(spec)
        prev = self.applied[i].v
        if self.clock.step_index:
            book.effort += ((new.v - prev) ** 2) / (self.ratio * self.dt)
        self.applied[i] = new
        return new

    def apply_many(self, agents: Sequence[int], commands: FloatArray) -> None:
        """Hold ``commands[k] = (V, u)`` for robot ``agents[k]``, each as :meth:`apply` holds one
        (the group laws' bulk hold, :func:`uvnav.core.run_loop`).  On the kernel path (a world of
        robots only) one compiled call (:func:`~uvnav.sim.packed_swarm.hold_py`) writes them
        into the arrays and no command object is made; :attr:`applied` is made from the arrays
        when next asked."""
        if self.core is None:
            for i, (v, u) in zip(agents, commands.tolist(), strict=True):
                self.apply(UnicycleCommand(v, u), i)
            return
        if agents != self._many[0]:  # the same robots as last time: the same index array
            self._many = (list(agents), np.array(agents, dtype=np.int64))
        self._hold(self.core.rob, self._many[1], len(agents), commands, self._stepped, self._rdt)
        self._applied = None

    @property
    def applied(self) -> list[UnicycleCommand]:
        """Each robot's command held now (the saturated one; zero before its first decision)."""
        if self._applied is None:  # after a bulk hold: made from the arrays
            held = self.core.rob[:, R_V : R_U + 1].tolist()  # type: ignore[union-attr]
            self._applied = [UnicycleCommand(v, u) for v, u in held]
        return self._applied

    def _count_violation(self, cmd: UnicycleCommand, i: int) -> None:
        """Count ``cmd`` in robot i's limit violations when it is outside (2.4) (kernel path)."""
        if cmd.violates(self.robots[i].spec):
            self._rows[i][R_VIOL] += 1.0

    def advance(self) -> None:
        """One step ``dt``: the active robots (exact), the obstacles, clearances, collisions,
        arrivals."""
        if self.core is not None:  # a world of robots only: the compiled step
            self.done = bool(self._advance(*self._advance_args))
            self.t = self.clock.tick()
            self._stepped = True
            return
        dt, state, active = self.dt, self.state, self._active
        start, t0, g0, f0 = state[:, :2].copy(), self.t, self.clearance.copy(), self._fld
        moving = active.copy()
        held = np.array([(c.v, c.u) for c in self.applied]).reshape(-1, 2)
        slack = np.where(moving, np.abs(held[:, 0] * held[:, 1]) * dt * dt / 8.0, 0.0)
        self.history.append(start)
        if len(self.history) > self.window + 1:
            self.history.pop(0)
        for i in range(self.n_agents):
            if not active[i]:
                self.speeds[i] = self.turns[i] = 0.0
                continue
            v, u = self.applied[i].v, self.applied[i].u
            book = self._books[i]
            book.effort += u * u * dt
            x, y, th = state[i]
            nx, ny, nth = unicycle_advance(float(x), float(y), float(th), v, u, dt)
            book.path += math.hypot(nx - x, ny - y)
            state[i] = (nx, ny, nth)
            self.speeds[i], self.turns[i] = v, u
        self.batch.step(self.t, dt)
        self.t = t = self.clock.tick()
        self._fld = self._field()
        self._check()
        hit = self._sweep_robots(start, moving)
        if self._obstacle_sweeps:
            hit = np.fmin(hit, self._sweep_obstacles(f0, start, held, slack, moving, g0))
        for i, gd in enumerate(self._goal_dists()):
            if active[i]:
                at = None if math.isnan(hit[i]) else t0 + float(hit[i]) * dt
                active[i] = not self._books[i].judge(t, float(self.clearance[i]), gd, at)
        self.done = not active.any() or self.clock.up

    def _sweep_robots(self, start: FloatArray, moving: np.ndarray) -> FloatArray:
        """The robot pairs judged along the step on the robots' chords (module docstring): each
        moving robot's least swept gap to the robots within its reach lowers its minimum
        clearance, and a pair below 0 collides.  Returns each robot's first contact as a
        fraction of the step (NaN: none)."""
        n = self.n_agents
        hit = np.full(n, np.nan)
        if n < 2 or not moving.any():
            return hit
        p0, p1 = start, self.state[:, :2]
        bound = self.template.bounding_radii[self.k :]
        dc = np.hypot(p1[None, :, 0] - p1[:, 0:1], p1[None, :, 1] - p1[:, 1:2])
        cull = _CULL_ABS * (1.0 + np.abs(p1[:, 0:1]) + np.abs(p1[:, 1:2]))
        with np.errstate(invalid="ignore"):
            limit = self.reach[:, None] * (1.0 + _CULL_REL) + cull
        within = (np.isinf(limit) | (dc - bound[None, :] <= limit)) & moving[:, None]
        np.fill_diagonal(within, False)
        rad = self.template.radii[self.k :][None, :] + self.radii[:, None]
        gaps = segment_gaps(
            p0[:, 0:1] - p0[None, :, 0], p0[:, 1:2] - p0[None, :, 1],
            p1[:, 0:1] - p1[None, :, 0], p1[:, 1:2] - p1[None, :, 1], rad,
        )  # fmt: skip
        gaps = np.where(within, gaps, np.inf)
        for i in np.flatnonzero(within.any(axis=1)).tolist():
            low = float(gaps[i].min())
            book = self._books[i]
            book.min_clear = min(book.min_clear, low)
            if low >= 0.0:
                continue
            for j in np.flatnonzero(gaps[i] < 0.0).tolist():
                self._pair_set.add((min(i, j), max(i, j)))
                _, _, s = disc_sweep(p0[i], p1[i], p0[j : j + 1], p1[j : j + 1], rad[i, j])
                hit[i] = np.fmin(hit[i], s[0])
        return hit

    def _sweep_obstacles(
        self, f0: ObstacleField, start: FloatArray, held: FloatArray, slack: FloatArray,
        moving: np.ndarray, g0: FloatArray,
    ) -> FloatArray:  # fmt: skip
        """The world's obstacles judged along the step for each moving robot
        (:class:`~uvnav.sim.swept.SweptClearance`); each robot's first contact as a fraction of
        the step (NaN: none)."""
        k, f1 = self.k, self._fld
        pr0 = None if f0.present is None else f0.present[:k]
        pr1 = None if f1.present is None else f1.present[:k]
        hit = np.full(self.n_agents, np.nan)
        for i in np.flatnonzero(moving).tolist():
            poses = StepPoses(
                f0.centres[:k], f0.headings[:k], f1.centres[:k], f1.headings[:k], pr0, pr1,
                start[i], self.state[i, :2].copy(), float(slack[i]),
            )  # fmt: skip
            book = self._books[i]
            travel = abs(float(held[i, 0])) * self.dt
            s = self._obstacle_sweeps[i].step(
                poses, travel, float(g0[i]), float(self.clearance[i]), book.min_clear
            )
            hit[i] = s
            if not math.isnan(s) and i not in self._hit:  # a hit between the samples
                self.obstacle_hits += 1
        return hit

    def _window_start(self) -> FloatArray | None:
        """The positions at the start of the deadlock window (``None`` before the first step)."""
        if self.core is not None:
            return self.core.window_start()
        return self.history[0] if self.history else None

    def close(self) -> None:
        """Write the obstacles' states back to their models (the setup's objects)."""
        self.batch.write_back()

    def metrics(self, log: AgentLog, agent: int = 0) -> EpisodeMetrics:
        """Robot ``agent``'s metrics (the names of a single-robot episode's)."""
        if self._obstacle_sweeps:  # the minimum along the steps it kept
            book = self._books[agent]
            book.min_clear = self._obstacle_sweeps[agent].finish(book.min_clear)
        if self.core is not None:
            book = self.core.ledger(agent, _STATUS[int(self.core.status[agent])])
        else:
            book = self._books[agent]
        return book.metrics(log, top_speed=float(self.robots[agent].spec.v_max))

    def group_metrics(self) -> GroupMetrics:
        """The group's outcome (module docstring, :func:`group_outcome`)."""
        return group_outcome(
            self.setup, self.status, self.reached, self.state[:, :2],
            self._window_start(), self.t, len(self.pairs),
            self.obstacle_hits,
        )  # fmt: skip

    def recorder(self) -> PosesProbe:
        """The probe that records every robot's pose and every obstacle's position."""
        return PosesProbe()

    def result(self, logs: Sequence[AgentLog], recorder: PosesProbe | None) -> MultiResult:
        """The episode's result: per robot and for the group."""
        rec, n = recorder, self.n_agents
        return MultiResult(
            robots=[self.metrics(log, i) for i, log in enumerate(logs)],
            statuses=self.status,
            group=self.group_metrics(),
            times=np.asarray(rec.times) if rec else np.zeros(0),
            poses=np.asarray(rec.poses) if rec and rec.poses else np.zeros((0, n, 3)),
            collided_pairs=sorted(self.pairs),
            obstacle_paths=(
                np.asarray(rec.obstacles) if rec and rec.obstacles else np.zeros((0, 0, 2))
            ),
        )


class PosesProbe(BaseProbe):
    """Records every robot's pose and every obstacle's position of a
    :class:`MultiUnicycleWorld` at every step and at the end."""

    def __init__(self) -> None:
        self.times: list[float] = []
        self.poses: list[FloatArray] = []
        self.obstacles: list[FloatArray] = []

    def on_step(self, world: Any, laws: Sequence[Any]) -> None:
        self.times.append(world.t)
        self.poses.append(world.state.copy())
        self.obstacles.append(np.array(world.batch.positions, dtype=float).reshape(-1, 2))

    on_end = on_step


def summarize(results: Sequence[MultiResult]) -> dict[str, float | None]:
    """Means over episodes: arrival rate, robot-collision pairs, deadlocks, makespan (of the
    episodes where all arrived), for tables."""
    if not results:
        return {}
    n = [len(r.robots) for r in results]
    makespans = [r.group.makespan for r in results if r.group.makespan is not None]
    return {
        "episodes": float(len(results)),
        "arrival_rate": float(
            np.mean([r.group.arrived / m for r, m in zip(results, n, strict=True)])
        ),
        "all_arrived_rate": float(np.mean([r.group.all_arrived for r in results])),
        "robot_collisions": float(np.mean([r.group.robot_collisions for r in results])),
        "obstacle_collisions": float(np.mean([r.group.obstacle_collisions for r in results])),
        "deadlocks": float(np.mean([r.group.deadlocks for r in results])),
        "makespan": float(np.mean(makespans)) if makespans else None,
    }
