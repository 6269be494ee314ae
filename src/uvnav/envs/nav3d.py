"""``uvnav/Nav3D-v0``: a Gymnasium environment on the 3D world of the thesis's Chapter 3.

One flying robot (the vehicle (3.1)-(3.6) of :mod:`uvnav.dynamics.vehicle3d`) among a Chapter-3
scene's moving, rotating 3D obstacles.  The env steps the simulator's own world
(:class:`uvnav.sim.episode3d.Vehicle3DWorld`, the one
:func:`~uvnav.sim.run.run_episode` runs): one env step is one decision
(``control_period``), integrated exactly with the scene's ``dt``, with the exact clearance
checked at every integration step.

**Sensing.**  The observation is built only from what the robot's sensor returns
(:func:`uvnav.sensors.sensing3d.sense_obstacles3d`, thesis (3.8): for each obstacle within
``sensing_range`` its nearest point r_min and distance d_min) and from the robot's own state.  The
obstacles' rates are finite differences of what is sensed
(:class:`~uvnav.sensors.sensing3d.FiniteDifference3D`) unless ``oracle=True`` is asked for, which
gives their true rates (ground truth; the thesis's "known motion" case).

Body frame: e1 = the heading a_R, e2 = (z x a_R) / ||z x a_R|| (to the left; y x a_R when the
heading is vertical), e3 = e1 x e2 (up).

* **Observation** ``Box(5 + 8 n_obstacles,)`` float32:

  ====================  =====================================================  =========
  index                 what                                                   range
  ====================  =====================================================  =========
  0                     distance to goal / ``goal_scale``, clipped             [0, 1]
  1, 2, 3               unit direction to the goal in the body frame           [-1, 1]
  4                     speed / V_max                                          [0, 1]
  5 + 8 j ..            slot j (the j-th nearest sensed obstacle):
  + 0                   1 when the slot holds an obstacle, else 0 (all zeros)  [0, 1]
  + 1                   d_min / sensing_range                                  [0, 1]
  + 2, 3, 4             unit direction to r_min in the body frame              [-1, 1]
  + 5, 6, 7             obstacle velocity in the body frame / V_max, clipped   [-1, 1]
  ====================  =====================================================  =========

* **Action** ``Box([-1, -1, -1], [1, 1, 1])`` float32: ``V_R = (a0 + 1) / 2 V_max`` and the turn
  vector ``u_R = U_max (a1 e3 - a2 e2)`` (a1 > 0 turns left, a2 > 0 climbs), scaled down to
  ``||u_R|| <= U_max`` when ``a1^2 + a2^2 > 1``; orthogonal to a_R and within (3.4)-(3.6) by
  construction.
* **Reward**: :class:`uvnav.envs.core.RewardConfig` (progress, time, clearance, success,
  collision), configurable with ``reward={...}``; the clearance term uses the smallest exact
  clearance over the decision.
* **Termination**: arrival or collision; **truncation** at the scene's ``t_max``.
* ``info``: ``status`` (``running``, ``success``, ``collision``, ``timeout``), ``distance`` [m],
  ``clearance`` [m], ``time`` [s] and ``uvnav`` (a :class:`~uvnav.envs.common.SimView`: the
  :class:`~uvnav.sensors.sensing3d.Observation3D` a Chapter-3 law is given, the limits, and the
  inverse action map used by :func:`uvnav.envs.as_policy`).
* ``render_mode="rgb_array"``: 256 x 512 RGB frames, top view (x-y) left and side view (x-z)
  right; obstacles are drawn as the convex hull of their projected vertices.

``scenario`` is a Chapter-3 scene (``thesis-ch3-*``, ``random-ch3:<seed>``, a YAML file or a
:class:`~uvnav.scenarios.schema3d.Scenario3D`) or ``"random-ch3"``: a fresh random scene every
episode.  Each ``reset(seed=...)`` draws an episode seed from the env's generator; the scene's
random motions (AR obstacles) and the sensing noise are drawn from it, so the same seed gives the
same episode.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from uvnav.dynamics.vehicle3d import Vehicle3DCommand
from uvnav.envs.common import SimView, VehicleWorldEnv, fill_polygon
from uvnav.envs.core import (
    ROBOT_COLOURS,
    RewardConfig,
    checked_count,
    goal_scale_for,
    pixel_grid,
    square_bounds,
)
from uvnav.sensors.sensing3d import Observation3D
from uvnav.sim.episode3d import Vehicle3DWorld

try:
    from gymnasium import spaces
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise ImportError("uvnav.envs needs gymnasium: pip install 'uvnav[envs]'") from exc

SLOT = 8  # values per obstacle slot
#: most obstacle slots of the observation vector (``n_obstacles``)
MAX_OBSTACLE_SLOTS = 100


def body_frame(heading: np.ndarray) -> np.ndarray:
    """Rows e1 (the unit heading), e2 (left) and e3 (up) of the body frame (module docstring)."""
    a = np.asarray(heading, dtype=float)
    side = np.cross([0.0, 0.0, 1.0], a)
    n = float(np.linalg.norm(side))
    if n < 1e-9:  # vertical heading
        side = np.cross([0.0, 1.0, 0.0], a)
        n = float(np.linalg.norm(side))
    e2 = side / n
    return np.array([a, e2, np.cross(a, e2)])


def command_of(
    action: np.ndarray, heading: np.ndarray, v_max: float, u_max: float
) -> Vehicle3DCommand:
    """The vehicle command of a normalised action (module docstring); the env
    refuses a non-finite action before (:func:`~uvnav.envs.core.checked_actions`), a direct
    caller's non-finite entries are 0."""
    a = np.asarray(action, dtype=float).reshape(3)
    a = np.clip(np.where(np.isfinite(a), a, 0.0), -1.0, 1.0)
    frame = body_frame(heading)
    w = np.array([a[1], a[2]])
    n = float(np.hypot(w[0], w[1]))
    if n > 1.0:
        w = w / n
    u = u_max * (w[0] * frame[2] - w[1] * frame[1])
    return Vehicle3DCommand(0.5 * (a[0] + 1.0) * v_max, u)


