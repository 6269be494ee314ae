"""A Gymnasium env for learning crowd navigation: CrowdNav's crossings and the harder crowd.

Each ``reset`` draws one of the env's ``rules`` (uniformly), then a case among ``cases`` of that
rule's *training* seeds, never a case the benchmarks judge:

* ``circle_crossing`` / ``square_crossing``: :func:`uvnav.scenarios.crowdnav.crowdnav_scenario`
  of the *train* phase (numpy legacy seeds ``2000 + case``, never the test phase's
  ``1000 + case``), with ``n_humans`` humans (an int, or a ``(low, high)`` range drawn per
  episode); a case whose humans cannot be placed apart is drawn again;
* ``crowd_dynamic``: :func:`uvnav.scenarios.crowd_dynamic.crowd_dynamic_scenario` of seed
  :data:`DYNAMIC_TRAIN_SEED` ``+ case`` (the benchmarks judge seeds below it), with its own
  20 humans and 5 m sensing;

and steps the simulator's own world (:class:`uvnav.sim.episode.World2D` through
:class:`uvnav.envs.core.EnvWorld`: the world's integration, crowd and collision checks, one env
step per 0.25 s decision).

* **Observation**: :func:`uvnav.controllers.crowd_features.crowd_vector` of the
  :class:`~uvnav.sensors.Observation` the world gives the robot (the robot's goal-frame state and
  its ``k`` nearest seen humans, masked), float32.
* **Action** ``Box([-1, -1], [1, 1])``: a velocity ``V_max a`` in the goal frame, scaled onto the
  disc of radius V_max (:func:`~uvnav.controllers.crowd_features.action_velocity`).
* **Reward**: :class:`uvnav.envs.core.RewardConfig` (progress to the goal, time, clearance under
  a margin, success, collision).
* **Termination** on arrival or collision, **truncation** at the scene's time limit (24 s for
  CrowdNav's scenes, 50 s for the harder crowd).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from uvnav.controllers.crowd_features import action_velocity, crowd_vector, vector_size
from uvnav.envs.core import TERMINAL, EnvWorld, RewardConfig
from uvnav.scenarios.build import build_episode
from uvnav.scenarios.crowd_dynamic import crowd_dynamic_scenario
from uvnav.scenarios.crowdnav import crowdnav_scenario
from uvnav.scenarios.errors import ScenarioError
from uvnav.scenarios.schema import Scenario
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
#: the scenes an env may draw from (module docstring)
RULES: tuple[str, ...] = ("circle_crossing", "square_crossing", "crowd_dynamic")
#: the first ``crowd-dynamic`` seed of training (seeds below it are the benchmarks')
DYNAMIC_TRAIN_SEED = 1_000_000
#: draws of a case before an env gives up on placing its humans
MAX_CASE_DRAWS = 100


class CrowdNavEnv(gym.Env[np.ndarray, np.ndarray]):
    """Crowd scenes for learning (module docstring).

    Args:
        k: human slots of the observation.
        n_humans: humans per CrowdNav scene, or ``(low, high)``: drawn uniformly per episode.
        cases: the training cases drawn from (``range(0, cases)``).
        reward: reward weights.
        rules: the scenes drawn from, uniformly per episode (:data:`RULES`).
    """

    metadata: dict[str, Any] = {"render_modes": []}  # noqa: RUF012 - gymnasium declares it an instance variable

    def __init__(
        self,
        *,
        k: int = 5,
        n_humans: int | tuple[int, int] = 5,
        cases: int = 100_000,
        reward: RewardConfig = CROWD_REWARD,
        rules: tuple[str, ...] = ("circle_crossing",),
    ) -> None:
        if not 1 <= int(k) <= 64:
            raise ValueError(f"k must be a whole number from 1 to 64 (got {k!r})")
        self.k = int(k)
        low, high = (n_humans, n_humans) if isinstance(n_humans, int) else n_humans
        if not 0 <= low <= high <= 64:
            raise ValueError(f"n_humans must be 0..64 or a range low <= high (got {n_humans!r})")
        self.humans = (int(low), int(high))
        if not rules or any(r not in RULES for r in rules):
            raise ValueError(f"rules must be some of {', '.join(RULES)} (got {rules!r})")
        self.rules = tuple(rules)
        self.rule = self.rules[0]
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
        scene, seed = self._draw_scene()
        setup = build_episode(scene, seed)
        world = World2D(setup, run_rng(seed), exact=True, vehicle="holonomic")
        self._world = EnvWorld(world, n_rays=0, reward=self.reward_config, raw_commands=True)
        return self._observe(), {"status": "running", "case": self.case, "rule": self.rule}

    def _draw_scene(self) -> tuple[Scenario, int]:
        """A training scene of a drawn rule and case, and its episode seed (module docstring)."""
        rng = self.np_random
        self.rule = self.rules[int(rng.integers(len(self.rules)))]
        for _ in range(MAX_CASE_DRAWS):
            self.case = int(rng.integers(self.cases))
            n = int(rng.integers(self.humans[0], self.humans[1] + 1))
            try:
                if self.rule == "crowd_dynamic":
                    seed = DYNAMIC_TRAIN_SEED + self.case
                    return crowd_dynamic_scenario(seed), seed
                rule: Any = self.rule
                return crowdnav_scenario(self.case, rule=rule, phase="train", n_humans=n), self.case
            except ScenarioError:
                continue
        raise RuntimeError(f"{self.rule}: no case of {MAX_CASE_DRAWS} could place its humans")

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        w, obs = self._world, self._obs
        if w is None or obs is None:
            raise RuntimeError("call reset() before step()")
        v = action_velocity(np.asarray(action, dtype=float), obs, float(w.spec(0).v_max))
        reward = float(w.step({0: np.array(v)})[0])
        status = w.status(0)
        terminated = status in TERMINAL
        truncated = not terminated and w.world.done
        info = {"status": "timeout" if truncated else status, "case": self.case, "rule": self.rule}
        return self._observe(), reward, terminated, truncated, info

    def close(self) -> None:
        if self._world is not None:
            self._world.close()
            self._world = None
