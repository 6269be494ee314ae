"""The Chapter-4 world: a planar UUV among shape-changing obstacles, sensed by sonar only,
stepped by the one loop :func:`uvnav.core.run_loop` (which times each decision in CPU time).

Same structure and metrics as :mod:`uvnav.sim.episode` (DESIGN §2, §4; the names of
:data:`~uvnav.sim.metrics.METRIC_NAMES`), for the vehicle of :mod:`uvnav.dynamics.holonomic` and
the bodies of :mod:`uvnav.obstacles.deforming`, whose outlines change every step (the unicycle
world's rigid-body field cannot hold them):

* every ``control_period`` [s] (a whole multiple of ``dt``) the sonar sweeps the viewing cone
  and the law is asked for a velocity; a command outside the limits (4.4)-(4.6) is counted in
  ``limit_violations`` and saturated (:meth:`HolonomicCommand.clipped`), never silently;
* every ``dt`` the vehicle moves exactly (constant velocity) and the clearance is exact at the
  step's end: signed distance from the vehicle's centre to every outline at that instant
  (:func:`~uvnav.geometry.polygons.rings_nearest` with the even-odd test), minus its radius;
  collisions are judged along the whole step by conservative advancement
  (:func:`~uvnav.sim.swept.first_contact`: the outlines are functions of time, and no boundary
  point moves faster than its body's ``max_rate`` plus its centre's speed), so a contact between
  two samples deeper than 0.1 mm is a collision (``swept=False``: at the step's end only);
* ``forbidden`` regions (the inner space of a Fig. 4.2(b) trap) are checked each step too: the
  result says whether the vehicle's centre ever entered one.

``control_effort`` is the analogue of the unicycle's: integral of the turn rate squared
(direction change per decision / T) plus integral of (dV/dt)^2.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from uvnav.core import AgentLog, BaseProbe
from uvnav.dynamics.holonomic import HolonomicCommand, HolonomicSpec, holonomic_step
from uvnav.geometry.angles import FloatArray, wrap_scalar
from uvnav.geometry.polygons import closed_rings, rings_nearest
from uvnav.obstacles.deforming import ShapeChanging
from uvnav.sensors.sonar2d import SonarConfig, SonarObservation, sonar_scan
from uvnav.sim.ledger import Clock, Ledger, OneVehicle
from uvnav.sim.metrics import EpisodeMetrics
from uvnav.sim.swept import first_contact


@dataclass
class Uuv2dSetup:
    """A fully instantiated Chapter-4 episode.

    Attributes:
        spec: vehicle limits and radius.
        start: initial pose ``[x, y, theta]``.
        goal: end point E [m].
        shapes: the obstacles.
        dt: integration step [s].
        control_period: decision period [s] (whole multiple of ``dt``).
        t_max: time limit [s].
        goal_tolerance: E is reached within this distance [m].
        sonar: the viewing-cone sonar.
        forbidden: polygons (n, 2) the vehicle's centre must never enter (trap inner spaces).
    """

    spec: HolonomicSpec
    start: FloatArray
    goal: FloatArray
    shapes: list[ShapeChanging]
    dt: float = 0.05
    control_period: float = 0.2
    t_max: float = 60.0
    goal_tolerance: float = 0.2
    sonar: SonarConfig = field(default_factory=SonarConfig)
    forbidden: list[FloatArray] = field(default_factory=list)


@dataclass
class Uuv2dTrajectory:
    """Recorded episode: per integration step times/poses/clearances, per decision the outlines,
    commands, modes and the law's own record (``decisions``, when it keeps ``last``)."""

    times: FloatArray
    poses: FloatArray
    clearance: FloatArray
    decision_times: FloatArray
    outlines: list[list[FloatArray]]
    commands: FloatArray
    modes: list[str]
    decisions: list[Any]
    #: the end point E [m]
    goal: FloatArray = field(default_factory=lambda: np.zeros(2))
    #: the law's AMAPS grid at the end of the episode (its ``grid`` attribute), if it has one
    grid: Any = None


def clearance_of(
    point: tuple[float, float], outlines: list[FloatArray], radius: float
) -> tuple[float, int]:
    """Gap [m] between the vehicle's disc at ``point`` and the nearest outline (negative on
    overlap), and that obstacle's index; ``(inf, -1)`` with no obstacle."""
    if not outlines:
        return math.inf, -1
    rings, _ = closed_rings(outlines)
    dist, _, inside = rings_nearest(point, rings)
    assert inside is not None
    signed = np.where(inside, -dist, dist) - radius
    j = int(np.argmin(signed))
    return float(signed[j]), j


