"""``uvnav/Nav2D-v0`` batched: K worlds stepped by one compiled call, a Gymnasium ``VectorEnv``.

``gymnasium.make_vec("uvnav/Nav2D-v0", num_envs=K, vectorization_mode="vector_entry_point")``
gives :class:`Nav2DVectorEnv`.  Its K sub-environments are :class:`uvnav.envs.nav2d.Nav2DEnv`'s
with ``swept=False``, number for number: the same observation vector (goal distance, goal
bearing, speed, lidar), the same actions, rewards, terminations and truncations, and the same
episodes for the same seeds (``reset(seed=s)`` seeds sub-environment ``i`` with ``s + i``, as
``SyncVectorEnv`` does), with Gymnasium's default ``NEXT_STEP`` autoreset.  The test suite
checks equality with a ``SyncVectorEnv`` of ``Nav2DEnv`` s, not closeness.

The worlds live in :class:`uvnav.sim.packed.PackedWorlds` (compiled with numba when it is
installed, the plain Python loops otherwise: the same numbers, far slower), so only scenes whose
obstacles are polygons moving with constant velocity or random turns can be batched (the
``random-ch2`` generator and the thesis's Ch. 2 scenes); another scene is refused with the reason.
What the single env has and this one has not: collisions judged along each step (the batched
worlds judge them at its end: the equal single env is ``Nav2DEnv(..., swept=False)``, and
``swept=True`` is refused here), rendering, and ``info["uvnav"]`` (the
:class:`~uvnav.sensors.Observation` a uvnav law would get), which needs the per-step objects that
batching removes.  ``info`` holds ``status``, ``distance`` [m], ``clearance`` [m] and ``time`` [s]
per sub-environment.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from uvnav.envs.core import (
    RewardConfig,
    action_commands,
    checked_actions,
    checked_count,
    checked_lidar,
    checked_scenario,
    goal_scale_for,
)
from uvnav.envs.nav2d import act_space, episode_seed, obs_space, reward_config
from uvnav.scenarios.build import build_episode
from uvnav.scenarios.loader import load_scenario
from uvnav.scenarios.schema import Scenario
from uvnav.sim.packed import (
    COLLISION,
    STATUS_NAMES,
    SUCCESS,
    TIMEOUT,
    PackedWorlds,
    kernel,
    pack_check,
)
from uvnav.sim.seeding import _WORLD as WORLD_KEY

try:
    import gymnasium as gym
    from gymnasium.utils import seeding
    from gymnasium.vector.utils import batch_space
except ImportError as exc:  # pragma: no cover - exercised only without the extra
    raise ImportError("uvnav.envs needs gymnasium: pip install 'uvnav[envs]'") from exc


#: Most sub-environments of one :class:`Nav2DVectorEnv` (each holds a world and its arrays).
MAX_NUM_ENVS = 10_000


class Nav2DVectorEnv(gym.vector.VectorEnv[np.ndarray, np.ndarray, np.ndarray]):
    """K ``uvnav/Nav2D-v0`` worlds in one (module docstring).

    Args:
        num_envs: K, a whole number from 1 to :data:`MAX_NUM_ENVS`.
        scenario: as :class:`~uvnav.envs.nav2d.Nav2DEnv`'s (built-in name, YAML path,
            ``generator:seed`` or a :class:`~uvnav.scenarios.Scenario`).
        n_rays, max_range, goal_scale, reward, raw_commands: as
            :class:`~uvnav.envs.nav2d.Nav2DEnv`'s.

    Raises:
        ValueError: the scene cannot be batched, or an argument is out of range (one line).
        TypeError: an argument is not a number (one line).
    """

    metadata: dict[str, Any] = {"autoreset_mode": gym.vector.AutoresetMode.NEXT_STEP}  # noqa: RUF012 - gymnasium declares it an instance variable

    def __init__(
        self,
        num_envs: int = 8,
        scenario: str | Scenario = "thesis-ch2-one-obstacle",
        *,
        n_rays: int = 32,
        max_range: float = 5.0,
        goal_scale: float | None = None,
        reward: RewardConfig | dict[str, float] | None = None,
        raw_commands: bool = False,
        render_mode: None = None,
        swept: bool = False,
    ) -> None:
        k = checked_count("num_envs", num_envs, 1, MAX_NUM_ENVS)
        if swept:
            raise ValueError(
                "swept: the batched worlds judge collisions at the end of each step; "
                "Nav2DEnv judges them along it"
            )
        if render_mode is not None:
            raise ValueError("the batched Nav2D env does not render; use Nav2DEnv")
        self.num_envs = k
        checked_scenario(scenario, Scenario)
        self.scenario = scenario if isinstance(scenario, Scenario) else load_scenario(scenario)
        why = pack_check(build_episode(self.scenario, 0))
        if why is not None:
            name = getattr(self.scenario, "name", None) or "the scene"
            raise ValueError(f"{name} cannot be batched: {why}")
        r = self.scenario.robot
        dist = float(np.hypot(r.goal[0] - r.start[0], r.goal[1] - r.start[1]))
        self.goal_scale = goal_scale_for(dist, goal_scale)
        self.n_rays, self.max_range = checked_lidar(n_rays, max_range)
        self.reward_config = reward_config(reward)
        self.raw_commands = raw_commands
        self.single_observation_space = obs_space(self.n_rays)
        self.single_action_space = act_space(r.v_max, r.u_max, raw=raw_commands)
        self.observation_space = batch_space(self.single_observation_space, k)
        self.action_space = batch_space(self.single_action_space, k)
        self.render_mode = None
        self.worlds = PackedWorlds(k)
        self._rel = np.linspace(-np.pi, np.pi, self.n_rays, endpoint=False)
        self._ranges = np.empty((k, self.n_rays))
        self._obs = np.empty((k, 4 + self.n_rays), dtype=np.float32)
        self._dist = np.zeros(k)
        self._clear = np.zeros(k)
        self._rngs: list[np.random.Generator | None] = [None] * k
        #: each slot's obstacle generators, reseeded at each restored reset
        self._pool: list[list[np.random.Generator] | None] = [None] * k
        self._autoreset = np.zeros(k, dtype=np.bool_)
        self.episode_seeds = np.zeros(k, dtype=np.int64)
        self._image: tuple[np.ndarray, ...] | None = None
        self._names = np.array(STATUS_NAMES, dtype=object)
        #: the info's masks (every sub-environment has every entry), shared and read-only
        self._ones = np.ones(k, dtype=np.bool_)
        self._ones.flags.writeable = False
        #: the clearance [m] for the reward of an episode restored from :attr:`_image`
        self._image_clear = 0.0
        self._weights_of: RewardConfig | None = None
        self._weight_row = np.zeros(6)

    def _load(self, i: int, options: dict[str, Any] | None) -> None:
        """Start sub-environment ``i``'s next episode (its generator picks the seed).  The first
        episode is built (:func:`~uvnav.scenarios.build.build_episode`) and loaded, the others
        restore its image (:meth:`PackedWorlds.restore_spawned
        <uvnav.sim.packed.PackedWorlds.restore_spawned>`) with the slot's own obstacle
        generators, reseeded to the states the children of :func:`~uvnav.sim.seeding.world_rng`
        would have: the same episodes, without building them."""
        self._start(i, self._next_seed(i, options))

    def _next_seed(self, i: int, options: dict[str, Any] | None) -> int:
        """Sub-environment ``i``'s next episode seed, from its generator."""
        rng = self._rngs[i]
        if rng is None:
            rng = self._rngs[i] = seeding.np_random()[0]
        self.episode_seeds[i] = k = episode_seed(rng, options)
        return k

    def _children(self, i: int) -> list[np.random.Generator]:
        """Sub-environment ``i``'s obstacle generators (reseeded at each restored reset)."""
        children = self._pool[i]
        if children is None:
            n = len(self.scenario.obstacles)
            children = self._pool[i] = [np.random.default_rng(0) for _ in range(n)]
        return children

    def _start(self, i: int, k: int) -> None:
        """Start sub-environment ``i``'s episode of seed ``k`` (:meth:`_load`)."""
        # world_rng(k).spawn(n): build_episode's generators
        if self._image is not None and self.worlds.restore_spawned(
            i, self._image, [k, WORLD_KEY], self._children(i)
        ):
            self._set_clear(i)
            return
        self.worlds.load(i, build_episode(self.scenario, k))
        self._image = self.worlds.image(i)
        self._set_clear(i)
        self._image_clear = float(self._clear[i])

    def _restart(self, ids: list[int]) -> None:
        """:meth:`_load` of sub-environments ``ids`` (no options), the restored ones in one
        compiled call (:meth:`PackedWorlds.restore_spawned_many
        <uvnav.sim.packed.PackedWorlds.restore_spawned_many>`)."""
        seeds = [self._next_seed(i, None) for i in ids]
        if self._image is not None and self.worlds.restore_spawned_many(
            ids, self._image, seeds, WORLD_KEY, [self._children(i) for i in ids]
        ):
            self._clear[ids] = self._image_clear  # every restored world starts as the image
            return
        for i, k in zip(ids, seeds, strict=True):
            self._start(i, k)

    def _set_clear(self, ids: int | list[int]) -> None:
        """Sub-environments ``ids``' clearance for the reward, from their worlds' at the start
        (``max_range`` where it is not finite)."""
        c = self.worlds.clearance[ids]
        self._clear[ids] = np.where(np.isfinite(c), c, self.max_range)

    def _observe(self) -> None:
        """Observation vectors and goal distances of every sub-environment."""
        self.worlds.observe(self._rel, self.max_range, self.goal_scale, self._ranges, self._obs,
                            self._dist)  # fmt: skip

    def _infos(self) -> dict[str, Any]:
        w = self.worlds
        status = self._names[w.status]
        ones = self._ones
        return {
            "status": status, "_status": ones,
            "distance": self._dist.copy(), "_distance": ones,
            "clearance": self._clear.copy(), "_clearance": ones,
            "time": w.time, "_time": ones,
        }  # fmt: skip

    def reset(
        self, *, seed: int | list[int | None] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start every sub-environment's next episode; ``seed`` (an int ``s``: ``s + i`` for
        sub-environment ``i``, or one per sub-environment) re-seeds their generators."""
        seeds = [seed + i for i in range(self.num_envs)] if isinstance(seed, int) else seed
        if seeds is not None and len(seeds) != self.num_envs:
            raise ValueError(f"reset: {len(seeds)} seeds for {self.num_envs} environments")
        for i in range(self.num_envs):
            if seeds is not None and seeds[i] is not None:
                self._rngs[i] = seeding.np_random(seeds[i])[0]
            self._load(i, options)
        self._autoreset[:] = False
        self._observe()
        return self._obs.copy(), self._infos()

    def _commands(self, actions: np.ndarray, acting: np.ndarray) -> None:
        """The ``acting`` worlds' actions to held commands: :func:`action_commands
        <uvnav.envs.core.action_commands>`, then the saturation of :meth:`UnicycleCommand.clipped
        <uvnav.dynamics.unicycle.UnicycleCommand.clipped>` on arrays."""
        vmax, umax = self.worlds.limits[:, 0], self.worlds.limits[:, 1]
        v, u = action_commands(actions, vmax, umax, self.raw_commands)
        v = np.minimum(np.maximum(v, 0.0), vmax)
        u = np.minimum(np.maximum(u, -umax), umax)
        cmd = self.worlds.command
        np.copyto(cmd[:, 0], v, where=acting)
        np.copyto(cmd[:, 1], u, where=acting)

    def _weights(self) -> np.ndarray:
        """The reward's weights (progress, time, clearance, clearance margin, success,
        collision) of :attr:`reward_config`, kept while it is the same object."""
        cfg = self.reward_config
        if self._weights_of is not cfg:
            self._weights_of = cfg
            self._weight_row = np.array([cfg.progress, cfg.time, cfg.clearance,
                                         cfg.clearance_margin, cfg.success, cfg.collision],
                                        dtype=float)  # fmt: skip
        return self._weight_row

    def step(
        self, actions: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """One decision in every sub-environment (those that ended last step restart instead,
        ignoring their action)."""
        actions = checked_actions("actions", actions, (self.num_envs, 2))
        w = self.worlds
        restart = self._autoreset.copy()
        ids = restart.nonzero()[0].tolist()
        if ids:
            self._restart(ids)
        if self.raw_commands:
            running = ~restart & (w.status != SUCCESS) & (w.status != COLLISION)
            self._commands(actions, running & (w.status != TIMEOUT))
        rewards = np.empty(self.num_envs)
        terminated = np.empty(self.num_envs, dtype=np.bool_)
        truncated = np.empty(self.num_envs, dtype=np.bool_)
        w.ensure_draws()  # its count is replaced by the kernel's, which knows the rows read
        w.safe_calls = kernel("vector_step")(
            actions, restart, self.raw_commands, w.wf, w.wi, w.oi, w.params, w.state, w.ubuf,
            w.rings, self._rel, self.max_range, self.goal_scale, self._ranges, self._obs,
            self._dist, self._clear, self._weights(), rewards, terminated, truncated,
        )  # fmt: skip
        self._autoreset = terminated | truncated
        return self._obs.copy(), rewards, terminated, truncated, self._infos()