def action_of(cmd: Vehicle3DCommand, heading: np.ndarray, v_max: float, u_max: float) -> np.ndarray:
    """The normalised action of a command already within the limits (the inverse of
    :func:`command_of`), float32."""
    frame = body_frame(heading)
    u = np.asarray(cmd.u, dtype=float)
    act = np.array(
        [2.0 * cmd.v / v_max - 1.0, float(u @ frame[2]) / u_max, -float(u @ frame[1]) / u_max]
    )
    return np.clip(act, -1.0, 1.0).astype(np.float32)


def observation_vector(
    obs: Observation3D,
    *,
    v_max: float,
    goal_scale: float,
    sensing_range: float,
    n_obstacles: int,
) -> np.ndarray:
    """The flat observation (module docstring) of an :class:`Observation3D`, float32."""
    frame = body_frame(obs.heading)
    out = np.zeros(5 + SLOT * n_obstacles, dtype=np.float32)
    gap = np.asarray(obs.goal, dtype=float) - obs.position
    dist = float(np.linalg.norm(gap))
    out[0] = min(dist / goal_scale, 1.0)
    if dist > 0:
        out[1:4] = frame @ (gap / dist)
    out[4] = min(max(obs.speed / v_max, 0.0), 1.0)
    for j, rd in enumerate(obs.obstacles[:n_obstacles]):
        base = 5 + SLOT * j
        out[base] = 1.0
        out[base + 1] = min(rd.distance / sensing_range, 1.0)
        d = rd.nearest_point - obs.position
        nd = float(np.linalg.norm(d))
        if nd > 0:
            out[base + 2 : base + 5] = np.clip(frame @ (d / nd), -1.0, 1.0)
        out[base + 5 : base + 8] = np.clip(frame @ rd.velocity / v_max, -1.0, 1.0)
    return out


