"""The 2D world (thesis Ch. 2; DESIGN §2, §4): sensing, exact integration, collision checks and
metrics of one robot among moving bodies, stepped by the one loop :func:`uvnav.core.run_loop`.

:class:`World2D` holds any planar vehicle (:class:`~uvnav.dynamics.vehicles.Vehicle2D`: the
thesis's unicycle, the holonomic disc robot of the crowd benchmarks, or a plug-in; the law's
vehicle picks it); :func:`uvnav.sim.run.run_episode` runs one episode.

Decision rate and integration rate are separate: the law is asked every ``control_period`` [s] (a
whole multiple of ``dt``, else the world refuses the setup with ``ValueError``); robot and obstacles
are integrated every ``dt`` [s] with the last command held.  Collisions are judged along the whole
of every integration step (:class:`~uvnav.sim.swept.SweptClearance`: the robot's disc against the
bodies' sweep, exact for bodies that do not rotate and at most 1 mm short for those that do),
besides the exact clearance sampled at the end of each step (robot disc against disc or polygon
sets, see :meth:`uvnav.obstacles.ObstacleField.query`; the kernel is property-tested against
shapely); the minimum clearance is the minimum along the steps.

The simulator clips nothing silently: a command outside the limits ((2.4), or the V_max disc) is
saturated to what the vehicle can physically do *and* counted in ``limit_violations``.

Speed (``benchmarks/``): the obstacles are advanced together by
:class:`uvnav.obstacles.ObstacleBatch` (bit for bit their models' own ``step``), each step's
:class:`~uvnav.obstacles.ObstacleField` is a few array references, and one nearest-point query per
step, culled by bounding discs, serves both the collision check and, before a decision, the
sensors (:func:`uvnav.sensors.sense_obstacles` finds it cached on the field).  Unrecorded, the
exact clearance of a step that can neither collide nor hold the episode's minimum is never
computed (:class:`_MinClearance`); recorded, every step's is.  Either way the metrics, the
observations and the trajectory are bit for bit those of the straightforward loop (every obstacle
stepped by its own model, exact nearest points of every obstacle at every step).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any, ClassVar

import numpy as np

from uvnav.core import AgentLog, BaseProbe
from uvnav.dynamics.unicycle import UnicycleSpec
from uvnav.dynamics.vehicles import Vehicle2D, make_vehicle
from uvnav.geometry.angles import FloatArray
from uvnav.obstacles.obstacle import FieldTemplate, ObstacleField
from uvnav.sensors.observation import Observation
from uvnav.sensors.suite2d import Sensors2D, observation
from uvnav.sim.bodies2d import Bodies2D, FieldBodies, PackedBodies
from uvnav.sim.comfort import MotionTracker
from uvnav.sim.ledger import Clock, Ledger, OneVehicle
from uvnav.sim.metrics import EpisodeMetrics
from uvnav.sim.packed import pack_check
from uvnav.sim.recorder import Trajectory, TrajectoryRecorder
from uvnav.sim.setup import EpisodeSetup
from uvnav.sim.social import GapHistory, SocialTracker, collision_by, pedestrian_ids
from uvnav.sim.swept import SweptClearance


class World2D(OneVehicle):
    """The 2D world: one planar vehicle among rigid moving bodies (:class:`uvnav.core.World`).

    Bookkeeping (path, effort, limit violations, clearance, status: the one
    :class:`~uvnav.sim.ledger.Ledger`; the social metrics of :mod:`uvnav.sim.social`) is the
    world's, so :func:`~uvnav.sim.run.run_episode` and the Gymnasium env ``uvnav/Nav2D-v0``
    get the same numbers.  Without
    ``exact`` the minimum clearance is tracked by :class:`_MinClearance` (the same minimum, and
    the per-step ``clearance`` only exact when it can matter).

    Args:
        setup: the episode; its obstacles are advanced in place and written back by
            :meth:`close`.
        rng: the episode generator; two independent children feed the law and the sensors.
        exact: the exact clearance and nearest obstacle at every step (recorded runs).
        packed: hold the obstacles as :class:`~uvnav.sim.bodies2d.PackedBodies` when the scene
            packs (:func:`~uvnav.sim.packed.pack_check`): compiled motion, clearance (exact at
            every step) and sensing, the numbers of :class:`~uvnav.sim.bodies2d.FieldBodies`
            (the other scenes' bodies).
        swept: judge collisions and the minimum clearance along every step
            (:class:`~uvnav.sim.swept.SweptClearance`); ``False`` samples the end of each step
            only (for comparisons with the sampled judgement).
        vehicle: the planar vehicle's name (:func:`~uvnav.dynamics.vehicles.vehicles_2d`),
            built from the setup's robot block.
    """

    sensing: ClassVar[str] = "exact"

    def __init__(
        self,
        setup: EpisodeSetup,
        rng: np.random.Generator,
        *,
        exact: bool,
        packed: bool = False,
        swept: bool = True,
        vehicle: str = "unicycle",
    ) -> None:
        self.setup = setup
        self.swept = swept
        self._law_rng, self.sense_rng = rng.spawn(2)
        self.vehicle = vehicle
        self.body: Vehicle2D = make_vehicle(vehicle, setup.spec)
        self.spec: Any = self.body.spec  # what the law is reset with
        self.command_names = self.body.command_names
        self.clock = Clock(setup.dt, setup.control_period, setup.t_max)
        self.dt, self.ratio = self.clock.dt, self.clock.ratio
        self.goal = np.asarray(setup.goal, dtype=float)
        self._gx, self._gy = float(self.goal[0]), float(self.goal[1])
        start = np.asarray(setup.start, dtype=float)
        self.x, self.y, self.th = float(start[0]), float(start[1]), float(start[2])
        self.obstacles = setup.obstacles
        self.template = FieldTemplate.from_bodies([o.body for o in self.obstacles])
        self.bodies: Bodies2D = (
            PackedBodies(self.obstacles, self.template, self.ratio)
            if packed and self.obstacles and pack_check(setup) is None
            else FieldBodies(self.obstacles, self.template, exact)
        )
        self.sensing_range = float(setup.sensing.sensing_range)
        self.sensors = Sensors2D(setup.sensing, self.sense_rng)
        self.pedestrians = pedestrian_ids(self.obstacles)
        self.exact = exact
        #: the bodies take the sensors' readings in the step that ends at a decision (the loop
        #: reads them at every decision); a caller that reads them later, or never, may turn
        #: it off (the same readings, taken when read)
        self.sense_in_step = True
        self.t = 0.0
        self.done = False

    @property
    def field(self) -> ObstacleField:
        """The obstacles now."""
        return self.bodies.field()

    def law_setup(self, agent: int = 0) -> tuple[UnicycleSpec, FloatArray, np.random.Generator]:
        """The law's limits, goal and generator."""
        return self.spec, self.goal, self._law_rng

    @property
    def pose(self) -> FloatArray:
        """``[x, y, theta]`` now."""
        return np.array((self.x, self.y, self.th))

    def start(self, oracles: Sequence[bool] = (False,)) -> None:
        """Clearance and status at t = 0; the finite-difference estimator unless the law is an
        oracle or the velocities are known."""
        self.sensors.reset(oracles[0])
        self.clearance, self.nearest = self.bodies.start(
            self.x, self.y, float(self.spec.radius), self.sensing_range
        )
        self.social: SocialTracker | None = None
        if len(self.pedestrians):
            radius = float(self.spec.radius)
            self.social = SocialTracker(
                self.pedestrians, self.template.radii, radius, self.dt, self.ratio,
                sensing_range=self.sensing_range,
            )  # fmt: skip
            self.social.observe(self.field, self.x, self.y, 0)
        self.sweep = (
            SweptClearance(self.template, float(self.spec.radius))
            if self.swept and self.obstacles
            else None
        )
        self.collision_by: str | None = None
        # the last second, for the blame of a collision with a disc (none: no disc to judge)
        discs = bool((self.template.radii > 0).any())
        self.history = GapHistory(len(self.obstacles), self.dt) if discs else None
        if self.history is not None:
            self.history.push(self.x, self.y, *self.bodies.centres())
        self.turn = 0.0  # total absolute heading change [rad]
        self.body.reset()
        self.applied: Any = self.body.rest()  # the command held now
        self.motion = MotionTracker(self.goal, self.dt, self.x, self.y, self.th, self.velocity())
        self._track = self.motion.track()
        self.book = book = Ledger(self.setup.goal_tolerance)
        gd = math.hypot(self.goal[0] - self.x, self.goal[1] - self.y)
        self.done = book.begin(self.clearance, gd) or self.clock.up
        if book.status == "collision":
            self.collision_by = self._collision_by()

    def observe(self, agent: int = 0) -> Observation:
        """What the robot's sensors give now (:class:`~uvnav.sensors.suite2d.Sensors2D`: the
        bodies within the range, exact or from the lidar scan, their rates known or estimated,
        the scan, the plug-ins)."""
        sensors, bodies = self.sensors, self.bodies
        if sensors.exact_only:  # (Sensors2D.exact_observation, inline)
            x, y = self.x, self.y
            return observation(
                self.t, np.array((x, y, self.th)), self.body.speed(), self.goal,
                bodies.readings(x, y, self.sensing_range), None, {},
            )  # fmt: skip
        return sensors.observe(
            self.t, self.pose, self.speed, self.goal,
            lambda: bodies.readings(self.x, self.y, self.sensing_range), bodies.field,
        )  # fmt: skip

    def observe_later(self, agent: int = 0) -> Callable[[], Observation]:
        """:meth:`observe` now, as a function: where the observation is the exact readings
        alone (:attr:`~uvnav.sensors.suite2d.Sensors2D.exact_only`) what it needs is kept now
        and the objects are made on the call; otherwise the observation is made now."""
        if not self.sensors.exact_only:
            obs = self.observe(agent)
            return lambda: obs
        t, x, y, th, speed, goal = self.t, self.x, self.y, self.th, self.speed, self.goal
        readings = self.bodies.readings_later(x, y, self.sensing_range)
        exact = self.sensors.exact_observation
        return lambda: exact(t, np.array((x, y, th)), speed, goal, readings())

    @property
    def speed(self) -> float:
        """The robot's speed now [m/s] (its vehicle's: the held command's, or on its way to it)."""
        return self.body.speed()

    def velocity(self) -> tuple[float, float]:
        """The robot's velocity now [m/s]."""
        return self.body.velocity(self.th)

    def _collision_by(self, was_present: np.ndarray | None = None) -> str:
        """Who closed the gap at the collision now (:func:`uvnav.sim.social.collision_by`);
        ``was_present``: the bodies that existed one step before."""
        return collision_by(self.field, self.x, self.y, self.velocity(), self.pedestrians,
                            was_present=was_present, history=self.history)  # fmt: skip

    def command_pair(self) -> tuple[float, float]:
        """The applied command as two numbers for the trajectory (:attr:`command_names`)."""
        return self.body.pair(self.applied)

    def apply(self, cmd: Any, agent: int = 0) -> Any:
        """Hold ``cmd``: counted in ``limit_violations`` when outside the vehicle's limits,
        saturated."""
        new, outside = self.body.saturate(cmd, self.th)
        if outside:
            self.book.violations += 1
        if self.clock.step_index > 0:
            self.book.effort += self.body.speed_change(new, self.applied) / (self.ratio * self.dt)
        self.applied = new
        self.body.hold(new)
        return new

    def advance(self) -> None:
        """One step ``dt``: robot (exact), obstacles, clearance, collision and arrival."""
        dt, book, clock, bodies, body = self.dt, self.book, self.clock, self.bodies, self.body
        x, y, t0, g0, ratio = self.x, self.y, self.t, self.clearance, self.ratio
        radius = self.spec.radius
        if bodies.sees_robot:  # bodies that react to the robot see it as it starts the step
            bodies.see_robot(np.array((x, y)), np.array(self.velocity()), radius)
        travel, slack = body.travel(dt)
        # the vehicle's exact motion; the heading, the total turn and the effort's turn term
        k = clock.step_index  # (a decision is due at this step when k % ratio == 0)
        nx, ny, self.th, turn, effort = body.move(x, y, self.th, dt, k % ratio == 0, ratio * dt)
        book.effort += effort
        self.turn += turn
        book.path += math.hypot(nx - x, ny - y)
        self.x, self.y = nx, ny
        sense = self.sensing_range if self.sense_in_step and (k + 1) % ratio == 0 else -1.0
        gap, nearest = bodies.measure(t0, dt, nx, ny, radius, sense)
        self.clearance = gap
        if nearest is not None:
            self.nearest = nearest
        self.t = t = clock.tick()
        k1 = k + 1
        self._track((nx, ny, self.th))
        if self.social is not None:
            self.social.observe(self.field, nx, ny, k1, self.velocity())
        if self.history is not None:
            self.history.push(nx, ny, *bodies.centres())
        sweep, contact_at = self.sweep, None
        if sweep is not None:
            ceiling = bodies.ceiling(book.min_clear, gap)
            shift = bodies.shift  # with it, most steps are left alone without their poses
            if shift is None or not sweep.idle(0.5 * (g0 + gap - travel - shift), ceiling):
                contact_at = self._swept((x, y), (nx, ny), t0, g0, travel, slack, ceiling)
        gd = math.hypot(self._gx - nx, self._gy - ny)
        self.done = book.judge(t, gap, gd, contact_at) or k1 >= clock.n_steps
        if book.status == "collision":  # judged at the first contact when the sweep found it
            sweep = self.sweep
            by = (
                sweep.contact_by(dt, self.velocity(), self.pedestrians, self.history)
                if sweep
                else None
            )
            self.collision_by = by or self._collision_by(bodies.present_before)

    def _swept(
        self,
        p0: tuple[float, float],
        p1: tuple[float, float],
        t0: float,
        g0: float,
        travel: float,
        slack: float,
        ceiling: float,
    ) -> float | None:
        """The step just made from ``p0`` (time ``t0`` [s], sampled gap ``g0`` [m]) to ``p1``,
        judged along its length (:class:`~uvnav.sim.swept.SweptClearance`; ``ceiling``: the
        bodies' bound of the sampled minimum [m]): the time of the first contact [s], ``None``
        without one."""
        sweep, bodies = self.sweep, self.bodies
        assert sweep is not None
        shift = bodies.shift
        s = sweep.step(
            bodies.step_poses_later(p0, p1, slack), travel, g0, self.clearance, ceiling,
            shift=shift, later=True,
        )  # fmt: skip
        return None if math.isnan(s) else t0 + s * self.dt

    def close(self) -> None:
        """Write the obstacles' states back to their models (the setup's objects)."""
        self.bodies.write_back()

    def metrics(self, log: AgentLog, agent: int = 0) -> EpisodeMetrics:
        """The episode's metrics (:mod:`uvnav.sim.metrics`)."""
        # the exact minimum of the steps the bodies deferred
        self.book.min_clear = self.bodies.min_clearance(self.book.min_clear)
        if self.sweep is not None:  # the minimum along the steps
            self.book.min_clear = self.sweep.finish(self.book.min_clear)
            self.sweep = None
        path = self.book.path
        return self.book.metrics(
            log,
            top_speed=float(self.spec.v_max),
            path_irregularity=self.turn / path if path > 0 else None,
            collision_by=self.collision_by,
            **self.motion.metrics(),
            **self._social_metrics(len(log.decision_us)),
        )

    def recorder(self) -> TrajectoryProbe:
        """The probe that records this world's trajectory."""
        return TrajectoryProbe()

    def _social_metrics(self, decisions: int) -> dict[str, float]:
        """The pedestrian metrics (:mod:`uvnav.sim.social`); none without pedestrians."""
        soc = self.social
        if soc is None:
            return {}
        return {
            "min_separation": soc.min_separation,
            "too_close_time": soc.too_close_time,
            "too_close_frequency": soc.too_close_frequency(decisions),
            "intrusion_time": soc.intrusion_time,
            "intrusion_ratio": soc.intrusion_ratio,
            "personal_space_time": soc.personal_space_time,
            "min_time_to_collision": soc.min_ttc,
        }


class TrajectoryProbe(BaseProbe):
    """Records a :class:`World2D` at every integration step and at the end."""

    def __init__(self) -> None:
        self.recorder: TrajectoryRecorder | None = None
        self.mode = ""  # the law's mode at its last decision

    def on_start(self, world: Any, laws: Sequence[Any]) -> None:
        self.recorder = TrajectoryRecorder(
            [o.body.outline() for o in world.obstacles], world.command_names
        )

    def on_decision(self, world: Any, agent: int, law: Any, obs: Any, applied: Any) -> None:
        self.mode = law.mode

    def on_step(self, world: Any, laws: Sequence[Any]) -> None:
        assert self.recorder is not None
        self.recorder.add(
            world.t, world.pose, world.command_pair(), self.mode, world.clearance,
            world.nearest, world.field,
        )  # fmt: skip

    on_end = on_step

    def finish(self) -> Trajectory:
        assert self.recorder is not None
        return self.recorder.finish()
