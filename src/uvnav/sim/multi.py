"""Several robots in one world: each with its own goal, law and sensing, each seeing the others
as moving obstacles (issue 9; thesis Ch. 8's "next step": robots as a networked system, each
avoiding the others).

Every robot is a unicycle (thesis (2.1)-(2.4)) with a disc body.  At a decision time robot i
senses, with its own :class:`~uvnav.sim.SensingConfig`, the world's obstacles *and the other
robots* — each other robot is a disc obstacle (its radius) whose observed motion is its current
velocity ``V_R [cos theta, sin theta]`` (``velocities="known"``) or, with ``"estimated"``
sensing, the finite-difference estimate of robot i's own
:class:`~uvnav.prediction.FiniteDifferenceEstimator`.  The robots do not communicate: nothing
else passes between them.  Obstacle ids in the observations are the world's obstacles first
(0..k-1), then the robots (k + j).

Integration, collision checks and the per-robot metrics follow :func:`uvnav.sim.run_episode`
(same names, :data:`uvnav.sim.metrics.METRIC_NAMES`): the robot's clearance is the gap to the
nearest obstacle *or other robot*.  A robot that reaches its goal stops there and stays in the
world as a parked disc (it is physically there); a robot that collides stops where it is (a
wreck, also still there); its own metrics stop there, as a single-robot episode's do.  The
episode ends when every robot has arrived or collided, or at ``t_max``.

Group metrics (:class:`GroupMetrics`): ``all_arrived``, ``robot_collisions`` (pairs of robots
whose discs ever overlapped), ``obstacle_collisions`` (robots that hit a world obstacle),
``makespan`` [s] (arrival time of the last robot when all arrived, else ``None``), ``deadlocks``
(robots neither arrived nor collided at the end that moved less than ``deadlock_distance`` [m]
over the last ``deadlock_window`` [s]: stuck, not merely slow), ``arrived`` (count) and
``sum_of_times`` [s] (sum of arrival times when all arrived).

Speed: when the world holds only the robots (no world obstacles: the antipodal swap, crossing
flows), the collision checks and the sensing of all robots are computed at once per step
(:class:`_DiscPairs`, (N, N) arrays) instead of one :meth:`ObstacleField.query` per robot — the
same element-wise arithmetic as the field's disc kernel, so the results are identical (tested
against the per-robot path, ``vectorised=False``).
"""

from __future__ import annotations

import math
import time as _time
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from uvnav.controllers.base import Controller
from uvnav.dynamics.unicycle import UnicycleCommand, UnicycleSpec, unicycle_advance
from uvnav.geometry.angles import FloatArray
from uvnav.obstacles.batch import ObstacleBatch
from uvnav.obstacles.bodies import Body, DiscBody
from uvnav.obstacles.obstacle import (
    _CULL_ABS,
    _CULL_REL,
    _X_AXIS,
    FieldTemplate,
    Obstacle,
    ObstacleField,
)
from uvnav.prediction.finite_difference import FiniteDifferenceEstimator
from uvnav.sensors.exact import sense_obstacles
from uvnav.sensors.observation import Observation, ObstacleReading
from uvnav.sim.episode import SensingConfig, decision_ratio
from uvnav.sim.metrics import EpisodeMetrics, episode_metrics

_NO_OUTLINE = np.zeros((0, 2))  # a disc's outline in a reading (as sense_obstacles gives it)

GROUP_METRIC_NAMES: tuple[str, ...] = (
    "all_arrived",
    "arrived",
    "robot_collisions",
    "obstacle_collisions",
    "makespan",
    "sum_of_times",
    "deadlocks",
)


@dataclass
class RobotSetup:
    """One robot of a multi-robot episode.

    Attributes:
        spec: limits and radius.
        start: initial pose ``[x, y, theta]`` ([m], [m], [rad]).
        goal: target [m], shape (2,).
        controller: its navigation law (reset at the start of the episode).
        sensing: its sensing configuration.
        name: label.
    """

    spec: UnicycleSpec
    start: FloatArray
    goal: FloatArray
    controller: Controller
    sensing: SensingConfig = field(default_factory=SensingConfig)
    name: str = ""


