"""The stepping world behind the Gymnasium and PettingZoo environments (no gymnasium import).

:class:`NavWorld` advances N unicycle robots (N = 1 for ``uvnav/Nav2D-v0``) and the scenario's
obstacles one *decision* at a time: each call to :meth:`NavWorld.step` holds every robot's
command for ``control_period`` [s] and integrates with ``dt`` [s], checking collisions at every
integration step exactly as :func:`uvnav.sim.run_episode` does (robots are discs; a robot sees
the other robots as moving discs, as in :mod:`uvnav.sim.multi`).

Observation vector of a robot (float32, documented in :data:`OBS_DOC`):

====================  ==========================================================  =========
index                 what                                                         range
====================  ==========================================================  =========
0                     distance to goal / ``goal_scale``, clipped                   [0, 1]
1, 2                  cos, sin of the goal bearing in the robot frame              [-1, 1]
3                     current speed / V_max                                        [0, 1]
4 ..                  lidar ranges / max_range (``n_rays`` beams, robot frame,     [0, 1]
                      first beam straight behind, counter-clockwise)
====================  ==========================================================  =========

Action (float32, in [-1, 1]^2): ``v = (a0 + 1) / 2 * V_max``, ``u = a1 * U_max`` (inside the
limits (2.4) by construction, so no limit is ever violated).

Reward per decision (weights in :class:`RewardConfig`): ``progress`` x (decrease of the distance
to the goal [m]) ``- time`` ``- clearance`` x max(0, ``clearance_margin`` - clearance [m]) ``+
success`` on arrival ``- collision`` on a collision.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from uvnav.dynamics.unicycle import UnicycleCommand, UnicycleSpec, unicycle_advance
from uvnav.geometry.angles import FloatArray
from uvnav.obstacles.batch import ObstacleBatch
from uvnav.obstacles.bodies import Body, DiscBody
from uvnav.obstacles.obstacle import FieldTemplate, Obstacle, ObstacleField
from uvnav.sensors.exact import lidar_scan, sense_obstacles
from uvnav.sensors.observation import Observation
from uvnav.sim.episode import SensingConfig, decision_ratio

OBS_DOC = (
    "[goal distance / goal_scale, cos(goal bearing), sin(goal bearing), speed / v_max, "
    "lidar ranges / max_range x n_rays]"
)


@dataclass(frozen=True)
class RewardConfig:
    """Reward weights (see the module docstring).

    Attributes:
        progress: per metre of progress toward the goal.
        time: per decision (a small penalty for dawdling).
        clearance: per metre below ``clearance_margin``.
        clearance_margin: clearance [m] under which the clearance penalty applies.
        success: on arrival.
        collision: on a collision (subtracted).
    """

    progress: float = 1.0
    time: float = 0.01
    clearance: float = 0.5
    clearance_margin: float = 0.3
    success: float = 10.0
    collision: float = 10.0

    def reward(self, progress: float, clearance: float, status: str) -> float:
        """One decision's reward: ``progress`` [m] toward the goal, the ``clearance`` [m] over the
        decision, and the episode status after it (``"success"``/``"collision"`` end it)."""
        r = self.progress * progress - self.time
        r -= self.clearance * max(0.0, self.clearance_margin - clearance)
        if status == "success":
            r += self.success
        elif status == "collision":
            r -= self.collision
        return r


@dataclass
class WorldRobot:
    """One robot: limits, start pose, goal, sensing."""

    spec: UnicycleSpec
    start: FloatArray
    goal: FloatArray
    sensing: SensingConfig = field(default_factory=SensingConfig)


@dataclass(frozen=True, eq=False)
class ControllerView:
    """What a uvnav controller would be given at this decision: its
    :class:`~uvnav.sensors.Observation` and its vehicle limits (``info["uvnav"]`` of the envs).

    Equality compares the contents (numpy arrays element-wise), so Gymnasium's determinism
    checks can compare infos.
    """

    observation: Observation
    spec: UnicycleSpec

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, ControllerView):
            return NotImplemented
        a, b = self.observation, other.observation
        if self.spec != other.spec or a.time != b.time or a.speed != b.speed:
            return False
        if not (np.array_equal(a.pose, b.pose) and np.array_equal(a.goal, b.goal)):
            return False
        if len(a.obstacles) != len(b.obstacles):
            return False
        return all(
            ra.obstacle_id == rb.obstacle_id
            and ra.distance == rb.distance
            and np.array_equal(ra.centre, rb.centre)
            and np.array_equal(ra.velocity, rb.velocity)
            for ra, rb in zip(a.obstacles, b.obstacles, strict=True)
        )

    __hash__ = None  # type: ignore[assignment]


class NavWorld:
    """N robots and the obstacles, advanced one decision at a time (module docstring).

    Args:
        robots: the robots.
        obstacles: fresh obstacles for this episode (advanced in place).
        dt: integration step [s].
        control_period: decision period [s].
        goal_tolerance: arrival radius [m].
        n_rays: lidar beams in the observation vector.
        max_range: lidar range [m].
        goal_scale: distance [m] mapped to 1 in the observation.
        reward: reward weights.
    """

    def __init__(
        self,
        robots: list[WorldRobot],
        obstacles: list[Obstacle],
        *,
        dt: float,
        control_period: float,
        goal_tolerance: float,
        n_rays: int = 32,
        max_range: float = 5.0,
        goal_scale: float = 20.0,
        reward: RewardConfig | None = None,
    ) -> None:
        self.robots = robots
        self.obstacles = obstacles
        self.dt = float(dt)
        self.ratio = decision_ratio(float(control_period), self.dt)
        self.tol = float(goal_tolerance)
        self.n_rays = int(n_rays)
        self.max_range = float(max_range)
        self.goal_scale = float(goal_scale)
        self.reward = reward or RewardConfig()
        n = len(robots)
        self.k = len(obstacles)
        bodies: list[Body] = [o.body for o in obstacles]
        bodies += [DiscBody(max(float(r.spec.radius), 1e-6)) for r in robots]
        self.template = FieldTemplate.from_bodies(bodies)
        self.batch = ObstacleBatch(obstacles)
        self.state = np.array([np.asarray(r.start, dtype=float)[:3] for r in robots])
        self.goals = np.array([np.asarray(r.goal, dtype=float)[:2] for r in robots])
        self.radii = np.array([float(r.spec.radius) for r in robots])
        self.speeds = np.zeros(n)
        self.turns = np.zeros(n)
        self.active = np.ones(n, dtype=bool)
        self.status = ["running"] * n
        self.t = 0.0
        self.field = self._field()
        self.clearance = np.array([self._clearance(i) for i in range(n)])
        for i in range(n):
            if self.clearance[i] < 0:
                self.status[i] = "collision"
                self.active[i] = False
            elif self.distance(i) <= self.tol:
                self.status[i] = "success"
                self.active[i] = False

    @property
    def n(self) -> int:
        return len(self.robots)

    def obs_size(self) -> int:
        return 4 + self.n_rays

    def distance(self, i: int) -> float:
        return float(math.hypot(*(self.goals[i] - self.state[i, :2])))

    def _field(self) -> ObstacleField:
        vel = np.column_stack(
            (self.speeds * np.cos(self.state[:, 2]), self.speeds * np.sin(self.state[:, 2]))
        )
        vel[~self.active] = 0.0
        omega = np.where(self.active, self.turns, 0.0)
        if self.k:
            b = self.batch
            return self.template.field(
                np.vstack((b.positions, self.state[:, :2])),
                np.concatenate((b.headings, self.state[:, 2])),
                np.vstack((b.velocities, vel)),
                np.concatenate((b.angular_velocities, omega)),
            )
        return self.template.field(self.state[:, :2].copy(), self.state[:, 2].copy(), vel, omega)

    def _clearance(self, i: int) -> float:
        """Gap [m] from robot i's disc to the nearest obstacle or other robot (``max_range`` when
        nothing is within ``max_range``)."""
        q = self.field.query(
            self.state[i, :2], self.max_range + self.radii.max() * 2, nearest=False
        )
        keep = q.ids != self.k + i
        if not keep.any() or self.n == 0:
            return self.max_range
        return float((q.signed[keep] - self.radii[i]).min())

    def observation(self, i: int) -> Observation:
        """What robot i's sensors give (the uvnav controller contract), other robots included."""
        r = self.robots[i]
        pose = self.state[i].copy()
        readings = sense_obstacles(pose[:2], self.field, sensing_range=r.sensing.sensing_range)
        readings = tuple(rd for rd in readings if rd.obstacle_id != self.k + i)
        return Observation(
            time=self.t,
            pose=pose,
            speed=float(self.speeds[i]),
            goal=self.goals[i].copy(),
            obstacles=readings,
        )

    def view(self, i: int) -> ControllerView:
        """Robot i's :class:`ControllerView` (observation and limits)."""
        return ControllerView(self.observation(i), self.robots[i].spec)

    def vector(self, i: int) -> np.ndarray:
        """Robot i's observation vector (module docstring), float32."""
        _x, _y, th = self.state[i]
        gap = self.goals[i] - self.state[i, :2]
        dist = float(math.hypot(*gap))
        bearing = math.atan2(gap[1], gap[0]) - th
        scan = lidar_scan(
            self.state[i], self._field_without(i), n_rays=self.n_rays, max_range=self.max_range
        )
        out = np.empty(self.obs_size(), dtype=np.float32)
        out[0] = min(dist / self.goal_scale, 1.0)
        out[1] = math.cos(bearing)
        out[2] = math.sin(bearing)
        out[3] = min(max(self.speeds[i] / self.robots[i].spec.v_max, 0.0), 1.0)
        out[4:] = np.clip(scan.ranges / self.max_range, 0.0, 1.0)
        return out

    def _field_without(self, i: int) -> ObstacleField:
        if self.n == 1:
            return self._obstacles_only()
        return self._drop(self.k + i)

    def _obstacles_only(self) -> ObstacleField:
        # the robot's own disc must not block its own lidar: a field of the obstacles only
        if not hasattr(self, "_tpl_obs"):
            self._tpl_obs = FieldTemplate.from_bodies([o.body for o in self.obstacles])
        b = self.batch
        return self._tpl_obs.field(b.positions, b.headings, b.velocities, b.angular_velocities)

    def _drop(self, j: int) -> ObstacleField:
        if not hasattr(self, "_drop_cache"):
            self._drop_cache: dict[int, tuple[FieldTemplate, np.ndarray]] = {}
        if j not in self._drop_cache:
            bodies: list[Body] = [o.body for o in self.obstacles]
            bodies += [DiscBody(max(float(r.spec.radius), 1e-6)) for r in self.robots]
            idx = np.array([m for m in range(len(bodies)) if m != j], dtype=int)
            self._drop_cache[j] = (FieldTemplate.from_bodies([bodies[m] for m in idx]), idx)
        tpl, keep = self._drop_cache[j]
        f = self.field
        return tpl.field(
            f.centres[keep], f.headings[keep], f.velocities[keep], f.angular_velocities[keep]
        )

    def command(self, i: int, action: np.ndarray) -> UnicycleCommand:
        """The unicycle command of a normalised action in [-1, 1]^2 (clipped)."""
        a = np.clip(np.asarray(action, dtype=float).reshape(2), -1.0, 1.0)
        a = np.where(np.isfinite(a), a, 0.0)
        spec = self.robots[i].spec
        return UnicycleCommand(0.5 * (a[0] + 1.0) * spec.v_max, a[1] * spec.u_max)

    def step(self, actions: dict[int, np.ndarray]) -> np.ndarray:
        """Hold the robots' commands for one decision period; returns the rewards (0 for robots
        that were already done)."""
        n = self.n
        rw = self.reward
        before = np.array([self.distance(i) for i in range(n)])
        was_active = self.active.copy()
        cmds = {i: self.command(i, actions[i]) for i in range(n) if self.active[i] and i in actions}
        for i in range(n):
            if self.active[i]:
                c = cmds.get(i, UnicycleCommand(0.0, 0.0))
                self.speeds[i], self.turns[i] = c.v, c.u
        min_clear = np.full(n, np.inf)
        for _ in range(self.ratio):
            if not self.active.any():
                break
            for i in range(n):
                if not self.active[i]:
                    self.speeds[i] = self.turns[i] = 0.0
                    continue
                x, y, th = self.state[i]
                self.state[i] = unicycle_advance(
                    float(x),
                    float(y),
                    float(th),
                    float(self.speeds[i]),
                    float(self.turns[i]),
                    self.dt,
                )
            self.batch.step(self.t, self.dt)
            self.t += self.dt
            self.field = self._field()
            for i in range(n):
                if not self.active[i]:
                    continue
                gap = self._clearance(i)
                min_clear[i] = min(min_clear[i], gap)
                if gap < 0:
                    self.status[i] = "collision"
                elif self.distance(i) <= self.tol:
                    self.status[i] = "success"
            for i in range(n):
                if self.active[i] and self.status[i] != "running":
                    self.active[i] = False
                    self.speeds[i] = self.turns[i] = 0.0
        self.field = self._field()
        rewards = np.zeros(n)
        for i in range(n):
            if not was_active[i]:
                continue
            self.clearance[i] = min_clear[i] if np.isfinite(min_clear[i]) else self.clearance[i]
            rewards[i] = rw.reward(
                before[i] - self.distance(i), float(self.clearance[i]), self.status[i]
            )
        return rewards

    def close(self) -> None:
        self.batch.write_back()


