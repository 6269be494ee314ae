"""Any uvnav controller as a Gymnasium / PettingZoo policy (issue 9).

:func:`as_policy` wraps a :class:`~uvnav.controllers.Controller` into ``policy(obs, info) ->
action``.  The controller sees exactly what it sees in the simulator — the
:class:`~uvnav.sensors.Observation` the env puts in ``info["uvnav"]``
(:class:`~uvnav.envs.core.ControllerView`; a controller never reads the flat observation
vector, which is for learned policies) — and its command is mapped to
the env's normalised action (the inverse of :meth:`uvnav.envs.core.NavWorld.command`), so a
learned policy and the thesis's laws are run on equal terms, on the same env.  The controller is
reset whenever a new episode starts (the observation's time is 0 or goes back).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from uvnav.controllers.base import Controller


class ControllerPolicy:
    """A controller driving an env: ``policy(obs, info) -> action`` (see :func:`as_policy`)."""

    def __init__(self, controller: Controller, seed: int = 0) -> None:
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
        cmd = self.controller.act(o).clipped(spec)
        a0 = 2.0 * cmd.v / spec.v_max - 1.0
        a1 = cmd.u / spec.u_max
        return np.clip(np.array([a0, a1], dtype=np.float32), -1.0, 1.0)


def as_policy(controller: Controller | str, seed: int = 0, **params: Any) -> ControllerPolicy:
    """``policy(obs, info) -> action`` driven by ``controller`` (an instance, or a registered
    name with ``params``)."""
    if isinstance(controller, str):
        from uvnav.controllers.base import make_controller

        controller = make_controller(controller, **params)
    return ControllerPolicy(controller, seed)
