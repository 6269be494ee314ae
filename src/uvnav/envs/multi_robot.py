"""A PettingZoo ``ParallelEnv`` of several robots: every robot is an agent.

The world is the simulator's own :class:`uvnav.sim.multi.MultiUnicycleWorld`, stepped one
decision at a time (:class:`uvnav.envs.core.EnvWorld`), built from a multi-robot scenario
(:mod:`uvnav.scenarios.multi`: ``antipodal:N``, ``crossing:N``, ``thesis-ch2-multi:N`` or a YAML
file); episode ``k`` (``reset(options={"episode_seed": k})``) is
:func:`uvnav.sim.run.run_episode`'s on ``build_multi(scenario, k)`` with ``run_rng(k)``, bit for
bit when the agents' actions are their laws' commands (``raw_commands=True``).

Agents ``robot_0 ... robot_{N-1}`` have the observation and action spaces of ``uvnav/Nav2D-v0``
(:mod:`uvnav.envs.nav2d`); each robot's lidar and its ``info["uvnav"]`` observation include the
other robots as moving discs.  An agent terminates on arrival or collision (and is then removed
from ``agents``, PettingZoo's convention; it stays in the world as a parked disc or wreck), and
all are truncated at the scenario's ``t_max``.  Rewards are per-agent,
:class:`~uvnav.envs.core.RewardConfig`.
"""

from __future__ import annotations

import functools
from typing import Any, ClassVar

import numpy as np

from uvnav.envs.core import TERMINAL, EnvWorldEnv, RewardConfig, checked_scenario, goal_scale_for
from uvnav.envs.nav2d import act_space, episode_seed, obs_space, reward_config
from uvnav.scenarios.multi import MultiScenario, build_multi, load_multi_scenario
from uvnav.sim.multi import MultiUnicycleWorld
from uvnav.sim.seeding import run_rng

try:
    from gymnasium import spaces
    from pettingzoo import ParallelEnv
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise ImportError(
        "uvnav.envs needs gymnasium and pettingzoo: pip install 'uvnav[envs]'"
    ) from exc


class MultiNav2DParallelEnv(EnvWorldEnv, ParallelEnv):
    """PettingZoo ParallelEnv of a multi-robot scenario (module docstring).

    Args:
        scenario: ``antipodal:4``-style generator, a YAML path or a
            :class:`~uvnav.scenarios.multi.MultiScenario`.
        render_mode: ``None`` or ``"rgb_array"``.
        n_rays: lidar beams per robot.
        max_range: lidar range [m].
        goal_scale: distance [m] mapped to 1 in the observation (default 1.5 x the longest
            start-goal distance).
        reward: reward weights.
        raw_commands: actions are unicycle commands ``(v, u)`` (:mod:`uvnav.envs.core`).
    """

    metadata: ClassVar[dict[str, Any]] = {
        "name": "uvnav_multinav2d_v0",
        "render_modes": ["rgb_array"],
        "render_fps": 10,
    }

    def __init__(
        self,
        scenario: str | MultiScenario = "antipodal:4",
        *,
        render_mode: str | None = None,
        n_rays: int = 32,
        max_range: float = 5.0,
        goal_scale: float | None = None,
        reward: RewardConfig | dict[str, float] | None = None,
        raw_commands: bool = False,
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be None or 'rgb_array' (got {render_mode!r})")
        checked_scenario(scenario, MultiScenario)
        self.scenario = (
            scenario if isinstance(scenario, MultiScenario) else load_multi_scenario(scenario)
        )
        starts = np.array([r.start for r in self.scenario.robots])
        goals = np.array([r.goal for r in self.scenario.robots])
        longest = float(np.hypot(*(goals - starts).T).max())
        self.goal_scale = goal_scale_for(longest, goal_scale)
        self._configure(render_mode, n_rays, max_range, reward_config(reward), raw_commands)
        self.possible_agents = [f"robot_{i}" for i in range(len(self.scenario.robots))]
        self.agents: list[str] = []
        self._index = {a: i for i, a in enumerate(self.possible_agents)}
        self._rng = np.random.default_rng()

    @property
    def world(self) -> MultiUnicycleWorld:
        """The loop world of the current episode (metrics, ``law_setup``...)."""
        world = self._loop_world()
        assert isinstance(world, MultiUnicycleWorld)
        return world

    @functools.cache  # noqa: B019 - one space object per agent, as PettingZoo asks
    def observation_space(self, agent: str) -> spaces.Box:
        return obs_space(self.n_rays)

    @functools.cache  # noqa: B019
    def action_space(self, agent: str) -> spaces.Box:
        r = self.scenario.robots[self._index[agent]]
        return act_space(r.v_max, r.u_max, raw=self.raw_commands)

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, dict[str, Any]]]:
        if seed is not None:
            self._rng = np.random.default_rng(seed)
        if self._world is not None:
            self._world.close()
        self.episode_seed = k = episode_seed(self._rng, options)
        w = self._open(MultiUnicycleWorld(build_multi(self.scenario, k), run_rng(k)))
        self.agents = [a for a in self.possible_agents if w.running(self._index[a])]
        obs = {a: w.vector(self._index[a]) for a in self.agents}
        infos = {a: self._info(self._index[a]) for a in self.agents}
        return obs, infos

    def step(
        self, actions: dict[str, np.ndarray]
    ) -> tuple[
        dict[str, np.ndarray],
        dict[str, float],
        dict[str, bool],
        dict[str, bool],
        dict[str, dict[str, Any]],
    ]:
        w = self._world
        if w is None:
            raise RuntimeError("call reset() before step()")
        live = list(self.agents)
        rewards_arr = w.step({self._index[a]: np.asarray(actions[a]) for a in live if a in actions})
        timeout = w.world.done
        obs, rewards, terms, truncs, infos = {}, {}, {}, {}, {}
        for a in live:
            i = self._index[a]
            obs[a] = w.vector(i)
            rewards[a] = float(rewards_arr[i])
            terms[a] = w.status(i) in TERMINAL
            truncs[a] = bool(timeout and not terms[a])
            infos[a] = self._info(i)
            if truncs[a]:
                infos[a]["status"] = "timeout"
        self.agents = [a for a in live if not (terms[a] or truncs[a])]
        return obs, rewards, terms, truncs, infos