def scene_bounds(world: NavWorld, margin: float = 1.5) -> tuple[float, float, float, float]:
    """A box [m] around the robots' starts and goals and the obstacles' initial bounding discs
    (pedestrians parked far away are left out), grown by ``margin``."""
    pts = [world.state[:, :2], world.goals]
    if world.k:
        c = world.batch.positions
        rad = world.template.bounding_radii[: world.k]
        near = np.hypot(*(c - world.state[0, :2]).T) < 100.0
        if near.any():
            pts += [c[near] - rad[near, None], c[near] + rad[near, None]]
    allp = np.vstack(pts)
    lo = allp.min(axis=0) - margin
    hi = allp.max(axis=0) + margin
    side = float(max(hi - lo))
    mid = 0.5 * (lo + hi)
    return (mid[0] - side / 2, mid[1] - side / 2, mid[0] + side / 2, mid[1] + side / 2)


ROBOT_COLOURS = np.array(
    [
        [31, 119, 180],
        [214, 39, 40],
        [44, 160, 44],
        [148, 103, 189],
        [255, 127, 14],
        [140, 86, 75],
        [227, 119, 194],
        [23, 190, 207],
    ],
    dtype=np.uint8,
)


def render_frame(
    world: NavWorld, bounds: tuple[float, float, float, float], size: int = 256
) -> np.ndarray:
    """An RGB frame (size, size, 3) uint8 of the world: obstacles grey, robots coloured discs,
    goals coloured squares; y up.  Pure numpy + shapely (no plotting library)."""
    import shapely

    xmin, ymin, xmax, ymax = bounds
    img = np.full((size, size, 3), 255, dtype=np.uint8)
    xs = xmin + (np.arange(size) + 0.5) * (xmax - xmin) / size
    ys = ymax - (np.arange(size) + 0.5) * (ymax - ymin) / size
    gx, gy = np.meshgrid(xs, ys)
    f = world.field
    for j in range(world.k):
        c = f.centres[j]
        r = float(f.bounding_radii[j])
        if c[0] + r < xmin or c[0] - r > xmax or c[1] + r < ymin or c[1] - r > ymax:
            continue
        poly = f.polygons[j]
        if poly is None:
            mask = np.hypot(gx - c[0], gy - c[1]) <= float(f.radii[j])
        else:
            mask = shapely.contains_xy(shapely.Polygon(poly), gx, gy)
        img[mask] = (120, 120, 120)
    px = (xmax - xmin) / size
    for i in range(world.n):
        col = ROBOT_COLOURS[i % len(ROBOT_COLOURS)]
        g = world.goals[i]
        img[(np.abs(gx - g[0]) <= 2.5 * px) & (np.abs(gy - g[1]) <= 2.5 * px)] = col
        x, y, th = world.state[i]
        rad = max(float(world.radii[i]), 2.0 * px)
        img[np.hypot(gx - x, gy - y) <= rad] = col
        tip = np.hypot(gx - (x + rad * math.cos(th)), gy - (y + rad * math.sin(th))) <= 1.5 * px
        img[tip] = (0, 0, 0)
    return img
