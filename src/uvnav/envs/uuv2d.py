"""``uvnav/UUV2D-v0``: a Gymnasium environment on the UUV world of the thesis's Chapter 4.

One planar UUV (the vehicle (4.1)-(4.6) of :mod:`uvnav.dynamics.holonomic`: a world-frame
velocity, each component bounded by V_max, its direction turning at most U_max per second) among
a Chapter-4 scene's shape-changing obstacles, sensed by the viewing-cone sonar of §4.2
(:func:`uvnav.sensors.sonar2d.sonar_scan`).  The env steps the simulator's own world
(:class:`uvnav.sim.episode_uuv2d.Uuv2dWorld`, the one
:func:`~uvnav.sim.run.run_episode` runs): one env step is one decision
(``control_period``), integrated with the scene's ``dt``, with the exact clearance to the
outlines of that instant checked at every integration step.

**Sensing.**  The observation is the sonar sweep (ranges along the beams of the viewing cone,
centred on the vehicle's orientation) and the vehicle's own state; nothing else of the world.

* **Observation** ``Box(4 + n_beams,)`` float32:

  ====================  =====================================================  =========
  index                 what                                                   range
  ====================  =====================================================  =========
  0                     distance to goal / ``goal_scale``, clipped             [0, 1]
  1, 2                  cos, sin of the goal bearing relative to the           [-1, 1]
                        orientation theta
  3                     speed / (sqrt(2) V_max)                                [0, 1]
  4 ..                  sonar ranges / max_range, beams in increasing angle    [0, 1]
                        across the cone; 1 for no return *and* for a dropout
  ====================  =====================================================  =========

* **Action** ``Box([-1, -1], [1, 1])`` float32: the velocity's direction is
  ``theta + a1 U_max T`` (T the decision period) and its speed
  ``(a0 + 1) / 2`` times the largest speed the box (4.4)-(4.5) allows along it; within
  (4.4)-(4.6) by construction.
* **Reward**: :class:`uvnav.envs.core.RewardConfig` (progress, time, clearance, success,
  collision), configurable with ``reward={...}``; the clearance term uses the smallest clearance
  over the decision.
* **Termination**: arrival or collision; **truncation** at the scene's ``t_max``.
* ``info``: ``status`` (``running``, ``success``, ``collision``, ``timeout``), ``distance`` [m],
  ``clearance`` [m], ``time`` [s], ``entered_forbidden`` (the vehicle's centre was in a trap's
  inner space) and ``uvnav`` (a :class:`~uvnav.envs.common.SimView`: the
  :class:`~uvnav.sensors.sonar2d.SonarObservation` a Chapter-4 law is given, the limits and the
  inverse action map used by :func:`uvnav.envs.as_policy`).
* ``render_mode="rgb_array"``: 256 x 256 RGB frames (obstacles grey, trap inner spaces pink, sonar
  returns black, the vehicle and its goal coloured).

``scenario`` is a Chapter-4 scene (``thesis-ch4-*``, ``random-ch4:<seed>``, a YAML file or a
:class:`~uvnav.scenarios.uuv2d.Uuv2dScenario`) or ``"random-ch4"``: a fresh random scene every
episode.  Each ``reset(seed=...)`` draws an episode seed from the env's generator; the sonar's
noise and dropout (the scene's ``sonar`` settings) are drawn from it.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from uvnav.dynamics.holonomic import SPEED_EPS, HolonomicCommand, max_speed_along
from uvnav.envs.common import SimView, VehicleWorldEnv, fill_polygon
from uvnav.envs.core import ROBOT_COLOURS, RewardConfig, goal_scale_for, pixel_grid, square_bounds
from uvnav.geometry.angles import wrap_scalar
from uvnav.sensors.sonar2d import SonarObservation
from uvnav.sim.episode_uuv2d import Uuv2dWorld

try:
    from gymnasium import spaces
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise ImportError("uvnav.envs needs gymnasium: pip install 'uvnav[envs]'") from exc


def command_of(
    action: np.ndarray, heading: float, v_max: float, u_max: float, period: float
) -> HolonomicCommand:
    """The velocity command of a normalised action (module docstring); the env
    refuses a non-finite action before (:func:`~uvnav.envs.core.checked_actions`), a direct
    caller's non-finite entries are 0."""
    a = np.asarray(action, dtype=float).reshape(2)
    a = np.clip(np.where(np.isfinite(a), a, 0.0), -1.0, 1.0)
    ang = heading + float(a[1]) * u_max * period
    s = 0.5 * (float(a[0]) + 1.0) * max_speed_along(ang, v_max)
    return HolonomicCommand(
        min(max(s * math.cos(ang), -v_max), v_max), min(max(s * math.sin(ang), -v_max), v_max)
    )


