"""Gymnasium / PettingZoo environments (layer 6; issue 9).

* ``uvnav/Nav2D-v0`` (:class:`uvnav.envs.nav2d.Nav2DEnv`): one robot on a uvnav scenario.
* :class:`uvnav.envs.multi_robot.MultiNav2DParallelEnv`: a PettingZoo ``ParallelEnv`` of several
  robots on a multi-robot scenario (``antipodal:4`` ...).
* :func:`as_policy`: any uvnav controller as a policy for them.

gymnasium and pettingzoo (``uvnav[envs]``) are imported only when an env class is used.
Registration: importing this package registers ``uvnav/Nav2D-v0`` with gymnasium (when it is
installed), so ``gymnasium.make("uvnav.envs:uvnav/Nav2D-v0")`` works from anywhere;
:func:`register_envs` is also the ``gymnasium.envs`` entry point declared in pyproject.toml
(gymnasium < 1.0 loads that group at import; gymnasium 1.x dropped plugin loading, hence the
``module:`` form or ``import uvnav.envs``).  Nav3D and UUV2D envs are future work (their worlds
live in the 3D/UUV chapters' modules).
"""

from __future__ import annotations

import contextlib
from typing import Any

from uvnav.envs.policy import ControllerPolicy, as_policy

ENV_IDS = ("uvnav/Nav2D-v0",)


def register_envs() -> None:
    """Register ``uvnav/Nav2D-v0`` with gymnasium (idempotent)."""
    import gymnasium

    if "uvnav/Nav2D-v0" not in gymnasium.registry:
        gymnasium.register(
            id="uvnav/Nav2D-v0",
            entry_point="uvnav.envs.nav2d:Nav2DEnv",
            disable_env_checker=False,
        )


def __getattr__(name: str) -> Any:
    if name == "Nav2DEnv":
        from uvnav.envs.nav2d import Nav2DEnv

        return Nav2DEnv
    if name == "MultiNav2DParallelEnv":
        from uvnav.envs.multi_robot import MultiNav2DParallelEnv

        return MultiNav2DParallelEnv
    raise AttributeError(name)


# without gymnasium the envs are unavailable and the rest of uvnav works
with contextlib.suppress(ImportError):
    register_envs()

__all__ = ["ENV_IDS", "ControllerPolicy", "as_policy", "register_envs"]
