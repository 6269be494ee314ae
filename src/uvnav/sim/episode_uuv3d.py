"""The Chapter 5 step loop: a 3D vehicle with the nine-sonar array among shape-changing obstacles.

Thesis Chapter 5 (Y. Zhang and J. Zhang, ICCAE 2022): vehicle (5.1)-(5.7), sonar array (5.8),
obstacles with fixed centres whose surfaces deform (§5.2.4).  Same conventions as the 2D loop
(:mod:`uvnav.sim.episode`): the controller is asked every ``control_period`` [s] (a whole multiple
of ``dt``), vehicle and obstacles advance every ``dt`` [s] with the command held (the vehicle's
exact sphere integration, :func:`~uvnav.dynamics.vehicle3d.vehicle3d_advance`), a command outside
the limits is saturated *and* counted in ``limit_violations``, and collisions are checked at every
integration step against the obstacles' tessellations at that time (hull sphere against triangle
meshes, exact for the mesh; the mesh is within ``tessellation_error`` of the analytic surface).
Metrics carry the names of :data:`uvnav.sim.metrics.METRIC_NAMES`.

Scene 2's check that the vehicle never enters an obstacle's inner space is reported separately
(:attr:`UUV3DResult.entered_inner_space`), as is the located-point error when recorded.
"""

from __future__ import annotations

import math
import time as _time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from uvnav.controllers.zhang_uuv3d import SonarObservation3D, ZhangUUV3D
from uvnav.dynamics.vehicle3d import Vehicle3DSpec, vehicle3d_advance
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.mesh3d import nearest_on_mesh
from uvnav.obstacles.deforming3d import CompoundBody
from uvnav.sensors.sonar_array import SonarArray, merge_triangles, sonar_scan
from uvnav.sim.episode import decision_ratio
from uvnav.sim.metrics import EpisodeMetrics, episode_metrics


@dataclass(frozen=True)
class UUV3DSetup:
    """Everything an episode needs.

    Attributes:
        start: A [m], (3,); heading: initial unit heading, (3,); goal: B [m], (3,).
        spec: vehicle limits and hull radius.
        obstacles: the shape-changing obstacles (stars enter as one-part compounds).
        array: the sonar array (its noise/dropout options apply).
        dt: integration step [s]; control_period: decision period [s]; t_max: time limit [s].
        goal_tolerance: distance to B that counts as arrival [m].
    """

    start: FloatArray
    heading: FloatArray
    goal: FloatArray
    spec: Vehicle3DSpec
    obstacles: tuple[CompoundBody, ...]
    array: SonarArray
    dt: float = 0.05
    control_period: float = 0.2
    t_max: float = 90.0
    goal_tolerance: float = 0.5


@dataclass
class UUV3DResult:
    """Outcome of one episode.

    Attributes:
        metrics: the common metrics (DESIGN §4).
        entered_inner_space: the vehicle centre was ever inside an obstacle's inner-space box.
        times, positions, modes: the trajectory at decisions (recorded runs only).
        located: the located point at each decision (NaN when none).
        true_nearest: the true nearest obstacle point at each decision.
        status: ``"success"``, ``"collision"`` or ``"timeout"``.
    """

    metrics: EpisodeMetrics
    entered_inner_space: bool
    status: str
    times: list[float] = field(default_factory=list)
    positions: list[FloatArray] = field(default_factory=list)
    modes: list[str] = field(default_factory=list)
    located: list[FloatArray] = field(default_factory=list)
    true_nearest: list[FloatArray] = field(default_factory=list)


def _nearest(
    position: FloatArray, obstacles: Sequence[CompoundBody], t: float, bound: float
) -> tuple[float, FloatArray | None]:
    """Distance [m] from ``position`` to the nearest obstacle surface (tessellations at ``t``) and
    that point; obstacles whose bounding sphere is farther than ``bound`` are skipped."""
    best, point = math.inf, None
    for ob in obstacles:
        for part in ob.parts:
            if float(np.linalg.norm(position - part.centre)) - part.bounding_radius > min(
                best, bound
            ):
                continue
            q, d, _ = nearest_on_mesh(position, part.triangles(t))
            if d < best:
                best, point = d, q
    return best, point