def inside_any(point: tuple[float, float], polygons: list[FloatArray]) -> bool:
    """True when ``point`` lies inside one of ``polygons``."""
    if not polygons:
        return False
    rings, _ = closed_rings(polygons)
    _, _, inside = rings_nearest(point, rings)
    return bool(inside is not None and inside.any())


class Uuv2dWorld(OneVehicle):
    """The Chapter-4 world: one planar UUV among shape-changing bodies, sensed by its sonar
    (:class:`uvnav.core.World`), run by :func:`~uvnav.sim.run.run_episode` and stepped by the
    Gymnasium env ``uvnav/UUV2D-v0`` (:mod:`uvnav.envs.uuv2d`).

    The bookkeeping (path, effort, limit violations, clearance, status) is the one
    :class:`~uvnav.sim.ledger.Ledger`'s, the forbidden regions this world's, so both users get
    the same numbers.

    Args:
        setup: the episode.
        rng: the episode generator; two independent children feed the law and the sonar's noise
            and dropout.
    """

    vehicle: ClassVar[str] = "uuv2d"
    sensing: ClassVar[str] = "sonar-fan"

    def __init__(self, setup: Uuv2dSetup, rng: np.random.Generator, *, swept: bool = True) -> None:
        self.setup = setup
        self.swept = swept
        self._law_rng, self.sense_rng = rng.spawn(2)
        self.spec = setup.spec
        self.clock = Clock(setup.dt, setup.control_period, setup.t_max)
        self.dt, self.ratio = self.clock.dt, self.clock.ratio
        self.period = float(setup.control_period)
        self.goal = np.asarray(setup.goal, dtype=float)
        self.state = np.asarray(setup.start, dtype=float).copy()
        self.shapes = setup.shapes
        #: the most a boundary point moves in a step [m] (centre speed plus deformation rate)
        self._body_reach = self.dt * max(
            (float(np.hypot(*s.velocity)) + float(s.max_rate) for s in self.shapes), default=0.0
        )
        self.t = 0.0
        self.done = False

    def law_setup(self, agent: int = 0) -> tuple[HolonomicSpec, FloatArray, np.random.Generator]:
        """The law's limits, goal and generator."""
        return self.spec, self.goal, self._law_rng

    def outlines_at(self, t: float) -> list[FloatArray]:
        """Every obstacle's outline at time ``t`` [s]."""
        return [s.outline(t) for s in self.shapes]

    def start(self, oracles: Sequence[bool] = (False,)) -> None:
        """Outlines, clearance and status at t = 0 (after the law's reset); the sonar is the
        only sensor, oracle or not."""
        state = self.state
        self.outlines = self.outlines_at(0.0)
        self.clearance, _ = clearance_of((state[0], state[1]), self.outlines, self.spec.radius)
        self.entered = inside_any((state[0], state[1]), self.setup.forbidden)
        self.book = Ledger(self.setup.goal_tolerance)
        self.done = self.book.begin(self.clearance, float(np.hypot(*(self.goal - state[:2]))))
        self.applied = HolonomicCommand(0.0, 0.0)
        self.t = 0.0

    def observe(self, agent: int = 0) -> SonarObservation:
        """The sonar sweep now and the vehicle's own state (:class:`SonarObservation`)."""
        t = self.t
        state = self.state
        centres = np.array([s.centre_at(t) for s in self.shapes]).reshape(-1, 2)
        reading = sonar_scan(
            state, self.outlines, self.sense_rng, self.setup.sonar, centres=centres
        )
        return SonarObservation(
            time=t,
            pose=state.copy(),
            velocity=np.array([self.applied.vx, self.applied.vy]),
            goal=self.goal,
            sonar=reading,
            period=self.period,
        )

    def apply(self, cmd: HolonomicCommand, agent: int = 0) -> HolonomicCommand:
        """Hold ``cmd`` from now on: counted in ``limit_violations`` when outside (4.4)-(4.6),
        saturated (:meth:`HolonomicCommand.clipped`); returns what is applied."""
        state = self.state
        period = self.period
        if cmd.violates(self.spec, float(state[2]), period):
            self.book.violations += 1
        new = cmd.clipped(self.spec, float(state[2]), period)
        if self.clock.step_index > 0:
            turn = (
                wrap_scalar(math.atan2(new.vy, new.vx) - float(state[2])) if new.speed > 0 else 0.0
            )
            self.book.effort += (
                turn * turn / period + (new.speed - self.applied.speed) ** 2 / period
            )
        self.applied = new
        return new

    def advance(self) -> None:
        """One integration step ``dt``: vehicle, outlines, clearance, forbidden regions, collision
        and arrival."""
        start, t0, g0 = self.state, self.t, self.clearance
        nxt = holonomic_step(start, self.applied, self.dt)
        step = math.hypot(nxt[0] - start[0], nxt[1] - start[1])
        self.book.path += step
        self.state = state = nxt
        self.t = t = self.clock.tick()
        self.outlines = self.outlines_at(t)
        self.clearance, _ = clearance_of((state[0], state[1]), self.outlines, self.spec.radius)
        self.entered = self.entered or inside_any((state[0], state[1]), self.setup.forbidden)
        contact_at = None
        if self.swept and self.shapes:
            s_hit, least = first_contact(
                lambda s: self._gap_at(start, nxt, t0, s), g0, self.clearance,
                step + self._body_reach,
            )  # fmt: skip
            self.book.min_clear = min(self.book.min_clear, least)
            if not math.isnan(s_hit):
                contact_at = t0 + s_hit * self.dt
        goal = self.goal
        gd = math.hypot(goal[0] - state[0], goal[1] - state[1])
        self.done = self.book.judge(t, self.clearance, gd, contact_at) or self.clock.up

    def _gap_at(self, start: FloatArray, end: FloatArray, t0: float, s: float) -> float:
        """The exact gap [m] at fraction ``s`` of the step from ``start`` (time ``t0``) to
        ``end``: the vehicle on the segment, the outlines of that instant."""
        p = (start[0] + s * (end[0] - start[0]), start[1] + s * (end[1] - start[1]))
        return clearance_of(p, self.outlines_at(t0 + s * self.dt), self.spec.radius)[0]

    def close(self) -> None:
        """Nothing to write back (the outlines are functions of time)."""

    def metrics(self, log: AgentLog, agent: int = 0) -> EpisodeMetrics:
        """The episode's metrics (:mod:`uvnav.sim.metrics`) so far; the time ratio's top speed is
        the box's along the start-goal line (its components are bounded separately)."""
        setup, goal = self.setup, self.goal
        direction = math.atan2(goal[1] - setup.start[1], goal[0] - setup.start[0])
        v_line = self.spec.v_max / max(abs(math.cos(direction)), abs(math.sin(direction)))
        return self.book.metrics(log, top_speed=v_line)

    def recorder(self) -> Uuv2dTrajectoryProbe:
        """The probe that records this world's trajectory."""
        return Uuv2dTrajectoryProbe()

    def flags(self) -> dict[str, bool]:
        """``entered_forbidden``: the vehicle's centre was in a region it may not enter."""
        return {"entered_forbidden": bool(self.entered)}