def action_of(
    cmd: HolonomicCommand, heading: float, v_max: float, u_max: float, period: float
) -> np.ndarray:
    """The normalised action of a command already within the limits (the inverse of
    :func:`command_of`), float32."""
    s = cmd.speed
    if s <= SPEED_EPS:
        return np.array([-1.0, 0.0], dtype=np.float32)
    ang = math.atan2(cmd.vy, cmd.vx)
    turn = wrap_scalar(ang - heading) / (u_max * period)
    act = np.array([2.0 * s / max_speed_along(ang, v_max) - 1.0, turn])
    return np.clip(act, -1.0, 1.0).astype(np.float32)


def observation_vector(obs: SonarObservation, *, v_max: float, goal_scale: float) -> np.ndarray:
    """The flat observation (module docstring) of a :class:`SonarObservation`, float32."""
    sonar = obs.sonar
    out = np.empty(4 + len(sonar.ranges), dtype=np.float32)
    gap = np.asarray(obs.goal, dtype=float) - obs.pose[:2]
    bearing = math.atan2(gap[1], gap[0]) - obs.heading
    out[0] = min(math.hypot(gap[0], gap[1]) / goal_scale, 1.0)
    out[1] = math.cos(bearing)
    out[2] = math.sin(bearing)
    out[3] = min(math.hypot(*obs.velocity) / (math.sqrt(2.0) * v_max), 1.0)
    ranges = np.where(np.isnan(sonar.ranges), sonar.max_range, sonar.ranges)
    out[4:] = np.clip(ranges / sonar.max_range, 0.0, 1.0)
    return out


