"""Planar underwater vehicle (UUV) of thesis Ch. 4, eqs. (4.1)-(4.7).

Reference: Y. Zhang, *Algorithms of Real-Time Navigation and Control of Autonomous Unmanned
Vehicles*, UNSW — Chapter 4, §4.2 (Y. Zhang and J. Zhang, ICCAE 2022):

    c(t) = [x(t), y(t)]                         (4.1)
    c'(t) = V(t) a(t)                           (4.2)
    V(t)^2 = V_X(t)^2 + V_Y(t)^2                (4.3)
    V_X(t) in [0, V_max],  V_Y(t) in [0, V_max] (4.4), (4.5)
    a(t) in [-U_max, U_max]                     (4.6)
    V(t) in [0, sqrt(2) V_max]                  (4.7)

How (4.4)-(4.6) are read (docs/thesis-notes.md, Chapter 4):

* (4.4)-(4.5) literally allow only non-negative components, i.e. motion into the first quadrant
  (which happens to suffice for the chapter's scene I = [0, 0] -> E = [10, 10]).  They are read
  as the *box* bound |V_X|, |V_Y| <= V_max on the world-frame velocity; that is what makes (4.7)
  (||V|| <= sqrt(2) V_max) true and lets the vehicle detour in any direction.  The fastest speed
  along direction phi is V_max / max(|cos phi|, |sin phi|) (:func:`max_speed_along`): V_max along
  an axis, sqrt(2) V_max along a diagonal.
* (4.6) bounds a(t), which (4.2) makes the unit orientation vector, by a scalar; it is read as the
  bounded *turn* of the orientation, |d theta / dt| <= U_max with a = [cos theta, sin theta].
  Commands are world-frame velocity vectors (DESIGN §2, "a velocity vector for holonomic
  vehicles"), held over a decision period T; (4.2) makes the orientation the direction of the
  velocity, so between two decisions the direction of a non-zero command may turn by at most
  U_max T.  A zero command keeps the orientation.
* Integration is exact for piecewise-constant commands (straight motion at constant velocity).

The simulator clips nothing silently: :meth:`HolonomicCommand.violates` counts commands outside the
limits and :meth:`HolonomicCommand.clipped` saturates them (the turn to U_max T, then the speed to
the box along the new direction).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from uvnav.geometry.angles import FloatArray, wrap_scalar

#: below this speed [m/s] a command has no direction (the orientation is kept)
SPEED_EPS = 1e-9


@dataclass(frozen=True, slots=True)
class HolonomicSpec:
    """Limits and size of the planar UUV.

    Attributes:
        v_max: V_max, bound of each world velocity component [m/s] (> 0).
        u_max: U_max, bound of the orientation's turn rate [rad/s] (> 0).
        radius: radius of the vehicle's disc body [m] (>= 0).
    """

    v_max: float
    u_max: float
    radius: float = 0.2


@dataclass(frozen=True, slots=True)
class HolonomicCommand:
    """World-frame velocity ``(vx, vy)`` [m/s] held until the next decision."""

    vx: float
    vy: float

    @property
    def speed(self) -> float:
        """||V|| [m/s]."""
        return math.hypot(self.vx, self.vy)

    def violates(
        self, spec: HolonomicSpec, heading: float, period: float, *, tol: float = 1e-9
    ) -> bool:
        """True when the command breaks the box (4.4)-(4.5) or turns the orientation by more than
        U_max ``period`` [s] from ``heading`` [rad] (4.6)."""
        if not (math.isfinite(self.vx) and math.isfinite(self.vy)):
            return True
        if abs(self.vx) > spec.v_max + tol or abs(self.vy) > spec.v_max + tol:
            return True
        if self.speed <= SPEED_EPS:
            return False
        turn = abs(wrap_scalar(math.atan2(self.vy, self.vx) - heading))
        return turn > spec.u_max * period + 1e-9

    def clipped(self, spec: HolonomicSpec, heading: float, period: float) -> HolonomicCommand:
        """The command saturated: its direction turned to within U_max ``period`` of ``heading``,
        then its speed reduced to the box bound along that direction; non-finite -> 0."""
        vx, vy = float(self.vx), float(self.vy)
        if not (math.isfinite(vx) and math.isfinite(vy)):
            return HolonomicCommand(0.0, 0.0)
        s = math.hypot(vx, vy)
        if s <= SPEED_EPS:
            return HolonomicCommand(0.0, 0.0)
        ang = math.atan2(vy, vx)
        err = wrap_scalar(ang - heading)
        lim = spec.u_max * period
        if abs(err) > lim:
            ang = heading + math.copysign(lim, err)
        s = min(s, max_speed_along(ang, spec.v_max))
        vm = float(spec.v_max)
        cx = min(max(s * math.cos(ang), -vm), vm)  # guards the last ulp
        cy = min(max(s * math.sin(ang), -vm), vm)
        return HolonomicCommand(cx, cy)


def max_speed_along(angle: float, v_max: float) -> float:
    """Largest speed [m/s] along direction ``angle`` [rad] within the box |V_X|, |V_Y| <= V_max."""
    return float(v_max / max(abs(math.cos(angle)), abs(math.sin(angle))))


def velocity_toward(
    direction: float, speed: float, spec: HolonomicSpec, heading: float, period: float
) -> HolonomicCommand:
    """A command within the limits that goes along ``direction`` [rad] as fast as allowed, up to
    ``speed`` [m/s].

    The direction is first turned toward ``direction`` by at most U_max ``period``; the speed is
    then reduced by the cosine of the remaining error (the vehicle slows while it turns, and only
    creeps — 1 % of the allowed speed — while the wanted direction is more than 90 degrees away).
    """
    err = wrap_scalar(direction - heading)
    lim = spec.u_max * period
    ang = heading + max(-lim, min(lim, err))
    left = abs(wrap_scalar(direction - ang))
    cap = max_speed_along(ang, spec.v_max)
    s = min(max(speed, 0.0), cap) * max(math.cos(left), 0.01)
    vx, vy = s * math.cos(ang), s * math.sin(ang)
    vm = float(spec.v_max)
    return HolonomicCommand(min(max(vx, -vm), vm), min(max(vy, -vm), vm))


def holonomic_step(state: FloatArray, command: HolonomicCommand, dt: float) -> FloatArray:
    """Exact motion for ``dt`` [s] under a constant command.

    Args:
        state: ``[x, y, theta]`` ([m], [m], [rad]).
        command: the (already clipped) velocity.

    Returns:
        The new ``[x, y, theta]``; theta is the command's direction (kept for a zero command).
    """
    x, y, th = float(state[0]), float(state[1]), float(state[2])
    if command.speed > SPEED_EPS:
        th = math.atan2(command.vy, command.vx)
    return np.array([x + command.vx * dt, y + command.vy * dt, th])