class Nav3DEnv(VehicleWorldEnv):
    """``uvnav/Nav3D-v0`` (module docstring).

    Args:
        scenario: a Chapter-3 scene (name, ``random-ch3:<seed>``, YAML path or
            :class:`~uvnav.scenarios.schema3d.Scenario3D`), or ``"random-ch3"`` for a new random
            scene every episode.
        render_mode: ``None`` or ``"rgb_array"``.
        n_obstacles: obstacle slots in the observation (the nearest sensed ones).
        oracle: give the obstacles' true rates (ground truth) instead of estimating them.
        goal_scale: distance [m] mapped to 1 (default: 1.5 x the start-goal distance).
        reward: reward weights (:class:`RewardConfig` or a dict of its fields).
    """

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "render_fps": 10}  # noqa: RUF012 - gymnasium declares it an instance variable
    _world: Vehicle3DWorld | None
    _obs: Observation3D | None

    def __init__(
        self,
        scenario: Any = "thesis-ch3-fig3-6-whole-manoeuvre",
        *,
        render_mode: str | None = None,
        n_obstacles: int = 4,
        oracle: bool = False,
        goal_scale: float | None = None,
        reward: RewardConfig | dict[str, float] | None = None,
    ) -> None:
        from uvnav.scenarios import load_scenario
        from uvnav.scenarios.generators3d import random_ch3_scenario
        from uvnav.scenarios.schema3d import Scenario3D

        def load(scenario: Any) -> Scenario3D:
            sc = scenario if isinstance(scenario, Scenario3D) else load_scenario(scenario)
            if not isinstance(sc, Scenario3D):
                raise ValueError(f"{scenario!r} is not a Chapter-3 (dim: 3) scene")
            return sc

        checked_count("n_obstacles", n_obstacles, 1, MAX_OBSTACLE_SLOTS)
        first = self._configure(
            scenario, {"random-ch3": random_ch3_scenario}, load, render_mode, reward
        )
        self.n_obstacles = int(n_obstacles)
        self.oracle = bool(oracle)
        r = first.robot
        dist = float(np.linalg.norm(np.subtract(r.goal, r.start)))
        self.goal_scale = goal_scale_for(dist, goal_scale)
        low = np.zeros(5 + SLOT * self.n_obstacles, dtype=np.float32)
        low[1:4] = -1.0
        for j in range(self.n_obstacles):
            low[5 + SLOT * j + 2 : 5 + SLOT * j + 8] = -1.0
        self.observation_space = spaces.Box(low=low, high=np.ones_like(low), dtype=np.float32)
        self.action_space = spaces.Box(low=-1.0, high=1.0, shape=(3,), dtype=np.float32)

    # ------------------------------------------------------------------------------ helpers
    def _new_world(self, scene: Any, episode_seed: int) -> Vehicle3DWorld:
        velocities = "known" if self.oracle else "estimated"
        setup = scene.build(episode_seed, velocities=velocities)
        world = Vehicle3DWorld(setup, np.random.default_rng(episode_seed), exact=True)
        world.start([self.oracle])
        return world

    def _command(self, action: np.ndarray) -> Vehicle3DCommand:
        world = self._world
        assert world is not None
        return command_of(action, world.a, world.spec.v_max, world.spec.u_max)

    def _distance(self) -> float:
        assert self._world is not None
        return float(np.linalg.norm(self._world.goal - self._world.pos))

    def _vector(self) -> np.ndarray:
        world, obs = self._world, self._obs
        assert world is not None and obs is not None
        return observation_vector(
            obs,
            v_max=world.spec.v_max,
            goal_scale=self.goal_scale,
            sensing_range=world.sensing_range,
            n_obstacles=self.n_obstacles,
        )

    def _info(self) -> dict[str, Any]:
        world, obs = self._world, self._obs
        assert world is not None and obs is not None
        spec, heading = world.spec, obs.heading.copy()

        def to_action(cmd: Vehicle3DCommand) -> np.ndarray:
            return action_of(cmd.clipped(spec, heading), heading, spec.v_max, spec.u_max)

        return {
            "status": world.status if world.done else "running",
            "distance": self._distance(),
            "clearance": float(self._clearance),
            "time": world.t,
            "uvnav": SimView(obs, spec, to_action),
        }

    def render(self) -> np.ndarray | None:
        if self.render_mode != "rgb_array" or self._world is None:
            return None
        return render_frame3d(self._world)


def render_frame3d(world: Vehicle3DWorld, size: int = 256) -> np.ndarray:
    """A (size, 2 size, 3) uint8 frame: top view (x-y) left, side view (x-z) right; obstacles
    grey (convex hull of their projected vertices), the robot a coloured disc with its path's
    goal as a square."""
    import shapely

    img = np.full((size, 2 * size, 3), 255, dtype=np.uint8)
    start = np.asarray(world.setup.start, dtype=float)
    pts = [start[None, :], world.goal[None, :], world.pos[None, :]]
    outlines = [ob.world_outline() for ob in world.obstacles]
    pts += outlines
    allp = np.vstack(pts)
    col = ROBOT_COLOURS[0]
    for panel, axes in enumerate(((0, 1), (0, 2))):
        bounds = square_bounds(allp[:, axes], 1.0)
        gx, gy = pixel_grid(bounds, size, size)
        view = img[:, panel * size : (panel + 1) * size]
        for ol in outlines:
            hull = shapely.MultiPoint(ol[:, axes]).convex_hull
            if hull.geom_type == "Polygon":
                fill_polygon(view, np.asarray(hull.exterior.coords), (120, 120, 120), gx, gy)
        px = (bounds[2] - bounds[0]) / size
        g = world.goal[list(axes)]
        view[(np.abs(gx - g[0]) <= 2.5 * px) & (np.abs(gy - g[1]) <= 2.5 * px)] = col
        p = world.pos[list(axes)]
        rad = max(float(world.spec.radius), 2.0 * px)
        view[np.hypot(gx - p[0], gy - p[1]) <= rad] = col
        tip = p + rad * world.a[list(axes)]
        view[np.hypot(gx - tip[0], gy - tip[1]) <= 1.5 * px] = (0, 0, 0)
    img[:, size - 1 : size + 1] = 0
    return img
