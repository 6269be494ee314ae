"""A holonomic (omnidirectional) disc robot with a speed bound: the robot of the crowd-navigation
benchmarks (C. Chen, Y. Liu, S. Kreiss, A. Alahi, "Crowd-robot interaction: crowd-aware robot
navigation with attention-based deep reinforcement learning", ICRA 2019, §IV-A: a holonomic robot
whose action is a velocity of norm at most its preferred speed).

    c'(t) = v(t),   ||v(t)|| <= V_max

The command is a world-frame velocity held over the decision period; integration is exact
(straight motion at constant velocity).  Unlike the Chapter-4 UUV (:mod:`uvnav.dynamics.holonomic`,
box bound (4.4)-(4.5) and a bounded turn (4.6)) the bound is a disc and the direction may change
at once.  The simulator counts a command outside the disc (``violates``) and scales it onto the
disc (``clipped``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, ClassVar

from uvnav.geometry.angles import wrap_scalar


@dataclass(frozen=True, slots=True)
class OmniSpec:
    """Limits and size of the holonomic robot.

    Attributes:
        v_max: speed bound V_max [m/s] (> 0).
        radius: radius of the robot's disc body [m] (>= 0).
        u_max: not a limit of this robot (kept so laws written for a heading can read it)
            [rad/s].
    """

    v_max: float
    radius: float = 0.1
    u_max: float = math.inf


@dataclass(frozen=True, slots=True)
class VelocityCommand:
    """World-frame velocity ``(vx, vy)`` [m/s] held until the next decision."""

    vx: float
    vy: float

    @property
    def speed(self) -> float:
        """||v|| [m/s]."""
        return math.hypot(self.vx, self.vy)

    def violates(self, spec: OmniSpec, *, tol: float = 1e-9) -> bool:
        """True when the command is not finite or faster than V_max."""
        if not (math.isfinite(self.vx) and math.isfinite(self.vy)):
            return True
        return self.speed > spec.v_max + tol

    def clipped(self, spec: OmniSpec) -> VelocityCommand:
        """The command scaled onto the V_max disc (non-finite -> 0)."""
        vx, vy = float(self.vx), float(self.vy)
        if not (math.isfinite(vx) and math.isfinite(vy)):
            return VelocityCommand(0.0, 0.0)
        s = math.hypot(vx, vy)
        if s <= spec.v_max:
            return VelocityCommand(vx, vy)
        k = spec.v_max / s
        return VelocityCommand(vx * k, vy * k)


def omni_advance(x: float, y: float, vx: float, vy: float, dt: float) -> tuple[float, float]:
    """Exact position after ``dt`` [s] at constant velocity ``(vx, vy)`` [m/s].

    >>> omni_advance(1.0, 2.0, 0.5, -1.0, 2.0)
    (2.0, 0.0)
    """
    return x + vx * dt, y + vy * dt


class OmniRobot:
    """The holonomic robot as a planar vehicle of the 2D world (:class:`uvnav.dynamics.vehicles.
    Vehicle2D`): the scene's V_max and radius, a velocity ``(vx, vy)`` within the V_max disc,
    exact straight motion; its heading is the direction of the last non-zero velocity, and the
    effort has no turn term.

    Args:
        robot: the scene's robot block (its ``v_max`` and ``radius`` apply).
    """

    name: ClassVar[str] = "holonomic"
    command_names: ClassVar[tuple[str, str]] = ("v_x [m/s]", "v_y [m/s]")

    def __init__(self, robot: Any) -> None:
        self.spec = OmniSpec(v_max=float(robot.v_max), radius=float(robot.radius))
        self.reset()

    def rest(self) -> VelocityCommand:
        return VelocityCommand(0.0, 0.0)

    def reset(self) -> None:
        self._cmd = self.rest()

    def hold(self, cmd: VelocityCommand) -> None:
        self._cmd = cmd

    def saturate(self, cmd: VelocityCommand, heading: float) -> tuple[VelocityCommand, bool]:
        return cmd.clipped(self.spec), cmd.violates(self.spec)

    def pair(self, cmd: VelocityCommand) -> tuple[float, float]:
        return cmd.vx, cmd.vy

    def command(self, a: float, b: float) -> VelocityCommand:
        return VelocityCommand(a, b)

    def bounds(self) -> tuple[tuple[float, float], tuple[float, float]]:
        v = self.spec.v_max
        return (-v, -v), (v, v)

    def speed(self) -> float:
        return float(self._cmd.speed)

    def velocity(self, heading: float) -> tuple[float, float]:
        return float(self._cmd.vx), float(self._cmd.vy)

    def speed_change(self, new: VelocityCommand, old: VelocityCommand) -> float:
        return float((new.vx - old.vx) ** 2 + (new.vy - old.vy) ** 2)

    def move(
        self, x: float, y: float, heading: float, dt: float, decision: bool, period: float
    ) -> tuple[float, float, float, float, float]:
        vx, vy = self._cmd.vx, self._cmd.vy
        turn = 0.0
        if vx != 0.0 or vy != 0.0:
            th = math.atan2(vy, vx)
            if th != heading:
                turn = abs(wrap_scalar(th - heading))
            heading = th
        nx, ny = omni_advance(x, y, vx, vy, dt)
        return nx, ny, heading, turn, 0.0

    def travel(self, dt: float) -> tuple[float, float]:
        return float(self._cmd.speed) * dt, 0.0