class Uuv2dTrajectoryProbe(BaseProbe):
    """Records a :class:`Uuv2dWorld`: times, poses and clearances at every integration step and at
    the end; at every decision the outlines, the applied command, the law's mode and the law's own
    record of it (its ``last`` attribute, when it has one); at the end the law's AMAPS grid (its
    ``grid`` attribute, when it has one).  The law's attributes are a trace of its state."""

    def __init__(self) -> None:
        self.times: list[float] = []
        self.poses: list[FloatArray] = []
        self.clears: list[float] = []
        self.d_times: list[float] = []
        self.d_outlines: list[list[FloatArray]] = []
        self.d_cmds: list[tuple[float, float]] = []
        self.d_modes: list[str] = []
        self.d_records: list[Any] = []
        self.goal = np.zeros(2)
        self.grid: Any = None

    def on_decision(self, world: Any, agent: int, law: Any, obs: Any, applied: Any) -> None:
        self.d_times.append(world.t)
        self.d_outlines.append(world.outlines)
        self.d_cmds.append((applied.vx, applied.vy))
        self.d_modes.append(law.mode)
        self.d_records.append(getattr(law, "last", None))

    def on_step(self, world: Any, laws: Sequence[Any]) -> None:
        self.times.append(world.t)
        self.poses.append(world.state.copy())
        self.clears.append(world.clearance)

    def on_end(self, world: Any, laws: Sequence[Any]) -> None:
        self.on_step(world, laws)
        self.goal = world.goal
        self.grid = getattr(laws[0], "grid", None)

    def finish(self) -> Uuv2dTrajectory:
        return Uuv2dTrajectory(
            times=np.asarray(self.times),
            poses=np.asarray(self.poses),
            clearance=np.asarray(self.clears),
            decision_times=np.asarray(self.d_times),
            outlines=self.d_outlines,
            commands=np.asarray(self.d_cmds).reshape(-1, 2),
            modes=self.d_modes,
            decisions=self.d_records,
            goal=self.goal,
            grid=self.grid,
        )
