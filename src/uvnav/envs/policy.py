"""Any uvnav controller as a Gymnasium / PettingZoo policy.

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
        body = getattr(view, "vehicle", None)
        if body is not None:  # a planar vehicle other than the unicycle: its command box
            return vehicle_action(body, self.controller.act(o), float(o.pose[2]),
                                  view.raw_commands)  # fmt: skip
        if getattr(view, "raw_commands", False):  # the command itself, exactly
            raw = self.controller.act(o)
            return np.array([raw.v, raw.u], dtype=float)
        cmd = self.controller.act(o).clipped(spec)
        a0 = 2.0 * cmd.v / spec.v_max - 1.0
        a1 = cmd.u / spec.u_max
        return np.clip(np.array([a0, a1], dtype=np.float32), -1.0, 1.0)


def vehicle_action(body: Any, cmd: Any, heading: float, raw: bool) -> np.ndarray:
    """A planar vehicle's command as an env action: its two numbers (float64) when ``raw``,
    else the saturated command placed in [-1, 1]^2 over the vehicle's command box (float32; the
    inverse of :func:`uvnav.envs.core.box_command`)."""
    if raw:
        return np.array(body.pair(cmd), dtype=float)
    low, high = (np.asarray(b, dtype=float) for b in body.bounds())
    sat, _ = body.saturate(cmd, heading)
    a = 2.0 * (np.asarray(body.pair(sat), dtype=float) - low) / (high - low) - 1.0
    return np.clip(a.astype(np.float32), -1.0, 1.0)


def check_env_law(env: Any, name: str) -> None:
    """Refuse a registered law that cannot drive ``env``'s scene, or whose declared assumptions
    the scene breaks (thesis (2.6)): the check of ``uvnav simulate`` and ``uvnav bench``
    (:func:`uvnav.scenarios.episodes.check_law`), on the env's scenario.  An env that draws a new
    scene at every reset (a generator name without a seed) is checked on its first scene.

    Raises:
        uvnav.scenarios.episodes.LawMismatchError: another vehicle or sensor.
        uvnav.scenarios.ScenarioError: the scene breaks the law's assumption.
    """
    from pydantic import BaseModel

    from uvnav.scenarios.catalog import Resolved, infer_kind, kinds
    from uvnav.scenarios.episodes import check_law

    scenario = getattr(getattr(env, "unwrapped", env), "scenario", None)
    if not isinstance(scenario, BaseModel):
        return
    kind = kinds()[infer_kind(scenario)]
    check_law(Resolved(kind, scenario, str(getattr(scenario, "name", "env")), None), name)


def as_policy(
    controller: Any, seed: int = 0, *, env: Any = None, **params: Any
) -> ControllerPolicy:
    """``policy(obs, info) -> action`` driven by ``controller`` (an instance, or a registered
    name of any vehicle's law with ``params``).  With ``env``, a named law is first checked
    against the env's scene (:func:`check_env_law`)."""
    if isinstance(controller, str):
        from uvnav.controllers.base import make_law

        if env is not None:
            check_env_law(env, controller)
        controller = make_law(controller, **params)
    return ControllerPolicy(controller, seed)
