"""Gymnasium / PettingZoo environments (layer 6).

* ``uvnav/Nav2D-v0`` (:class:`uvnav.envs.nav2d.Nav2DEnv`): one robot on a uvnav scenario.
* ``uvnav/Nav3D-v0`` (:class:`uvnav.envs.nav3d.Nav3DEnv`): the Chapter-3 3D flying robot.
* ``uvnav/UUV2D-v0`` (:class:`uvnav.envs.uuv2d.Uuv2DEnv`): the Chapter-4 UUV with its sonar.
* :class:`uvnav.envs.multi_robot.MultiNav2DParallelEnv`: a PettingZoo ``ParallelEnv`` of several
  robots on a multi-robot scenario (``antipodal:4`` ...).
* :class:`uvnav.envs.nav2d_vec.Nav2DVectorEnv`: ``uvnav/Nav2D-v0`` batched, K worlds in one
  compiled step (``gymnasium.make_vec("uvnav/Nav2D-v0", num_envs=K,
  vectorization_mode="vector_entry_point")``).
* :class:`uvnav.envs.crowd.CrowdNavEnv`: CrowdNav's circle crossing for learning a crowd law
  (train-phase seeds, holonomic robot, the goal-frame crowd observation; not registered).
* :func:`as_policy`: any uvnav controller as a policy for them.

gymnasium and pettingzoo (``uvnav[envs]``) are imported only when an env class is used.

Making the envs with Gymnasium 1.x, which does not load plugin entry points (a plain
``gymnasium.make("uvnav/Nav2D-v0")`` in a fresh interpreter without uvnav raises
``NamespaceNotFound``): ``import uvnav`` registers them, before or after gymnasium's import (the
hook of :mod:`uvnav`), and so does importing this package::

    import gymnasium as gym
    import uvnav

    env = gym.make("uvnav/Nav2D-v0", scenario="office-floor")

or, with no import of uvnav, the ``module:`` form (Gymnasium imports the module first)::

    env = gym.make("uvnav.envs:uvnav/Nav2D-v0", scenario="office-floor")

Importing this package registers the three envs with gymnasium (when it is installed);
:func:`register_envs` does it (idempotent) and is also the ``gymnasium.envs`` entry point
declared in pyproject.toml, which only gymnasium < 1.0 loads at its own import.

The 2D envs step the simulator's worlds (:mod:`uvnav.envs.core`): ``Nav2DEnv(...,
raw_commands=True)`` driven by a law's commands gives :func:`uvnav.sim.run_episode`'s episode bit
for bit (``reset(options={"episode_seed": k})`` is ``uvnav simulate SCENE --seed k``).
"""

from __future__ import annotations

import contextlib
from typing import Any

from uvnav.envs.policy import ControllerPolicy, as_policy

ENV_IDS = ("uvnav/Nav2D-v0", "uvnav/Nav3D-v0", "uvnav/UUV2D-v0")
_ENTRY_POINTS = {
    "uvnav/Nav2D-v0": "uvnav.envs.nav2d:Nav2DEnv",
    "uvnav/Nav3D-v0": "uvnav.envs.nav3d:Nav3DEnv",
    "uvnav/UUV2D-v0": "uvnav.envs.uuv2d:Uuv2DEnv",
}
_VECTOR_ENTRY_POINTS = {"uvnav/Nav2D-v0": "uvnav.envs.nav2d_vec:Nav2DVectorEnv"}


def register_envs() -> None:
    """Register the uvnav envs (:data:`ENV_IDS`) with gymnasium (idempotent)."""
    import gymnasium

    for env_id in ENV_IDS:
        if env_id not in gymnasium.registry:
            gymnasium.register(
                id=env_id,
                entry_point=_ENTRY_POINTS[env_id],
                vector_entry_point=_VECTOR_ENTRY_POINTS.get(env_id),
                disable_env_checker=False,
            )


def __getattr__(name: str) -> Any:
    if name == "Nav2DEnv":
        from uvnav.envs.nav2d import Nav2DEnv

        return Nav2DEnv
    if name == "Nav2DVectorEnv":
        from uvnav.envs.nav2d_vec import Nav2DVectorEnv

        return Nav2DVectorEnv
    if name == "Nav3DEnv":
        from uvnav.envs.nav3d import Nav3DEnv

        return Nav3DEnv
    if name == "Uuv2DEnv":
        from uvnav.envs.uuv2d import Uuv2DEnv

        return Uuv2DEnv
    if name == "MultiNav2DParallelEnv":
        from uvnav.envs.multi_robot import MultiNav2DParallelEnv

        return MultiNav2DParallelEnv
    raise AttributeError(name)


# without gymnasium the envs are unavailable and the rest of uvnav works
with contextlib.suppress(ImportError):
    register_envs()

__all__ = ["ENV_IDS", "ControllerPolicy", "as_policy", "register_envs"]