class Uuv2DEnv(VehicleWorldEnv):
    """``uvnav/UUV2D-v0`` (module docstring).

    Args:
        scenario: a Chapter-4 scene (name, ``random-ch4:<seed>``, YAML path or
            :class:`~uvnav.scenarios.uuv2d.Uuv2dScenario`), or ``"random-ch4"`` for a new random
            scene every episode.
        render_mode: ``None`` or ``"rgb_array"``.
        goal_scale: distance [m] mapped to 1 (default: 1.5 x the start-goal distance).
        reward: reward weights (:class:`RewardConfig` or a dict of its fields).
    """

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "render_fps": 5}  # noqa: RUF012 - gymnasium declares it an instance variable
    _world: Uuv2dWorld | None
    _obs: SonarObservation | None

    def __init__(
        self,
        scenario: Any = "thesis-ch4-fig4-9-whole-run",
        *,
        render_mode: str | None = None,
        goal_scale: float | None = None,
        reward: RewardConfig | dict[str, float] | None = None,
    ) -> None:
        from uvnav.scenarios.uuv2d import UUV2D_GENERATORS, Uuv2dScenario, load_uuv2d_scenario

        def load(scenario: Any) -> Uuv2dScenario:
            return (
                scenario if isinstance(scenario, Uuv2dScenario) else load_uuv2d_scenario(scenario)
            )

        first = self._configure(scenario, UUV2D_GENERATORS, load, render_mode, reward)
        v = first.vehicle
        dist = float(math.hypot(v.goal[0] - v.start[0], v.goal[1] - v.start[1]))
        self.goal_scale = goal_scale_for(dist, goal_scale)
        n = first.sonar.to_config().n_beams
        low = np.zeros(4 + n, dtype=np.float32)
        low[1:3] = -1.0
        self.observation_space = spaces.Box(low=low, high=np.ones_like(low), dtype=np.float32)
        self.action_space = spaces.Box(low=-1.0, high=1.0, shape=(2,), dtype=np.float32)
        self._n_beams = n

    def _new_world(self, scene: Any, episode_seed: int) -> Uuv2dWorld:
        world = Uuv2dWorld(scene.to_setup(), np.random.default_rng(episode_seed))
        world.start()
        return world

    def _command(self, action: np.ndarray) -> HolonomicCommand:
        world = self._world
        assert world is not None
        spec = world.spec
        return command_of(action, float(world.state[2]), spec.v_max, spec.u_max, world.period)

    def _distance(self) -> float:
        assert self._world is not None
        return float(math.hypot(*(self._world.goal - self._world.state[:2])))

    def _vector(self) -> np.ndarray:
        world, obs = self._world, self._obs
        assert world is not None and obs is not None
        if len(obs.sonar.ranges) != self._n_beams:
            raise ValueError(
                f"scene {self.scenario!r}: its sonar has {len(obs.sonar.ranges)} beams, the "
                f"observation space {self._n_beams}"
            )
        return observation_vector(obs, v_max=world.spec.v_max, goal_scale=self.goal_scale)

    def _info(self) -> dict[str, Any]:
        world, obs = self._world, self._obs
        assert world is not None and obs is not None
        spec, heading, period = world.spec, float(obs.heading), world.period

        def to_action(cmd: HolonomicCommand) -> np.ndarray:
            applied = cmd.clipped(spec, heading, period)
            return action_of(applied, heading, spec.v_max, spec.u_max, period)

        return {
            "status": world.status if world.done else "running",
            "distance": self._distance(),
            "clearance": float(self._clearance),
            "time": world.t,
            "entered_forbidden": bool(world.entered),
            "uvnav": SimView(obs, spec, to_action),
        }

    def render(self) -> np.ndarray | None:
        if self.render_mode != "rgb_array" or self._world is None:
            return None
        return render_frame_uuv2d(self._world, self._obs)


def render_frame_uuv2d(
    world: Uuv2dWorld, obs: SonarObservation | None = None, size: int = 256
) -> np.ndarray:
    """A (size, size, 3) uint8 frame of the scene now: obstacles grey, trap inner spaces pink,
    the last sonar returns black, the vehicle a coloured disc and its goal a square; y up."""
    img = np.full((size, size, 3), 255, dtype=np.uint8)
    start = np.asarray(world.setup.start, dtype=float)[None, :2]
    allp = np.vstack([start, world.goal[None, :], world.state[None, :2], *world.outlines])
    bounds = square_bounds(allp, 1.0)
    gx, gy = pixel_grid(bounds, size, size)
    px = (bounds[2] - bounds[0]) / size
    for region in world.setup.forbidden:
        fill_polygon(img, region, (255, 200, 200), gx, gy)
    for ol in world.outlines:
        fill_polygon(img, ol, (120, 120, 120), gx, gy)
    if obs is not None:
        for p in obs.sonar.points:
            if np.all(np.isfinite(p)):
                img[np.hypot(gx - p[0], gy - p[1]) <= 1.2 * px] = (0, 0, 0)
    col = ROBOT_COLOURS[0]
    g = world.goal
    img[(np.abs(gx - g[0]) <= 2.5 * px) & (np.abs(gy - g[1]) <= 2.5 * px)] = col
    x, y, th = world.state
    rad = max(float(world.spec.radius), 2.0 * px)
    img[np.hypot(gx - x, gy - y) <= rad] = col
    tip = np.hypot(gx - (x + rad * math.cos(th)), gy - (y + rad * math.sin(th))) <= 1.5 * px
    img[tip] = (0, 0, 0)
    return img