def run_uuv3d_episode(
    setup: UUV3DSetup,
    controller: ZhangUUV3D,
    rng: np.random.Generator,
    *,
    record: bool = False,
) -> UUV3DResult:
    """Run one episode (module docstring).

    Raises:
        ValueError: ``control_period`` is not a whole multiple of ``dt``.
    """
    spec = setup.spec
    ratio = decision_ratio(setup.control_period, setup.dt)
    pos = np.asarray(setup.start, dtype=float).copy()
    head = np.asarray(setup.heading, dtype=float)
    head = head / np.linalg.norm(head)
    goal = np.asarray(setup.goal, dtype=float)
    controller.reset(spec, goal, rng)
    n_steps = math.ceil(setup.t_max / setup.dt - 1e-9)
    u_held = np.zeros(3)
    v_held = 0.0
    v_prev = 0.0
    effort = 0.0
    path = 0.0
    violations = 0
    switches = 0
    last_mode = controller.mode
    decision_us: list[float] = []
    min_clear = math.inf
    collided = False
    inner = False
    reached_t: float | None = None
    res_times: list[float] = []
    res_pos: list[FloatArray] = []
    res_modes: list[str] = []
    res_loc: list[FloatArray] = []
    res_true: list[FloatArray] = []
    has_obstacles = bool(setup.obstacles)
    for k in range(n_steps + 1):
        t = k * setup.dt
        d, q = _nearest(pos, setup.obstacles, t, math.inf) if has_obstacles else (math.inf, None)
        clear = d - spec.radius
        min_clear = min(min_clear, clear)
        if clear < 0:
            collided = True
        if any(bool(ob.in_inner_space(pos[None])[0]) for ob in setup.obstacles):
            inner = True
        if float(np.linalg.norm(goal - pos)) <= setup.goal_tolerance:
            reached_t = t
        if collided or reached_t is not None or k == n_steps:
            break
        if k % ratio == 0:
            tri = merge_triangles([p.triangles(t) for ob in setup.obstacles for p in ob.parts])
            scan = sonar_scan(setup.array, pos, head, tri, rng)
            obs = SonarObservation3D(
                time=t,
                position=pos.copy(),
                heading=head.copy(),
                speed=v_held,
                goal=goal,
                ranges=scan.ranges,
                echo=scan.echo,
                array=setup.array,
                truth_point=None if (q is None or not controller.oracle) else q.copy(),
            )
            tic = _time.perf_counter()
            cmd = controller.act(obs)
            decision_us.append((_time.perf_counter() - tic) * 1e6)
            if cmd.violates(spec, head):
                violations += 1
            cmd = cmd.clipped(spec, head)
            v_held, u_held = float(cmd.v), np.asarray(cmd.u, dtype=float)
            if controller.mode != last_mode:
                switches += 1
                last_mode = controller.mode
            if record:
                res_times.append(t)
                res_pos.append(pos.copy())
                res_modes.append(controller.mode)
                loc = controller.last_located
                res_loc.append(loc.point.copy() if loc is not None else np.full(3, np.nan))
                res_true.append(q.copy() if q is not None else np.full(3, np.nan))
        effort += float(u_held @ u_held) * setup.dt
        if k % ratio == 0:
            effort += ((v_held - v_prev) / setup.control_period) ** 2 * setup.control_period
            v_prev = v_held
        new_pos, head, u_held = vehicle3d_advance(pos, head, v_held, u_held, setup.dt)
        path += float(np.linalg.norm(new_pos - pos))
        pos = new_pos
    if record:
        res_times.append(k * setup.dt)
        res_pos.append(pos.copy())
        res_modes.append(controller.mode)
        res_loc.append(np.full(3, np.nan))
        res_true.append(np.full(3, np.nan))
    success = reached_t is not None and not collided
    straight = max(
        float(np.linalg.norm(goal - np.asarray(setup.start, float))) - setup.goal_tolerance, 1e-9
    )
    status = "success" if success else ("collision" if collided else "timeout")
    metrics = episode_metrics(
        status=status,
        path_length=path,
        shortest=straight,
        straight_time=straight / spec.v_max,
        reached_at=reached_t if success else None,
        min_clearance=float(min_clear) if has_obstacles and math.isfinite(min_clear) else None,
        control_effort=effort,
        limit_violations=violations,
        mode_switches=switches,
        decision_us=decision_us,
    )
    return UUV3DResult(
        metrics=metrics,
        entered_inner_space=inner,
        status=status,
        times=res_times,
        positions=res_pos,
        modes=res_modes,
        located=res_loc,
        true_nearest=res_true,
    )
