"""Controller contract and registry for the 3D vehicle (DESIGN §2; thesis Chapters 3 and 5).

A 3D law is reset with the vehicle's limits (:class:`~uvnav.dynamics.vehicle3d.Vehicle3DSpec`),
the goal and a generator, and asked for a :class:`~uvnav.dynamics.vehicle3d.Vehicle3DCommand`
``(V_R, u_R)`` with nothing but an :class:`~uvnav.sensors.sensing3d.Observation3D`.

3D laws live in the one registry of :mod:`uvnav.controllers.base` with ``vehicle="vehicle3d"``
(``register``, ``make_law``, ``available_controllers("vehicle3d")``; the unicycle views leave
them out: a 3D law cannot take a 2D observation).
"""

from __future__ import annotations

import math
from typing import ClassVar, Protocol, runtime_checkable

import numpy as np

from uvnav.controllers.base import LawState
from uvnav.dynamics.vehicle3d import Vehicle3DCommand, Vehicle3DSpec
from uvnav.geometry.angles import FloatArray
from uvnav.geometry.frames3d import turn_toward
from uvnav.sensors.sensing3d import Observation3D


@runtime_checkable
class Controller3D(Protocol):
    """A navigation law for the 3D vehicle."""

    name: ClassVar[str]
    oracle: bool

    def reset(self, spec: Vehicle3DSpec, goal: np.ndarray, rng: np.random.Generator) -> None: ...

    def act(self, obs: Observation3D) -> Vehicle3DCommand: ...

    @property
    def mode(self) -> str: ...


class Vehicle3DController(LawState[Vehicle3DSpec]):
    """:class:`~uvnav.controllers.base.LawState` of the 3D laws, and the M1 approach law."""

    def __init__(self) -> None:
        super().__init__(Vehicle3DSpec(1.0, 1.0), 3)

    def steer(
        self, obs: Observation3D, direction: FloatArray, speed: float, period: float
    ) -> Vehicle3DCommand:
        """Command turning the heading toward ``direction`` at the bounded rate (orthogonal to
        a_R by construction) with speed ``speed`` clipped to [0, V_max]."""
        a = np.asarray(obs.heading, dtype=float)
        u = turn_toward(a, direction, self._spec.u_max, period)
        v = min(max(float(speed), 0.0), self._spec.v_max) if math.isfinite(speed) else 0.0
        return Vehicle3DCommand(v, u)

    def approach(self, obs: Observation3D, period: float) -> Vehicle3DCommand:
        """M1 (3.11)-(3.12): V_max straight to E; when not facing E the heading turns toward it
        at the bounded rate, slowing where E lies inside the minimum turning circle."""
        gap = self._goal - obs.position
        dist = float(np.linalg.norm(gap))
        if dist < 1e-9:
            return Vehicle3DCommand(0.0, np.zeros(3))
        cos_e = float(np.clip(gap @ obs.heading / dist, -1.0, 1.0))
        err = math.acos(cos_e)
        v = self._spec.v_max
        # keep E outside the turning circle of radius V / U (a circle through the robot tangent
        # to a_R contains E when dist < 2 R sin(err)); slow down so that it does not
        if err > 1e-6:
            v_fit = self._spec.u_max * dist / (2.0 * math.sin(err)) if err < math.pi / 2 else 0.0
            v = min(v, max(v_fit, 0.2 * self._spec.v_max))
        return self.steer(obs, gap, v, period)
