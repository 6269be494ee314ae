"""Unicycle robot, thesis Ch. 2 eqs. (2.1)-(2.4).

    x' = V_R cos(theta),  y' = V_R sin(theta),  theta' = u_R,
    V_R in [0, V_max],  u_R in [-U_max, U_max].

Eq. (2.3) of the thesis reads ``theta' = u_R cos(theta)``; the ``cos(theta)`` is a typo (it would
make the robot unable to turn when heading along +-y, contradicting the rest of the chapter), so
the standard unicycle is used (docs/thesis-notes.md).  Integration is exact for piecewise-constant
commands (motion along a circular arc, written as the arc's chord so that it stays exact as
u -> 0), not Euler.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from uvnav.geometry.angles import FloatArray, wrap_scalar

_EPS = float(np.finfo(float).eps)


@dataclass(frozen=True, slots=True)
class UnicycleSpec:
    """Limits and size of a unicycle robot.

    Attributes:
        v_max: maximum speed V_max [m/s] (> 0).
        u_max: maximum turn rate U_max [rad/s] (> 0).
        radius: radius of the robot's disc body [m] (>= 0).
    """

    v_max: float
    u_max: float
    radius: float = 0.1


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


def unicycle_step(state: FloatArray, v: float, u: float, dt: float) -> FloatArray:
    """Exact unicycle motion for ``dt`` [s] under constant ``v`` [m/s], ``u`` [rad/s].

    Args:
        state: ``[x, y, theta]`` ([m], [m], [rad]).

    Returns:
        The new ``[x, y, theta]`` with theta wrapped to (-pi, pi].
    """
    return np.array(unicycle_advance(float(state[0]), float(state[1]), float(state[2]), v, u, dt))
