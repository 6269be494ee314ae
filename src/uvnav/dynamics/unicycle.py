"""Unicycle robot, thesis Ch. 2 eqs. (2.1)-(2.4).

    x' = V_R cos(theta),  y' = V_R sin(theta),  theta' = u_R,
    V_R in [0, V_max],  u_R in [-U_max, U_max].

Eq. (2.3) of the thesis reads ``theta' = u_R cos(theta)``; the ``cos(theta)`` is a typo (it would
make the robot unable to turn when heading along +-y, contradicting the rest of the chapter), so
the standard unicycle is used (docs/thesis-notes.md).  Integration is exact for piecewise-constant
commands (motion along a circular arc, written as the arc's chord so that it stays exact as
u -> 0), not Euler.

Acceleration limits (``UnicycleSpec.accel_max`` [m/s^2], ``turn_accel_max`` [rad/s^2]; unbounded
by default, as in the thesis) make the vehicle's speed and turn rate states of their own: at
each integration step of ``dt`` they move toward the held command by at most ``accel_max dt``
and ``turn_accel_max dt`` (:func:`approach`), and the step integrates the arc under the values
reached (a staircase at the step's resolution, exact for it).  A law's command is then what the
vehicle aims at, not what it does; the observation reports the speed it has.

A second kinematics, ``turn-then-move`` (:data:`KINEMATICS`), is the unicycle of the CrowdNav
benchmark (Chen et al., ICRA 2019; CrowdSim's ``ActionRot``: ``theta += r``, then a straight move
at ``v`` for the time step): the turn of a whole decision period, ``u T``, happens at once when
the decision is taken, and the robot then moves straight along its new heading
(:func:`turn_then_move`).  The same command ``(v, u)`` and limits (2.4) drive both.  Under a
turn-rate limit the period's turn is the heading change the ramped turn rate makes over the
period (:func:`ramp_turn`: the arc's heading at the period's end, taken at once), whatever the
integration step; the turn rate itself ramps step by step as on the arc.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from uvnav.geometry.angles import FloatArray, wrap_scalar
from uvnav.geometry.sweep import arc_slack

_EPS = float(np.finfo(float).eps)

#: how a unicycle integrates a held command over a decision period: ``arc`` (the thesis's
#: continuous turn, exact) or ``turn-then-move`` (CrowdNav's ``ActionRot``)
KINEMATICS: tuple[str, ...] = ("arc", "turn-then-move")


@dataclass(frozen=True, slots=True)
class UnicycleSpec:
    """Limits and size of a unicycle robot.

    Attributes:
        v_max: maximum speed V_max [m/s] (> 0).
        u_max: maximum turn rate U_max [rad/s] (> 0).
        radius: radius of the robot's disc body [m] (>= 0).
        kinematics: ``arc`` or ``turn-then-move`` (:data:`KINEMATICS`, module docstring).
        accel_max: largest rate of change of the speed [m/s^2] (``inf``: the speed follows the
            command at once, the thesis's model).
        turn_accel_max: largest rate of change of the turn rate [rad/s^2] (``inf``: at once).
    """

    v_max: float
    u_max: float
    radius: float = 0.1
    kinematics: str = "arc"
    accel_max: float = math.inf
    turn_accel_max: float = math.inf

    def __post_init__(self) -> None:
        if self.kinematics not in KINEMATICS:
            raise ValueError(
                f"kinematics must be one of {', '.join(KINEMATICS)} (got {self.kinematics!r})"
            )
        for name in ("accel_max", "turn_accel_max"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be > 0 (got {getattr(self, name)!r})")

    @property
    def ideal(self) -> bool:
        """The speed and the turn rate follow the command at once (no acceleration limit)."""
        return math.isinf(self.accel_max) and math.isinf(self.turn_accel_max)


@dataclass(frozen=True, slots=True)
class UnicycleCommand:
    """Speed ``v`` [m/s] and angular velocity ``u`` [rad/s] of a unicycle."""

    v: float
    u: float

    def violates(self, spec: UnicycleSpec, *, tol: float = 1e-9) -> bool:
        """True when the command is outside the limits (2.4) of ``spec``."""
        return bool(self.v < -tol or self.v > spec.v_max + tol or abs(self.u) > spec.u_max + tol)

    def clipped(self, spec: UnicycleSpec) -> UnicycleCommand:
        """The command saturated to the limits (2.4); NaN and infinite components become 0.

        A command of two floats within the limits is returned as it is (the saturation would
        give the same numbers).
        """
        v, u = self.v, self.u
        if (
            type(v) is float
            and type(u) is float
            and 0.0 <= v <= spec.v_max
            and -spec.u_max <= u <= spec.u_max
        ):
            return self
        v = float(self.v)
        u = float(self.u)
        v = min(max(v, 0.0), float(spec.v_max)) if math.isfinite(v) else 0.0
        u = min(max(u, -float(spec.u_max)), float(spec.u_max)) if math.isfinite(u) else 0.0
        return UnicycleCommand(v, u)


def unicycle_advance(
    x: float, y: float, theta: float, v: float, u: float, dt: float
) -> tuple[float, float, float]:
    """:func:`unicycle_step` on plain floats: the new ``(x, y, theta)``, bit for bit the same."""
    half = 0.5 * u * dt
    # chord of the arc, v dt sin(half)/half, along the mid-arc heading: exact for every turn rate,
    # with no cancellation near u = 0; written as numpy's sinc(half / pi) = sin(y) / y with
    # y = pi * (half / pi) (machine epsilon at 0), as numpy computes it, to keep its numbers
    s = math.pi * (half / math.pi)
    if s == 0.0:
        s = _EPS
    chord = v * dt * (math.sin(s) / s)
    return (
        x + chord * math.cos(theta + half),
        y + chord * math.sin(theta + half),
        wrap_scalar(theta + 2.0 * half),
    )


def turn_then_move(
    x: float, y: float, theta: float, v: float, turn: float, dt: float
) -> tuple[float, float, float]:
    """CrowdNav's unicycle step: turn by ``turn`` [rad] at once, then move straight at ``v``
    [m/s] for ``dt`` [s]; the new ``(x, y, theta)``, theta wrapped to (-pi, pi].

    >>> [round(c, 12) for c in turn_then_move(0.0, 0.0, 0.0, 1.0, math.pi / 2, 0.25)]
    [0.0, 0.25, 1.570796326795]
    """
    th = wrap_scalar(theta + turn)
    return x + v * dt * math.cos(th), y + v * dt * math.sin(th), th


def ramp_turn(u_now: float, target: float, rate: float, period: float) -> float:
    """The heading change [rad] over ``period`` [s] of a turn rate that moves from ``u_now``
    toward ``target`` [rad/s] at ``rate`` [rad/s^2] (``inf``: at once) and then holds it.

    >>> ramp_turn(0.0, 1.0, math.inf, 0.25), ramp_turn(0.0, 1.0, 2.0, 0.25)  # at once; ramping
    (0.25, 0.0625)
    >>> ramp_turn(0.0, 0.2, 2.0, 0.25)  # reaches 0.2 rad/s after 0.1 s: 0.01 + 0.03
    0.04
    """
    if math.isinf(rate):
        return target * period
    gap = target - u_now
    ramp = min(abs(gap) / rate, period)
    u_end = u_now + math.copysign(rate * ramp, gap)
    if ramp < period:  # reaches the target, then holds it
        return 0.5 * (u_now + u_end) * ramp + target * (period - ramp)
    return 0.5 * (u_now + u_end) * period


def approach(value: float, target: float, most: float) -> float:
    """``value`` moved toward ``target`` by at most ``most`` (>= 0).

    >>> approach(0.0, 1.0, 0.1), approach(0.5, 0.45, 0.1), approach(0.0, -1.0, math.inf)
    (0.1, 0.45, -1.0)
    """
    if math.isinf(most):
        return target
    return value + min(max(target - value, -most), most)


def unicycle_step(state: FloatArray, v: float, u: float, dt: float) -> FloatArray:
    """Exact unicycle motion for ``dt`` [s] under constant ``v`` [m/s], ``u`` [rad/s].

    Args:
        state: ``[x, y, theta]`` ([m], [m], [rad]).

    Returns:
        The new ``[x, y, theta]`` with theta wrapped to (-pi, pi].
    """
    return np.array(unicycle_advance(float(state[0]), float(state[1]), float(state[2]), v, u, dt))


class Unicycle:
    """The unicycle as a planar vehicle of the 2D world (:class:`uvnav.dynamics.vehicles.
    Vehicle2D`): the command ``(V_R, u_R)`` within (2.4), moved by the robot block's
    ``kinematics`` and acceleration limits (module docstring); the effort's turn term is
    ``u_R^2 dt`` of the turn rate it has.

    Args:
        robot: limits, radius, kinematics and acceleration limits (the law is reset with it).
    """

    name: ClassVar[str] = "unicycle"
    command_names: ClassVar[tuple[str, str]] = ("V_R [m/s]", "u_R [rad/s]")

    def __init__(self, robot: UnicycleSpec) -> None:
        self.spec = robot
        self._ideal = robot.ideal
        self._arc = robot.kinematics == "arc"
        self.reset()

    def rest(self) -> UnicycleCommand:
        return UnicycleCommand(0.0, 0.0)

    def reset(self) -> None:
        self._cmd = self.rest()
        self._v, self._u = 0.0, 0.0  # the speed and turn rate it has

    def hold(self, cmd: UnicycleCommand) -> None:
        self._cmd = cmd
        if self._ideal:
            self._v, self._u = cmd.v, cmd.u

    def _next(self, dt: float) -> tuple[float, float]:
        """The speed and turn rate of the coming step of ``dt`` [s]."""
        cmd, s = self._cmd, self.spec
        if self._ideal:
            return cmd.v, cmd.u
        return approach(self._v, cmd.v, s.accel_max * dt), approach(
            self._u, cmd.u, s.turn_accel_max * dt
        )

    def saturate(self, cmd: UnicycleCommand, heading: float) -> tuple[UnicycleCommand, bool]:
        new = cmd.clipped(self.spec)
        # a command returned as it is lies within the limits: it violates none
        return new, new is not cmd and cmd.violates(self.spec)

    def pair(self, cmd: UnicycleCommand) -> tuple[float, float]:
        return cmd.v, cmd.u

    def command(self, a: float, b: float) -> UnicycleCommand:
        return UnicycleCommand(a, b)

    def bounds(self) -> tuple[tuple[float, float], tuple[float, float]]:
        s = self.spec
        return (0.0, -s.u_max), (s.v_max, s.u_max)

    def speed(self) -> float:
        return float(self._v)

    def turn_rate(self) -> float:
        """The turn rate it has now [rad/s]."""
        return float(self._u)

    def velocity(self, heading: float) -> tuple[float, float]:
        v = float(self._v)
        return v * math.cos(heading), v * math.sin(heading)

    def speed_change(self, new: UnicycleCommand, old: UnicycleCommand) -> float:
        return float((new.v - old.v) ** 2)

    def move(
        self, x: float, y: float, heading: float, dt: float, decision: bool, period: float
    ) -> tuple[float, float, float, float, float]:
        u_was = self._u
        v, u = self._v, self._u = self._next(dt)
        if self._arc:
            nx, ny, th = unicycle_advance(x, y, heading, v, u, dt)
        else:  # the period's turn at the decision (the ramp's, module docstring), then straight
            turn = (ramp_turn(u_was, self._cmd.u, self.spec.turn_accel_max, period)
                    if decision else 0.0)  # fmt: skip
            nx, ny, th = turn_then_move(x, y, heading, v, turn, dt)
        return nx, ny, th, abs(u) * dt, u**2 * dt

    def travel(self, dt: float) -> tuple[float, float]:
        if self._ideal:  # (self._next, inline)
            cmd = self._cmd
            v, u = cmd.v, cmd.u
        else:
            v, u = self._next(dt)
        slack = arc_slack(v, u, dt) if self._arc else 0.0
        return abs(v) * dt, slack
