"""Unicycle robot, thesis Ch. 2 eqs. (2.1)-(2.4).

    x' = V_R cos(theta),  y' = V_R sin(theta),  theta' = u_R,
    V_R in [0, V_max],  u_R in [-U_max, U_max].

Eq. (2.3) of the thesis reads ``theta' = u_R cos(theta)``; the ``cos(theta)`` is a typo (it would make
the robot unable to turn when heading along +-y, contradicting the rest of the chapter), so the
standard unicycle is used (docs/thesis-notes.md).  Integration is exact for piecewise-constant
commands (motion along a circular arc, written as the arc's chord so that it stays exact as
u -> 0), not Euler.
"""

from __future__ import annotations

from dataclasses import dataclass

import math

import numpy as np

from uvnav.geometry.angles import FloatArray, wrap_scalar

@dataclass(frozen=True)
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


@dataclass(frozen=True)
class UnicycleCommand:
    """Speed ``v`` [m/s] and angular velocity ``u`` [rad/s] of a unicycle."""

    v: float
    u: float

    def violates(self, spec: UnicycleSpec, *, tol: float = 1e-9) -> bool:
        """True when the command is outside the limits (2.4) of ``spec``."""
        return bool(self.v < -tol or self.v > spec.v_max + tol or abs(self.u) > spec.u_max + tol)

    def clipped(self, spec: UnicycleSpec) -> UnicycleCommand:
        """The command saturated to the limits (2.4); NaN components become 0."""
        v = 0.0 if not np.isfinite(self.v) else float(np.clip(self.v, 0.0, spec.v_max))
        u = 0.0 if not np.isfinite(self.u) else float(np.clip(self.u, -spec.u_max, spec.u_max))
        return UnicycleCommand(v, u)


def unicycle_step(state: FloatArray, v: float, u: float, dt: float) -> FloatArray:
    """Exact unicycle motion for ``dt`` [s] under constant ``v`` [m/s], ``u`` [rad/s].

    Args:
        state: ``[x, y, theta]`` ([m], [m], [rad]).

    Returns:
        The new ``[x, y, theta]`` with theta wrapped to (-pi, pi].
    """
    x, y, th = float(state[0]), float(state[1]), float(state[2])
    half = 0.5 * u * dt
    # chord of the arc, v dt sin(half)/half, along the mid-arc heading: exact for every turn rate,
    # with no cancellation near u = 0 (np.sinc(x) = sin(pi x) / (pi x))
    chord = v * dt * float(np.sinc(half / math.pi))
    x += chord * math.cos(th + half)
    y += chord * math.sin(th + half)
    return np.array([x, y, wrap_scalar(th + 2.0 * half)])
