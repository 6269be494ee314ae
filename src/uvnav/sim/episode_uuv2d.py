"""The Chapter-4 step loop: a planar UUV among shape-changing obstacles, sensed by sonar only.

Same structure and metrics as :mod:`uvnav.sim.episode` (DESIGN §2, §4; the names of
:data:`~uvnav.sim.metrics.METRIC_NAMES`), for the vehicle of :mod:`uvnav.dynamics.holonomic` and
the bodies of :mod:`uvnav.obstacles.deforming`, whose outlines change every step (the unicycle
loop's rigid-body field cannot hold them):

* every ``control_period`` [s] (a whole multiple of ``dt``) the sonar sweeps the viewing cone
  and the law is asked for a velocity; a command outside the limits (4.4)-(4.6) is counted in
  ``limit_violations`` and saturated (:meth:`HolonomicCommand.clipped`), never silently;
* every ``dt`` the vehicle moves exactly (constant velocity) and the collision check is exact:
  signed distance from the vehicle's centre to every outline at that instant
  (:func:`~uvnav.geometry.polygons.rings_nearest` with the even-odd test), minus its radius;
* ``forbidden`` regions (the inner space of a Fig. 4.2(b) trap) are checked each step too: the
  result says whether the vehicle's centre ever entered one.

``control_effort`` is the analogue of the unicycle's: integral of the turn rate squared
(direction change per decision / T) plus integral of (dV/dt)^2.
"""

from __future__ import annotations

import math
import time as _time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from uvnav.dynamics.holonomic import HolonomicCommand, HolonomicSpec, holonomic_step
from uvnav.geometry.angles import FloatArray, wrap_scalar
from uvnav.geometry.polygons import closed_rings, rings_nearest
from uvnav.obstacles.deforming import ShapeChanging
from uvnav.sensors.sonar2d import SonarConfig, SonarObservation, sonar_scan
from uvnav.sim.episode import decision_ratio
from uvnav.sim.metrics import EpisodeMetrics, episode_metrics


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


@dataclass
class Uuv2dResult:
    """Metrics, status (``success``, ``collision`` or ``timeout``), whether a forbidden region was
    entered, and the recorded trajectory."""

    metrics: EpisodeMetrics
    status: str
    entered_forbidden: bool
    trajectory: Uuv2dTrajectory | None
    decision_us: FloatArray


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


