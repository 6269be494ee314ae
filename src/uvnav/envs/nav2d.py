"""``uvnav/Nav2D-v0``: a Gymnasium environment on the 2D world of the thesis's Ch. 2.

One robot (the unicycle, (2.1)-(2.4), or another planar vehicle: ``vehicle=``, the holonomic
robot or a plug-in's, :mod:`uvnav.dynamics.vehicles`) among a scenario's obstacles.  The env
steps the simulator's own world, :class:`uvnav.sim.episode.World2D`
(:class:`uvnav.envs.core.EnvWorld`): one env
step is one decision (``control_period``), integrated with the scenario's ``dt`` and checked for
collisions at every integration step by the world, so that an env episode driven by a law's
commands (``raw_commands=True``) is bit for bit :func:`uvnav.sim.run_episode`'s.  As there, with
numba enabled a scene that packs (:func:`uvnav.sim.packed.pack_check`) moves, senses and casts the
lidar in compiled calls (:class:`uvnav.sim.bodies2d.PackedBodies`), with the same numbers.

* **Observation** ``Box(4 + n_rays,)`` float32: goal distance / ``goal_scale`` in [0, 1], cos and
  sin of the goal bearing in the robot frame, speed / V_max, then ``n_rays`` lidar ranges /
  ``max_range`` in [0, 1] (first beam straight behind, counter-clockwise).
* **Action** ``Box([-1, -1], [1, 1])`` float32: ``v = (a0 + 1) / 2 V_max``, ``u = a1 U_max``;
  with ``raw_commands=True``, ``Box([0, -U_max], [V_max, U_max])`` float64: the command
  ``(v [m/s], u [rad/s])`` itself, saturated and counted as a limit violation when outside, as
  the simulator does with a law's command (:mod:`uvnav.envs.core`).  Another vehicle's action
  is its command box (``Vehicle2D.bounds``), normalised the same way or raw.
* **Reward**: :class:`uvnav.envs.core.RewardConfig` (progress, time, clearance, success,
  collision), configurable with ``reward={...}``.
* **Termination**: arrival (``info["status"] == "success"``) or collision; **truncation** at the
  scenario's ``t_max``.
* ``info``: ``status``, ``distance`` [m], ``clearance`` [m], ``time`` [s], and — so that any uvnav
  controller can drive the env (:func:`uvnav.envs.as_policy`) — ``uvnav``, a
  :class:`~uvnav.envs.core.ControllerView` holding the :class:`~uvnav.sensors.Observation` the
  simulator would give the controller at this step (made when first read) and the vehicle
  limits.
* ``render_mode="rgb_array"``: 256 x 256 RGB frames.

Each ``reset(seed=...)`` draws an episode seed from the env's generator, so random obstacles
differ per episode and the same seed gives the same episode; ``reset(options={"episode_seed":
k})`` runs episode ``k`` itself.  Episode ``k`` is the simulator's (``uvnav simulate SCENE
--seed k``): the scene :func:`uvnav.scenarios.build.build_episode` ``(scenario, k)``, the world's
generator :func:`uvnav.sim.run_rng` ``(k)`` (the law's generator is ``env.world.law_setup()``'s).
"""

from __future__ import annotations

from dataclasses import fields, replace
from typing import Any

import numpy as np

from uvnav.dynamics.vehicles import make_vehicle, vehicles_2d
from uvnav.envs.core import (
    TERMINAL,
    EnvWorldEnv,
    RewardConfig,
    checked_count,
    checked_scenario,
    goal_scale_for,
)
from uvnav.geometry.kernels3d import numba_enabled
from uvnav.scenarios.build import build_episode
from uvnav.scenarios.loader import load_scenario
from uvnav.scenarios.schema import Scenario
from uvnav.sim.episode import World2D
from uvnav.sim.seeding import run_rng

try:
    import gymnasium as gym
    from gymnasium import spaces
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise ImportError("uvnav.envs needs gymnasium: pip install 'uvnav[envs]'") from exc


def reward_config(reward: RewardConfig | dict[str, float] | None) -> RewardConfig:
    """A :class:`RewardConfig` from a config, a dict of its fields, or ``None`` (defaults)."""
    if reward is None:
        return RewardConfig()
    if isinstance(reward, RewardConfig):
        return reward
    if not isinstance(reward, dict):
        raise TypeError(
            f"reward must be a RewardConfig or a dict of its fields (got {type(reward).__name__})"
        )
    known = [f.name for f in fields(RewardConfig)]
    unknown = sorted(set(reward) - set(known))
    if unknown:
        raise ValueError(
            f"reward: unknown field(s) {', '.join(unknown)}; known: {', '.join(known)}"
        )
    return replace(RewardConfig(), **reward)


