"""Any uvnav controller as a Gymnasium / PettingZoo policy (issue 9).

:func:`as_policy` wraps a :class:`~uvnav.controllers.Controller` into ``policy(obs, info) ->
action``.  The controller sees exactly what it sees in the simulator — the
:class:`~uvnav.sensors.Observation` the env puts in ``info["uvnav"]``
(:class:`~uvnav.envs.core.ControllerView`; a controller never reads the flat observation
vector, which is for learned policies) — and its command is mapped to
the env's normalised action (the inverse of :meth:`uvnav.envs.core.EnvWorld.command`, float32,
so not exact; for the Chapter 3 / 4 envs the view's own ``to_action``,
:class:`uvnav.envs.common.SimView`), so a learned policy and the thesis's laws are run on equal
terms, on the same env.  On a 2D env made with ``raw_commands=True`` the command itself is the
action (float64, unclipped), and the episode is bit for bit the simulator's (given the same law
generator).  A law is named
from any registry: the 2D laws, the 3D laws (``uvnav/Nav3D-v0``) or the Chapter-4 UUV laws
(``uvnav/UUV2D-v0``).  The controller is
reset whenever a new episode starts (the observation's time is 0 or goes back).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from uvnav.controllers.base import Controller


class ControllerPolicy:
    """A controller driving an env: ``policy(obs, info) -> action`` (see :func:`as_policy`)."""

    def __init__(self, controller: Controller | Any, seed: int = 0) -> None:
        self.controller = controller
        self._rng = np.random.default_rng(seed)
        self._last_t: float | None = None

    def __call__(self, obs: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        view = info["uvnav"]
        o = view.observation
        spec = view.spec
        if self._last_t is None or o.time <= self._last_t - 1e-12 or o.time == 0.0:
            self.controller.reset(spec, np.asarray(o.goal, dtype=float), self._rng.spawn(1)[0])
        self._last_t = float(o.time)
        to_action = getattr(view, "to_action", None)
        if to_action is not None:  # the Chapter 3 / 4 envs: their own inverse action map
            return np.asarray(to_action(self.controller.act(o)), dtype=np.float32)
        if getattr(view, "raw_commands", False):  # the command itself, exactly
            raw = self.controller.act(o)
            return np.array([raw.v, raw.u], dtype=float)
        cmd = self.controller.act(o).clipped(spec)
        a0 = 2.0 * cmd.v / spec.v_max - 1.0
        a1 = cmd.u / spec.u_max
        return np.clip(np.array([a0, a1], dtype=np.float32), -1.0, 1.0)


def make_any_controller(name: str, **params: Any) -> Any:
    """A registered law by name, whatever vehicle it drives (unicycle, 3D or Chapter-4 UUV).

    Raises:
        uvnav.controllers.UnknownControllerError: not registered (a ``KeyError``).
    """
    from uvnav.controllers.base import controller_info, make_controller
    from uvnav.controllers.base3d import make_controller3d
    from uvnav.controllers.zhang2022_uuv2d import make_uuv2d_controller

    builders = {
        "unicycle": make_controller,
        "vehicle3d": make_controller3d,
        "uuv2d": make_uuv2d_controller,
    }
    return builders[controller_info(name).vehicle](name, **params)


def as_policy(controller: Any, seed: int = 0, **params: Any) -> ControllerPolicy:
    """``policy(obs, info) -> action`` driven by ``controller`` (an instance, or a registered
    name — 2D, 3D or Chapter-4 UUV law — with ``params``)."""
    if isinstance(controller, str):
        controller = make_any_controller(controller, **params)
    return ControllerPolicy(controller, seed)
