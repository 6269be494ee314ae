"""A third-party vehicle in one file: a point robot with a bounded velocity command, and a law
that drives it (the test plug-in of ``tests/plugins/test_plugins_vehicle.py``).

Its package would declare, and the test writes into a ``.dist-info`` folder::

    [uvnav.vehicles]
    point = point_robot:PointRobot
    [uvnav.controllers]
    point-straight-v1 = point_robot:POINT_STRAIGHT

The robot moves at ``(vx, vy)`` with each component within [-V_max, V_max] (a box, not the
holonomic robot's disc); it senses as the 2D world's robot does (exact readings).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from uvnav.controllers.base import ControllerInfo


@dataclass(frozen=True)
class PointSpec:
    """The point robot's limits: ``v_max`` per component [m/s], disc ``radius`` [m]."""

    v_max: float
    radius: float


@dataclass(frozen=True)
class Velocity:
    """World-frame velocity command [m/s]."""

    vx: float
    vy: float


class PointRobot:
    """The point robot as a planar vehicle (``uvnav.dynamics.vehicles.Vehicle2D``'s members)."""

    name: ClassVar[str] = "point"
    command_names: ClassVar[tuple[str, str]] = ("v_x [m/s]", "v_y [m/s]")

    def __init__(self, robot: Any) -> None:
        self.spec = PointSpec(float(robot.v_max), float(robot.radius))
        self.held = self.rest()

    def rest(self) -> Velocity:
        return Velocity(0.0, 0.0)

    def reset(self) -> None:
        self.held = self.rest()

    def hold(self, cmd: Velocity) -> None:
        self.held = cmd

    def saturate(self, cmd: Velocity, heading: float) -> tuple[Velocity, bool]:
        vx, vy, v = float(cmd.vx), float(cmd.vy), self.spec.v_max
        if not (math.isfinite(vx) and math.isfinite(vy)):
            return Velocity(0.0, 0.0), True
        out = Velocity(min(max(vx, -v), v), min(max(vy, -v), v))
        return out, out != Velocity(vx, vy)

    def pair(self, cmd: Velocity) -> tuple[float, float]:
        return cmd.vx, cmd.vy

    def command(self, a: float, b: float) -> Velocity:
        return Velocity(a, b)

    def bounds(self) -> tuple[tuple[float, float], tuple[float, float]]:
        v = self.spec.v_max
        return (-v, -v), (v, v)

    def speed(self) -> float:
        return math.hypot(self.held.vx, self.held.vy)

    def velocity(self, heading: float) -> tuple[float, float]:
        return self.held.vx, self.held.vy

    def speed_change(self, new: Velocity, old: Velocity) -> float:
        return (new.vx - old.vx) ** 2 + (new.vy - old.vy) ** 2

    def move(
        self, x: float, y: float, heading: float, dt: float, decision: bool, period: float
    ) -> tuple[float, float, float, float, float]:
        return x + self.held.vx * dt, y + self.held.vy * dt, heading, 0.0, 0.0

    def travel(self, dt: float) -> tuple[float, float]:
        return self.speed() * dt, 0.0


class PointStraight:
    """Toward the goal at the box's top speed, slowing within one period of it; no avoidance."""

    name: ClassVar[str] = "point-straight-v1"

    def __init__(self) -> None:
        self.oracle = False
        self.spec = PointSpec(1.0, 0.1)
        self.goal = np.zeros(2)
        self._last = 0.0

    @property
    def mode(self) -> str:
        return "M1"

    def reset(self, spec: PointSpec, goal: np.ndarray, rng: np.random.Generator) -> None:
        self.spec, self.goal, self._last = spec, np.asarray(goal, dtype=float), 0.0

    def act(self, obs: Any) -> Velocity:
        period = max(obs.time - self._last, 0.1)
        self._last = obs.time
        gap = self.goal - np.asarray(obs.pose[:2], dtype=float)
        step = np.clip(gap / period, -self.spec.v_max, self.spec.v_max)
        return Velocity(float(step[0]), float(step[1]))


POINT_STRAIGHT = ControllerInfo(
    name="point-straight-v1",
    factory=PointStraight,
    params_type=None,
    summary="Point robot straight to the target (a test plug-in).",
    vehicle="point",
)