def obs_space(n_rays: int) -> spaces.Box:
    low = np.zeros(4 + n_rays, dtype=np.float32)
    low[1:3] = -1.0
    return spaces.Box(low=low, high=np.ones(4 + n_rays, dtype=np.float32), dtype=np.float32)


def act_space(v_max: float = 1.0, u_max: float = 1.0, *, raw: bool = False) -> spaces.Box:
    """The normalised action box, or (``raw``) the command box ``[0, V_max] x [-U_max, U_max]``."""
    if raw:
        return spaces.Box(
            low=np.array([0.0, -u_max]), high=np.array([v_max, u_max]), dtype=np.float64
        )
    return spaces.Box(low=-1.0, high=1.0, shape=(2,), dtype=np.float32)


def episode_seed(rng: np.random.Generator, options: dict[str, Any] | None) -> int:
    """``options["episode_seed"]`` when given, else one drawn from ``rng``."""
    if options and options.get("episode_seed") is not None:
        return checked_count("options['episode_seed']", options["episode_seed"], 0, 2**63 - 1)
    return int(rng.integers(2**31 - 1))


class Nav2DEnv(EnvWorldEnv, gym.Env[np.ndarray, np.ndarray]):
    """``uvnav/Nav2D-v0`` (module docstring).

    Args:
        scenario: built-in name, YAML path or generator (``random-ch2:3``), or a
            :class:`~uvnav.scenarios.Scenario`.
        render_mode: ``None`` or ``"rgb_array"``.
        n_rays: lidar beams in the observation.
        max_range: lidar range [m].
        goal_scale: distance [m] mapped to 1 (default: the scenario's start-goal distance x 1.5).
        reward: reward weights (:class:`RewardConfig` or a dict of its fields).
        raw_commands: actions are the vehicle's commands (the unicycle's ``(v, u)``; module
            docstring).
        vehicle: the planar vehicle the agent drives (the unicycle; ``holonomic`` or a plug-in
            vehicle's name, :func:`~uvnav.dynamics.vehicles.vehicles_2d`).
        swept: collisions judged along each integration step, as ``uvnav simulate`` judges them
            (``False``: at each step's end, as the batched env does).
    """

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "render_fps": 10}  # noqa: RUF012 - gymnasium declares it an instance variable

    def __init__(
        self,
        scenario: str | Scenario = "thesis-ch2-one-obstacle",
        *,
        render_mode: str | None = None,
        n_rays: int = 32,
        max_range: float = 5.0,
        goal_scale: float | None = None,
        reward: RewardConfig | dict[str, float] | None = None,
        raw_commands: bool = False,
        vehicle: str = "unicycle",
        swept: bool = True,
    ) -> None:
        if vehicle not in vehicles_2d():
            known = ", ".join(vehicles_2d())
            raise ValueError(f"vehicle: no 2D vehicle {vehicle!r}; known: {known}")
        self.vehicle = vehicle
        self.swept = swept
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be None or 'rgb_array' (got {render_mode!r})")
        checked_scenario(scenario, Scenario)
        self.scenario = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
        r = self.scenario.robot
        dist = float(np.hypot(r.goal[0] - r.start[0], r.goal[1] - r.start[1]))
        self.goal_scale = goal_scale_for(dist, goal_scale)
        self._configure(render_mode, n_rays, max_range, reward_config(reward), raw_commands)
        self.observation_space = obs_space(self.n_rays)
        if vehicle == "unicycle":
            self.action_space = act_space(r.v_max, r.u_max, raw=raw_commands)
        else:
            low, high = make_vehicle(vehicle, self.scenario.robot.to_spec()).bounds()
            self.action_space = (
                spaces.Box(low=np.array(low), high=np.array(high), dtype=np.float64)
                if raw_commands
                else spaces.Box(low=-1.0, high=1.0, shape=(2,), dtype=np.float32)
            )

    @property
    def world(self) -> World2D:
        """The loop world of the current episode (metrics, ``law_setup``...)."""
        world = self._loop_world()
        assert isinstance(world, World2D)
        return world

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        if self._world is not None:
            self._world.close()
        self.episode_seed = k = episode_seed(self.np_random, options)
        setup = build_episode(self.scenario, k)
        world = World2D(setup, run_rng(k), exact=True, vehicle=self.vehicle, swept=self.swept,
                        packed=numba_enabled())  # fmt: skip
        w = self._open(world)
        return w.vector(0), self._info(0)

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        w = self._world
        if w is None:
            raise RuntimeError("call reset() before step()")
        reward = w.step_one(action)
        info = w.info_one()
        terminated = info["status"] in TERMINAL
        truncated = not terminated and w.world.done
        if truncated:
            info["status"] = "timeout"
        return w.vector(0), reward, terminated, truncated, info