@dataclass
class MultiSetup:
    """A fully instantiated multi-robot episode.

    Attributes:
        robots: the robots.
        obstacles: the world's (non-robot) obstacles.
        dt: integration step [s].
        control_period: decision period [s] (a whole multiple of ``dt``).
        t_max: time limit [s].
        goal_tolerance: arrival radius [m].
        deadlock_window: the window of the deadlock test [s].
        deadlock_distance: a robot that moved less than this [m] over the window is stuck.
    """

    robots: list[RobotSetup]
    obstacles: list[Obstacle] = field(default_factory=list)
    dt: float = 0.1
    control_period: float = 0.1
    t_max: float = 60.0
    goal_tolerance: float = 0.2
    deadlock_window: float = 10.0
    deadlock_distance: float = 0.2


@dataclass(frozen=True)
class GroupMetrics:
    """Outcome of the group (see the module docstring)."""

    all_arrived: bool
    arrived: int
    robot_collisions: int
    obstacle_collisions: int
    makespan: float | None
    sum_of_times: float | None
    deadlocks: int

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass
class MultiResult:
    """Per-robot metrics and statuses, group metrics, and the recorded robot trajectories.

    Attributes:
        robots: per-robot :class:`EpisodeMetrics` (same names as single-robot episodes).
        statuses: per robot ``success``, ``collision`` or ``timeout``.
        group: the group metrics.
        times: (n,) sample times [s] (empty when not recorded).
        poses: (n, N, 3) robot poses (empty when not recorded).
        collided_pairs: the robot index pairs that overlapped.
    """

    robots: list[EpisodeMetrics]
    statuses: list[str]
    group: GroupMetrics
    times: FloatArray
    poses: FloatArray
    collided_pairs: list[tuple[int, int]]


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