def run_uuv2d_episode(
    setup: Uuv2dSetup,
    controller: Any,
    rng: np.random.Generator,
    *,
    record: bool = True,
) -> Uuv2dResult:
    """Run one episode to success, collision or ``t_max``.

    Args:
        setup: the instantiated scene.
        controller: a Chapter-4 law (:class:`~uvnav.controllers.zhang2022_uuv2d.Uuv2dController`);
            it is reset here.
        rng: the episode generator; independent children feed the controller and the sonar.
        record: keep the trajectory (for figures).
    """
    ctrl_rng, sense_rng = rng.spawn(2)
    spec = setup.spec
    dt = float(setup.dt)
    period = float(setup.control_period)
    ratio = decision_ratio(period, dt)
    n_steps = round(setup.t_max / dt)
    goal = np.asarray(setup.goal, dtype=float)
    state = np.asarray(setup.start, dtype=float).copy()
    shapes = setup.shapes
    controller.reset(spec, goal, ctrl_rng)

    def outlines_at(t: float) -> list[FloatArray]:
        return [s.outline(t) for s in shapes]

    outlines = outlines_at(0.0)
    clear, _ = clearance_of((state[0], state[1]), outlines, spec.radius)
    min_clear = clear
    entered = inside_any((state[0], state[1]), setup.forbidden)
    start_dist = float(np.hypot(*(goal - state[:2])))
    status = "timeout"
    if clear < 0:
        status, n_steps = "collision", 0
    elif start_dist <= setup.goal_tolerance:
        status, n_steps = "success", 0
    path = 0.0
    effort = 0.0
    violations = 0
    switches = 0
    last_mode: str | None = None
    applied = HolonomicCommand(0.0, 0.0)
    decision_us: list[float] = []
    reached: float | None = None
    t = 0.0
    times = [0.0]
    poses = [state.copy()]
    clears = [clear]
    d_times: list[float] = []
    d_outlines: list[list[FloatArray]] = []
    d_cmds: list[tuple[float, float]] = []
    d_modes: list[str] = []
    d_records: list[Any] = []
    perf = _time.perf_counter_ns
    for i in range(n_steps):
        if i % ratio == 0:
            centres = np.array([s.centre_at(t) for s in shapes]).reshape(-1, 2)
            reading = sonar_scan(state, outlines, sense_rng, setup.sonar, centres=centres)
            obs = SonarObservation(
                time=t,
                pose=state.copy(),
                velocity=np.array([applied.vx, applied.vy]),
                goal=goal,
                sonar=reading,
                period=period,
            )
            tic = perf()
            cmd = controller.act(obs)
            decision_us.append((perf() - tic) / 1000.0)
            if cmd.violates(spec, float(state[2]), period):
                violations += 1
            new = cmd.clipped(spec, float(state[2]), period)
            if i > 0:
                turn = (
                    wrap_scalar(math.atan2(new.vy, new.vx) - float(state[2]))
                    if new.speed > 0
                    else 0.0
                )
                effort += turn * turn / period + (new.speed - applied.speed) ** 2 / period
            applied = new
            mode = controller.mode
            if last_mode is not None and mode != last_mode:
                switches += 1
            last_mode = mode
            if record:
                d_times.append(t)
                d_outlines.append(outlines)
                d_cmds.append((applied.vx, applied.vy))
                d_modes.append(mode)
                d_records.append(getattr(controller, "last", None))
        nxt = holonomic_step(state, applied, dt)
        path += math.hypot(nxt[0] - state[0], nxt[1] - state[1])
        state = nxt
        t = (i + 1) * dt
        outlines = outlines_at(t)
        clear, _ = clearance_of((state[0], state[1]), outlines, spec.radius)
        min_clear = min(min_clear, clear)
        entered = entered or inside_any((state[0], state[1]), setup.forbidden)
        if record:
            times.append(t)
            poses.append(state.copy())
            clears.append(clear)
        if clear < 0:
            status = "collision"
            break
        if math.hypot(goal[0] - state[0], goal[1] - state[1]) <= setup.goal_tolerance:
            status, reached = "success", t
            break
    dec = np.asarray(decision_us) if decision_us else np.zeros(1)
    shortest = max(start_dist - setup.goal_tolerance, 0.0)
    # the fastest straight run: along the start->goal direction at the box's speed there
    direction = math.atan2(goal[1] - setup.start[1], goal[0] - setup.start[0])
    v_line = spec.v_max / max(abs(math.cos(direction)), abs(math.sin(direction)))
    metrics = episode_metrics(
        status=status,
        path_length=path,
        shortest=shortest,
        straight_time=shortest / v_line if v_line > 0 else 0.0,
        reached_at=reached,
        min_clearance=float(min_clear) if shapes else None,
        control_effort=effort,
        limit_violations=violations,
        mode_switches=switches,
        decision_us=decision_us,
    )
    traj = None
    if record:
        traj = Uuv2dTrajectory(
            times=np.asarray(times),
            poses=np.asarray(poses),
            clearance=np.asarray(clears),
            decision_times=np.asarray(d_times),
            outlines=d_outlines,
            commands=np.asarray(d_cmds).reshape(-1, 2),
            modes=d_modes,
            decisions=d_records,
            goal=goal,
            grid=getattr(controller, "grid", None),
        )
    return Uuv2dResult(
        metrics=metrics,
        status=status,
        entered_forbidden=entered,
        trajectory=traj,
        decision_us=dec,
    )
