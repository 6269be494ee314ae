"""A Gymnasium env for learning crowd navigation: CrowdNav's circle crossing, holonomic robot.

Each ``reset`` draws a case of ``crowdnav-circle`` (:func:`uvnav.scenarios.crowdnav.
crowdnav_scenario`) from the env's generator among ``cases`` of the *train* phase (numpy legacy
seeds ``2000 + case``: never the test phase's ``1000 + case`` that the benchmarks judge), with
``n_humans`` humans (an int, or a ``(low, high)`` range drawn per episode: a curriculum), and
steps the simulator's own world (:class:`uvnav.sim.episode.World2D` through
:class:`uvnav.envs.core.EnvWorld`: the world's integration, crowd and collision checks, one env
step per 0.25 s decision).

* **Observation**: :func:`uvnav.controllers.crowd_features.crowd_vector` of the
  :class:`~uvnav.sensors.Observation` the world gives the robot (the robot's goal-frame state and
  its ``k`` nearest seen humans, masked), float32.
* **Action** ``Box([-1, -1], [1, 1])``: a velocity ``V_max a`` in the goal frame, scaled onto the
  disc of radius V_max (:func:`~uvnav.controllers.crowd_features.action_velocity`).
* **Reward**: :class:`uvnav.envs.core.RewardConfig` (progress to the goal, time, clearance under
  a margin, success, collision).
* **Termination** on arrival or collision, **truncation** at the scene's time limit (24 s).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from uvnav.controllers.crowd_features import action_velocity, crowd_vector, vector_size
from uvnav.envs.core import TERMINAL, EnvWorld, RewardConfig
from uvnav.scenarios.build import build_episode
from uvnav.scenarios.crowdnav import crowdnav_scenario
from uvnav.sensors.observation import Observation
from uvnav.sim.episode import World2D
from uvnav.sim.seeding import run_rng

try:
    import gymnasium as gym
    from gymnasium import spaces
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise ImportError("uvnav.envs needs gymnasium: pip install 'uvnav[envs]'") from exc

#: the reward of the shipped policy's training: RewardConfig's, with a 0.2 m comfort margin
#: (CrowdNav's discomfort distance)
CROWD_REWARD = RewardConfig(clearance_margin=0.2)


class CrowdNavEnv(gym.Env[np.ndarray, np.ndarray]):
    """CrowdNav's circle crossing for learning (module docstring).

    Args:
        k: human slots of the observation.
        n_humans: humans per scene, or ``(low, high)``: drawn uniformly per episode.
        cases: the train-phase cases drawn from (``range(0, cases)``).
        reward: reward weights.
    """

    metadata: dict[str, Any] = {"render_modes": []}  # noqa: RUF012 - gymnasium declares it an instance variable

    def __init__(
        self,
        *,
        k: int = 5,
        n_humans: int | tuple[int, int] = 5,
        cases: int = 100_000,
        reward: RewardConfig = CROWD_REWARD,
    ) -> None:
        if not 1 <= int(k) <= 64:
            raise ValueError(f"k must be a whole number from 1 to 64 (got {k!r})")
        self.k = int(k)
        low, high = (n_humans, n_humans) if isinstance(n_humans, int) else n_humans
        if not 0 <= low <= high <= 64:
            raise ValueError(f"n_humans must be 0..64 or a range low <= high (got {n_humans!r})")
        self.humans = (int(low), int(high))
        self.cases = int(cases)
        self.reward_config = reward
        size = vector_size(self.k)
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(size,), dtype=np.float32)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)
        self._world: EnvWorld | None = None
        self._obs: Observation | None = None
        self.case = -1

    def _observe(self) -> np.ndarray:
        w = self._world
        assert w is not None
        self._obs = w.view(0).observation
        spec = w.spec(0)
        return crowd_vector(self._obs, self.k, float(spec.v_max), float(spec.radius))

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        super().reset(seed=seed)
        if self._world is not None:
            self._world.close()
        rng = self.np_random
        self.case = int(rng.integers(self.cases))
        n = int(rng.integers(self.humans[0], self.humans[1] + 1))
        scene = crowdnav_scenario(self.case, phase="train", n_humans=n)
        setup = build_episode(scene, self.case)
        world = World2D(setup, run_rng(self.case), exact=True, vehicle="holonomic")
        self._world = EnvWorld(world, n_rays=0, reward=self.reward_config, raw_commands=True)
        return self._observe(), {"status": "running", "case": self.case}

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        w, obs = self._world, self._obs
        if w is None or obs is None:
            raise RuntimeError("call reset() before step()")
        v = action_velocity(np.asarray(action, dtype=float), obs, float(w.spec(0).v_max))
        reward = float(w.step({0: np.array(v)})[0])
        status = w.status(0)
        terminated = status in TERMINAL
        truncated = not terminated and w.world.done
        info = {"status": "timeout" if truncated else status, "case": self.case}
        return self._observe(), reward, terminated, truncated, info

    def close(self) -> None:
        if self._world is not None:
            self._world.close()
            self._world = None
