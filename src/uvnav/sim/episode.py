"""The 2D step loop: sensing, decisions, exact integration, collision checks, metrics (DESIGN §2,
§4).

Decision rate and integration rate are separate: the controller is asked every ``control_period``
[s] (a whole multiple of ``dt``, else :func:`run_episode` raises ``ValueError``); robot and
obstacles are integrated every ``dt`` [s] with the last command held.  Collisions are checked at
*every* integration step, exactly (robot disc against disc or polygon sets, see
:meth:`uvnav.obstacles.ObstacleField.query`; the kernel is property-tested against shapely).

The simulator clips nothing silently: a command outside the limits (2.4) is saturated to what the
vehicle can physically do *and* counted in ``limit_violations``.

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
import time as _time
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from uvnav.controllers.base import Controller
from uvnav.dynamics.unicycle import UnicycleCommand, UnicycleSpec, unicycle_advance
from uvnav.geometry.angles import FloatArray
from uvnav.obstacles.batch import ObstacleBatch
from uvnav.obstacles.obstacle import FieldTemplate, Obstacle, ObstacleField
from uvnav.prediction.finite_difference import FiniteDifferenceEstimator
from uvnav.sensors.exact import lidar_scan, sense_obstacles
from uvnav.sensors.observation import Observation
from uvnav.sim.metrics import EpisodeMetrics, episode_metrics
from uvnav.sim.recorder import Trajectory, TrajectoryRecorder


@dataclass(frozen=True)
class LidarConfig:
    """Lidar on the robot: ``n_rays`` beams over ``fov`` [rad], ``max_range`` [m], noise [m]."""

    n_rays: int = 72
    max_range: float = 5.0
    fov: float = 2.0 * np.pi
    noise_std: float = 0.0
    dropout: float = 0.0


@dataclass(frozen=True)
class SensingConfig:
    """How observations are made.

    Attributes:
        sensing_range: obstacles farther than this [m] are not reported.
        velocities: ``"known"`` gives true v_i, u_i (the thesis's assumption); ``"estimated"``
            gives finite differences of the sensed centre and outline
            (:class:`FiniteDifferenceEstimator`).
        position_noise: std [m] of the noise on the observed centre when estimating.
        lidar: optional range scanner.
    """

    sensing_range: float = 5.0
    velocities: Literal["known", "estimated"] = "known"
    position_noise: float = 0.0
    lidar: LidarConfig | None = None


@dataclass
class EpisodeSetup:
    """A fully instantiated episode (what a scenario builds for one seed).

    Attributes:
        spec: robot limits and radius.
        start: initial pose ``[x, y, theta]``.
        goal: target T [m].
        obstacles: obstacles with their episode-specific motion models.
        dt: integration step [s].
        control_period: decision period [s], a whole multiple of ``dt`` (within 1e-9 relative).
        t_max: time limit [s].
        goal_tolerance: the goal is reached within this distance [m].
        sensing: sensing configuration.
    """

    spec: UnicycleSpec
    start: FloatArray
    goal: FloatArray
    obstacles: list[Obstacle]
    dt: float = 0.1
    control_period: float = 0.1
    t_max: float = 60.0
    goal_tolerance: float = 0.2
    sensing: SensingConfig = field(default_factory=SensingConfig)


@dataclass
class EpisodeResult:
    """Metrics, status (``success``, ``collision`` or ``timeout``) and the recorded trajectory."""

    metrics: EpisodeMetrics
    status: str
    trajectory: Trajectory | None
    decision_us: FloatArray


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


def decision_ratio(control_period: float, dt: float) -> int:
    """Integration steps per decision: ``control_period / dt`` as a whole number >= 1.

    Raises:
        ValueError: ``control_period`` is not a positive whole multiple of ``dt`` within 1e-9
            relative (the same rule as the scenario schema).
    """
    if not (dt > 0 and math.isfinite(dt)):
        raise ValueError(f"dt must be a positive number of seconds (got {dt!r})")
    ratio = control_period / dt
    n = round(ratio) if math.isfinite(ratio) else 0
    if n < 1 or abs(ratio - n) > 1e-9 * max(1.0, ratio):
        raise ValueError(
            f"control_period must be a positive multiple of dt={dt:g} s (got {control_period:g})"
        )
    return int(n)


def run_episode(
    setup: EpisodeSetup,
    controller: Controller,
    rng: np.random.Generator,
    *,
    record: bool = True,
) -> EpisodeResult:
    """Run one episode to success, collision or ``t_max``.

    Args:
        setup: the instantiated scenario; its obstacles' states (and their motion models' internal
            state) are left as they are at the end of the episode.
        controller: a fresh or reusable controller; it is reset here.
        rng: the episode generator; independent children feed the controller and the sensors.
        record: keep the full trajectory (needed for figures; off for large campaigns).

    Raises:
        ValueError: ``setup.control_period`` is not a whole multiple of ``setup.dt``.
    """
    ctrl_rng, sense_rng = rng.spawn(2)
    spec = setup.spec
    dt = float(setup.dt)
    ratio = decision_ratio(float(setup.control_period), dt)
    n_steps = round(setup.t_max / dt)
    goal = np.asarray(setup.goal, dtype=float)
    gx, gy = float(goal[0]), float(goal[1])
    start = np.asarray(setup.start, dtype=float)
    x, y, th = float(start[0]), float(start[1]), float(start[2])
    obstacles = setup.obstacles
    template = FieldTemplate.from_bodies([o.body for o in obstacles])
    batch = ObstacleBatch(obstacles)
    field_now = batch.field(template)
    sensing = setup.sensing
    sensing_range = float(sensing.sensing_range)
    robot_radius = float(spec.radius)
    goal_tolerance = float(setup.goal_tolerance)
    estimator = None
    if sensing.velocities == "estimated" and not getattr(controller, "oracle", False):
        estimator = FiniteDifferenceEstimator(sense_rng, sensing.position_noise)

    controller.reset(spec, goal, ctrl_rng)
    recorder = TrajectoryRecorder([o.body.outline() for o in obstacles]) if record else None
    has_obstacles = len(obstacles) > 0

    def clearance_of(
        fld: ObstacleField, px: float, py: float, radius: float, with_nearest: bool
    ) -> tuple[float, int]:
        """Gap [m] between the robot's disc and the nearest obstacle (negative on overlap), and
        that obstacle; the query also covers ``radius`` [m] for the sensors.  Without
        ``with_nearest`` only obstacles within ``radius`` are examined: ``(inf, -1)`` if none."""
        if not has_obstacles:
            return math.inf, -1
        q = fld.query((px, py), radius, nearest=with_nearest)
        if len(q.ids) == 0:
            return math.inf, -1
        gaps = q.signed - robot_radius
        j = int(gaps.argmin())
        return float(gaps[j]), int(q.ids[j])

    clearance, nearest = clearance_of(field_now, x, y, sensing_range, True)
    min_clear = clearance
    # unrecorded, only the minimum clearance and collisions are visible: defer what can wait
    tracker = _MinClearance(robot_radius, clearance) if has_obstacles and not record else None
    start_dist = math.hypot(gx - x, gy - y)
    path = 0.0
    effort = 0.0
    violations = 0
    switches = 0
    decision_us: list[float] = []
    applied = UnicycleCommand(0.0, 0.0)
    last_mode: str | None = None
    status = "timeout"
    t = 0.0
    reached_at: float | None = None
    if clearance < 0:
        status = "collision"
        n_steps = 0
    elif start_dist <= goal_tolerance:
        status, reached_at, n_steps = "success", 0.0, 0

    perf_ns = _time.perf_counter_ns
    try:
        for i in range(n_steps):
            if i % ratio == 0:
                robot = np.array((x, y, th))
                readings = sense_obstacles(robot[:2], field_now, sensing_range=sensing_range)
                if estimator is not None:
                    readings = estimator.update(t, readings)
                scan = None
                if sensing.lidar is not None:
                    lc = sensing.lidar
                    scan = lidar_scan(
                        robot,
                        field_now,
                        sense_rng,
                        n_rays=lc.n_rays,
                        max_range=lc.max_range,
                        fov=lc.fov,
                        noise_std=lc.noise_std,
                        dropout=lc.dropout,
                    )
                obs = Observation(
                    time=t,
                    pose=robot,
                    speed=applied.v,
                    goal=goal,
                    obstacles=readings,
                    lidar=scan,
                )
                tic = perf_ns()
                cmd = controller.act(obs)
                decision_us.append((perf_ns() - tic) / 1000.0)
                if cmd.violates(spec):
                    violations += 1
                new = cmd.clipped(spec)
                effort += ((new.v - applied.v) ** 2) / (ratio * dt) if i > 0 else 0.0
                applied = new
                mode = controller.mode
                if last_mode is not None and mode != last_mode:
                    switches += 1
                last_mode = mode
            if recorder is not None:
                recorder.add(
                    t,
                    np.array((x, y, th)),
                    (applied.v, applied.u),
                    last_mode or "",
                    clearance,
                    nearest,
                    field_now,
                )
            effort += applied.u**2 * dt
            nx, ny, th = unicycle_advance(x, y, th, applied.v, applied.u, dt)
            path += math.hypot(nx - x, ny - y)
            x, y = nx, ny
            batch.step(t, dt)
            t = (i + 1) * dt
            field_now = batch.field(template)
            radius = sensing_range if (i + 1) % ratio == 0 else 0.0
            if recorder is not None or tracker is None:
                clearance, nearest = clearance_of(field_now, x, y, radius, True)
                min_clear = min(min_clear, clearance)
            else:
                clearance = tracker.step(field_now, x, y, radius)
            if clearance < 0:
                status = "collision"
                break
            if math.hypot(gx - x, gy - y) <= goal_tolerance:
                status = "success"
                reached_at = t
                break
    finally:
        batch.write_back()
    if tracker is not None:
        min_clear = tracker.finish()

    if recorder is not None:
        recorder.add(
            t,
            np.array((x, y, th)),
            (applied.v, applied.u),
            last_mode or "",
            clearance,
            nearest,
            field_now,
        )
    dec = np.asarray(decision_us) if decision_us else np.zeros(1)
    shortest = max(start_dist - goal_tolerance, 0.0)  # to the edge of the goal disc
    metrics = episode_metrics(
        status=status,
        path_length=path,
        shortest=shortest,
        straight_time=shortest / spec.v_max if spec.v_max > 0 else 0.0,
        reached_at=reached_at,
        min_clearance=float(min_clear) if has_obstacles else None,
        control_effort=effort,
        limit_violations=violations,
        mode_switches=switches,
        decision_us=decision_us,
    )
    return EpisodeResult(
        metrics=metrics,
        status=status,
        trajectory=recorder.finish() if recorder is not None else None,
        decision_us=dec,
    )