def run_multi(
    setup: MultiSetup,
    rng: np.random.Generator,
    *,
    record: bool = True,
    vectorised: bool = True,
) -> MultiResult:
    """Run one multi-robot episode (see the module docstring).

    Args:
        setup: the instantiated scene; its obstacles are advanced in place.
        rng: episode generator; each robot gets independent children for its law and sensors.
        record: keep every robot's pose at every integration step (figures).
        vectorised: check and sense all robots at once when the world holds only robots
            (identical results; ``False`` forces one field query per robot).

    Raises:
        ValueError: ``control_period`` is not a whole multiple of ``dt``, or no robot.
    """
    robots = setup.robots
    n = len(robots)
    if n == 0:
        raise ValueError("a multi-robot episode needs at least one robot")
    dt = float(setup.dt)
    ratio = decision_ratio(float(setup.control_period), dt)
    n_steps = round(setup.t_max / dt)
    tol = float(setup.goal_tolerance)
    children = rng.spawn(2 * n)
    k = len(setup.obstacles)
    bodies: list[Body] = [o.body for o in setup.obstacles]
    bodies += [DiscBody(max(float(r.spec.radius), 1e-6)) for r in robots]
    template = FieldTemplate.from_bodies(bodies)
    batch = ObstacleBatch(setup.obstacles)
    radii = np.array([float(r.spec.radius) for r in robots])
    reach = [max(float(r.sensing.sensing_range), 4.0 * float(radii.max()) + 1.0) for r in robots]
    state = np.array([np.asarray(r.start, dtype=float)[:3] for r in robots])
    goals = np.array([np.asarray(r.goal, dtype=float)[:2] for r in robots])
    speeds = np.zeros(n)
    turns = np.zeros(n)
    active = np.ones(n, dtype=bool)  # neither arrived nor collided
    status = ["timeout"] * n
    reached: list[float | None] = [None] * n
    estimators: list[FiniteDifferenceEstimator | None] = []
    for i, r in enumerate(robots):
        r.controller.reset(r.spec, goals[i], children[2 * i])
        est = None
        if r.sensing.velocities == "estimated" and not getattr(r.controller, "oracle", False):
            est = FiniteDifferenceEstimator(children[2 * i + 1], r.sensing.position_noise)
        estimators.append(est)
    start_dist = np.hypot(*(goals - state[:, :2]).T)
    path = np.zeros(n)
    effort = np.zeros(n)
    violations = np.zeros(n, dtype=int)
    switches = np.zeros(n, dtype=int)
    last_mode: list[str | None] = [None] * n
    decision_us: list[list[float]] = [[] for _ in range(n)]
    min_clear = np.full(n, np.inf)
    pairs: set[tuple[int, int]] = set()
    obstacle_hits = 0
    times: list[float] = []
    poses: list[FloatArray] = []
    window = max(1, round(setup.deadlock_window / dt))
    history: list[FloatArray] = []
    perf_ns = _time.perf_counter_ns

    def world(t_batch: ObstacleBatch) -> ObstacleField:
        vel = np.array([_robot_velocity(speeds[i], state[i, 2]) for i in range(n)])
        vel[~active] = 0.0
        centres = np.vstack((t_batch.positions, state[:, :2])) if k else state[:, :2].copy()
        headings = np.concatenate((t_batch.headings, state[:, 2])) if k else state[:, 2].copy()
        velocities = np.vstack((t_batch.velocities, vel)) if k else vel
        omegas = np.concatenate((t_batch.angular_velocities, np.where(active, turns, 0.0)))
        if not k:
            omegas = np.where(active, turns, 0.0)
        return template.field(centres, headings, velocities, omegas)

    batched = vectorised and k == 0
    reach_arr = np.array(reach)
    pairs_now: list[_DiscPairs | None] = [None]

    def check(fld: ObstacleField) -> None:
        """Clearances, collisions and arrivals after a step (or at t = 0)."""
        nonlocal obstacle_hits
        if batched:
            dp = _DiscPairs(fld, state[:, :2], reach_arr)
            pairs_now[0] = dp
            keep = dp.within & active[:, None]
            np.fill_diagonal(keep, False)
            gaps = dp.signed - radii[:, None]
            seen = keep.any(axis=1)
            low = np.where(keep, gaps, np.inf).min(axis=1)
            min_clear[seen] = np.minimum(min_clear[seen], low[seen])
            hit_i, hit_j = np.nonzero(keep & (gaps < 0))
            for i, j in zip(hit_i.tolist(), hit_j.tolist(), strict=True):
                pairs.add((min(i, j), max(i, j)))
                status[i] = "collision"
            for i in range(n):
                if status[i] == "collision":
                    active[i] = False
            return
        for i in range(n):
            if not active[i]:
                continue  # an arrived or wrecked robot's episode is over (as in run_episode)
            # the own disc is always nearest: ask for everything within the sensing range instead
            # (clearances beyond it are not tracked: min_clearance is exact when below it)
            q = fld.query(state[i, :2], reach[i], nearest=False)
            ids = q.ids
            gaps = q.signed - radii[i]
            own = ids == k + i
            gaps = gaps[~own]
            ids = ids[~own]
            if len(gaps) == 0:
                continue
            min_clear[i] = min(min_clear[i], float(gaps.min()))
            hit = gaps < 0
            if hit.any():
                for j in ids[hit]:
                    j = int(j)
                    if j >= k:
                        pairs.add((min(i, j - k), max(i, j - k)))
                    else:
                        obstacle_hits += 1
                status[i] = "collision"
        for i in range(n):
            if status[i] == "collision":
                active[i] = False

    fld = world(batch)
    check(fld)
    for i in range(n):
        if active[i] and start_dist[i] <= tol:
            status[i], reached[i], active[i] = "success", 0.0, False
    t = 0.0
    applied = [UnicycleCommand(0.0, 0.0) for _ in range(n)]
    try:
        for step in range(n_steps):
            if not active.any():
                break
            if step % ratio == 0:
                for i in range(n):
                    if not active[i]:
                        continue
                    r = robots[i]
                    pose = state[i].copy()
                    dp = pairs_now[0]
                    if dp is not None:
                        readings = dp.readings(i, fld, float(r.sensing.sensing_range))
                    else:
                        readings = sense_obstacles(
                            pose[:2], fld, sensing_range=float(r.sensing.sensing_range)
                        )
                        readings = tuple(rd for rd in readings if rd.obstacle_id != k + i)
                    est = estimators[i]
                    if est is not None:
                        readings = est.update(t, readings)
                    obs = Observation(
                        time=t, pose=pose, speed=applied[i].v, goal=goals[i], obstacles=readings
                    )
                    tic = perf_ns()
                    cmd = r.controller.act(obs)
                    decision_us[i].append((perf_ns() - tic) / 1000.0)
                    if cmd.violates(r.spec):
                        violations[i] += 1
                    new = cmd.clipped(r.spec)
                    effort[i] += ((new.v - applied[i].v) ** 2) / (ratio * dt) if step > 0 else 0.0
                    applied[i] = new
                    mode = r.controller.mode
                    if last_mode[i] is not None and mode != last_mode[i]:
                        switches[i] += 1
                    last_mode[i] = mode
            if record:
                times.append(t)
                poses.append(state.copy())
            history.append(state[:, :2].copy())
            if len(history) > window + 1:
                history.pop(0)
            for i in range(n):
                if not active[i]:
                    speeds[i] = turns[i] = 0.0
                    continue
                v, u = applied[i].v, applied[i].u
                effort[i] += u * u * dt
                x, y, th = state[i]
                nx, ny, nth = unicycle_advance(float(x), float(y), float(th), v, u, dt)
                path[i] += math.hypot(nx - x, ny - y)
                state[i] = (nx, ny, nth)
                speeds[i], turns[i] = v, u
            batch.step(t, dt)
            t = (step + 1) * dt
            fld = world(batch)
            check(fld)
            for i in range(n):
                if active[i] and math.hypot(*(goals[i] - state[i, :2])) <= tol:
                    status[i], reached[i], active[i] = "success", t, False
    finally:
        batch.write_back()
    if record:
        times.append(t)
        poses.append(state.copy())
    history.append(state[:, :2].copy())

    per_robot = []
    for i, r in enumerate(robots):
        shortest = max(float(start_dist[i]) - tol, 0.0)
        per_robot.append(
            episode_metrics(
                status=status[i],
                path_length=float(path[i]),
                shortest=shortest,
                straight_time=shortest / r.spec.v_max if r.spec.v_max > 0 else 0.0,
                reached_at=reached[i],
                min_clearance=float(min_clear[i]) if math.isfinite(min_clear[i]) else None,
                control_effort=float(effort[i]),
                limit_violations=int(violations[i]),
                mode_switches=int(switches[i]),
                decision_us=decision_us[i],
            )
        )
    arrived = sum(s == "success" for s in status)
    all_arrived = arrived == n
    arrival_times = [a for a in reached if a is not None]
    moved = np.hypot(*(history[-1] - history[0]).T)
    stuck = sum(
        1
        for i in range(n)
        if status[i] == "timeout"
        and t >= setup.deadlock_window
        and moved[i] < setup.deadlock_distance
    )
    group = GroupMetrics(
        all_arrived=all_arrived,
        arrived=int(arrived),
        robot_collisions=len(pairs),
        obstacle_collisions=int(obstacle_hits),
        makespan=max(arrival_times) if all_arrived else None,
        sum_of_times=float(sum(arrival_times)) if all_arrived else None,
        deadlocks=int(stuck),
    )
    return MultiResult(
        robots=per_robot,
        statuses=status,
        group=group,
        times=np.asarray(times),
        poses=np.asarray(poses) if poses else np.zeros((0, n, 3)),
        collided_pairs=sorted(pairs),
    )


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
