"""The 2D step loop: sensing, decisions, exact integration, collision checks, metrics (DESIGN §2, §4).

Decision rate and integration rate are separate: the controller is asked every ``control_period``
[s]; robot and obstacles are integrated every ``dt`` [s] with the last command held.  Collisions are
checked at *every* integration step, exactly (robot disc against disc or polygon sets, see
:meth:`uvnav.obstacles.ObstacleField.nearest`; the kernel is property-tested against shapely).

The simulator clips nothing silently: a command outside the limits (2.4) is saturated to what the
vehicle can physically do *and* counted in ``limit_violations``.
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from uvnav.controllers.base import Controller
from uvnav.dynamics.unicycle import UnicycleCommand, UnicycleSpec, unicycle_step
from uvnav.geometry.angles import FloatArray
from uvnav.obstacles.obstacle import FieldTemplate, Obstacle, ObstacleField
from uvnav.prediction.finite_difference import FiniteDifferenceEstimator
from uvnav.sensors.exact import lidar_scan, sense_obstacles
from uvnav.sensors.observation import Observation
from uvnav.sim.metrics import EpisodeMetrics
from uvnav.sim.recorder import Trajectory, TrajectoryRecorder


@dataclass(frozen=True)
class LidarConfig:
    """Lidar attached to the robot: ``n_rays`` beams over ``fov`` [rad], ``max_range`` [m], noise [m]."""

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
        velocities: ``"known"`` gives true v_i, u_i (the thesis's assumption); ``"estimated"`` gives
            finite differences of the sensed centre and outline (:class:`FiniteDifferenceEstimator`).
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
        control_period: decision period [s] (a multiple of ``dt``).
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


def run_episode(
    setup: EpisodeSetup,
    controller: Controller,
    rng: np.random.Generator,
    *,
    record: bool = True,
) -> EpisodeResult:
    """Run one episode to success, collision or ``t_max``.

    Args:
        setup: the instantiated scenario (obstacles are advanced in place).
        controller: a fresh or reusable controller; it is reset here.
        rng: the episode generator; independent children feed the controller and the sensors.
        record: keep the full trajectory (needed for figures; off for large campaigns).
    """
    ctrl_rng, sense_rng = rng.spawn(2)
    spec = setup.spec
    dt = float(setup.dt)
    ratio = max(1, round(setup.control_period / dt))
    n_steps = round(setup.t_max / dt)
    goal = np.asarray(setup.goal, dtype=float)
    robot = np.asarray(setup.start, dtype=float).copy()
    obstacles = setup.obstacles
    template = FieldTemplate.from_bodies([o.body for o in obstacles])
    field_now = ObstacleField.from_obstacles(obstacles, template)
    sensing = setup.sensing
    estimator = None
    if sensing.velocities == "estimated" and not getattr(controller, "oracle", False):
        estimator = FiniteDifferenceEstimator(sense_rng, sensing.position_noise)

    controller.reset(spec, goal, ctrl_rng)
    recorder = TrajectoryRecorder([o.body.outline() for o in obstacles]) if record else None

    def clearance_of(fld: ObstacleField, pos: FloatArray) -> tuple[float, int]:
        if len(fld) == 0:
            return np.inf, -1
        d, near, inside = fld.nearest(pos)
        depth = np.hypot(near[:, 0] - pos[0], near[:, 1] - pos[1])
        gaps = np.where(inside, -depth, d) - spec.radius
        j = int(np.argmin(gaps))
        return float(gaps[j]), j

    clearance, nearest = clearance_of(field_now, robot[:2])
    min_clear = clearance
    start_dist = float(np.hypot(*(goal - robot[:2])))
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
    elif start_dist <= setup.goal_tolerance:
        status, reached_at, n_steps = "success", 0.0, 0

    for i in range(n_steps):
        if i % ratio == 0:
            readings = sense_obstacles(robot[:2], field_now, sensing_range=sensing.sensing_range)
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
                pose=robot.copy(),
                speed=applied.v,
                goal=goal,
                obstacles=readings,
                lidar=scan,
            )
            tic = _time.perf_counter_ns()
            cmd = controller.act(obs)
            decision_us.append((_time.perf_counter_ns() - tic) / 1000.0)
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
                robot.copy(),
                (applied.v, applied.u),
                last_mode or "",
                clearance,
                nearest,
                field_now.centres,
                field_now.headings,
                field_now.velocities,
                field_now.angular_velocities,
            )
        effort += applied.u**2 * dt
        new_robot = unicycle_step(robot, applied.v, applied.u, dt)
        path += float(np.hypot(*(new_robot[:2] - robot[:2])))
        robot = new_robot
        for ob in obstacles:
            ob.state = ob.motion.step(ob.state, t, dt)
        t = (i + 1) * dt
        field_now = ObstacleField.from_obstacles(obstacles, template)
        clearance, nearest = clearance_of(field_now, robot[:2])
        min_clear = min(min_clear, clearance)
        if clearance < 0:
            status = "collision"
            break
        if float(np.hypot(*(goal - robot[:2]))) <= setup.goal_tolerance:
            status = "success"
            reached_at = t
            break

    if recorder is not None:
        recorder.add(
            t,
            robot.copy(),
            (applied.v, applied.u),
            last_mode or "",
            clearance,
            nearest,
            field_now.centres,
            field_now.headings,
            field_now.velocities,
            field_now.angular_velocities,
        )
    dec = np.asarray(decision_us) if decision_us else np.zeros(1)
    success = status == "success"
    shortest = max(start_dist - setup.goal_tolerance, 0.0)  # to the edge of the goal disc
    straight_time = shortest / spec.v_max if spec.v_max > 0 else 0.0
    metrics = EpisodeMetrics(
        success=success,
        collision=status == "collision",
        min_clearance=float(min_clear) if np.isfinite(min_clear) else 1e9,
        path_length=path,
        detour_ratio=(path / shortest) if success and shortest > 0 else None,
        time_to_goal=reached_at,
        time_ratio=(reached_at / straight_time)
        if (reached_at is not None and straight_time > 0)
        else None,
        control_effort=float(effort),
        limit_violations=violations,
        mode_switches=switches,
        decision_us_median=float(np.median(dec)),
        decision_us_p99=float(np.percentile(dec, 99)),
    )
    return EpisodeResult(
        metrics=metrics,
        status=status,
        trajectory=recorder.finish() if recorder is not None else None,
        decision_us=dec,
    )
