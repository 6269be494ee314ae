"""3D nonholonomic vehicle (flying robot), thesis Chapter 3 eqs. (3.1)-(3.7).

    c_R' = V_R a_R,   a_R' = u_R,   ||a_R|| = 1,   (a_R, u_R) = 0,
    V_R in [0, V_max],   ||u_R|| <= U_max.

Reference: Y. Zhang, *Algorithms of Real-Time Navigation and Control of Autonomous Unmanned
Vehicles*, UNSW, Chapter 3 §3.2 (ICCAR 2020).  Chapter 5's underwater vehicle has the same model.

Integration is exact for a command held over a step: the heading moves along a great circle of the
unit sphere (rotation of a_R about the fixed axis a_R x u_R by ||u_R|| dt) and the position
integrates V_R a_R(t) along it in closed form (:func:`uvnav.geometry.frames3d.rotate_on_sphere`,
:func:`~uvnav.geometry.frames3d.arc_displacement`).  During the hold, u_R(t) rotates with a_R so
that (a_R, u_R) = 0 and ||u_R|| stay exact — the held command is the angular velocity
a_R x u_R.  The
heading is renormalised every step (a projection the exact flow leaves unchanged), so ||a_R|| = 1
to rounding over any number of steps (tested over 10^5 steps to 1e-12).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.frames3d import arc_displacement, check_unit, rotate_on_sphere

#: tolerance of the orthogonality check (a, u) = 0, relative to max(1, ||u||)
ORTHO_TOL = 1e-9


@dataclass(frozen=True, slots=True)
class Vehicle3DSpec:
    """Limits and size of the 3D vehicle.

    Attributes:
        v_max: maximum speed V_max [m/s] (> 0).
        u_max: maximum turn rate U_max [rad/s] (> 0), bound on ||u_R||.
        radius: radius of the robot's spherical body [m] (>= 0).
    """

    v_max: float
    u_max: float
    radius: float = 0.1

    def __post_init__(self) -> None:
        for name in ("v_max", "u_max"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a number > 0 (got {value!r})")
        if not (math.isfinite(self.radius) and self.radius >= 0):
            raise ValueError(f"radius must be a number >= 0 (got {self.radius!r})")


@dataclass(frozen=True, slots=True)
class Vehicle3DState:
    """Position c_R [m] (3,) and unit heading a_R (3,)."""

    position: FloatArray
    heading: FloatArray


@dataclass(frozen=True, slots=True)
class Vehicle3DCommand:
    """Speed ``v`` = V_R [m/s] and turn vector ``u`` = u_R [rad/s] (3,), orthogonal to a_R."""

    v: float
    u: FloatArray

    def violates(self, spec: Vehicle3DSpec, heading: FloatArray, *, tol: float = 1e-9) -> bool:
        """True when the command breaks (3.4)-(3.6) for the current ``heading``."""
        u = np.asarray(self.u, dtype=float)
        if not (math.isfinite(self.v) and np.all(np.isfinite(u))):
            return True
        nu = float(np.linalg.norm(u))
        return bool(
            self.v < -tol
            or self.v > spec.v_max + tol
            or nu > spec.u_max + tol
            or abs(float(u @ heading)) > ORTHO_TOL * max(1.0, nu)
        )

    def clipped(self, spec: Vehicle3DSpec, heading: FloatArray) -> Vehicle3DCommand:
        """What the vehicle can do: V_R saturated to [0, V_max], u_R projected orthogonal to a_R
        and scaled to ||u_R|| <= U_max; non-finite values become 0."""
        v = float(self.v)
        v = min(max(v, 0.0), spec.v_max) if math.isfinite(v) else 0.0
        u = np.asarray(self.u, dtype=float)
        if not np.all(np.isfinite(u)) or u.shape != (3,):
            return Vehicle3DCommand(v, np.zeros(3))
        u = u - float(u @ heading) * heading
        nu = float(np.linalg.norm(u))
        if nu > spec.u_max:
            u = u * (spec.u_max / nu)
        return Vehicle3DCommand(v, u)


def check_command(heading: FloatArray, u: FloatArray) -> FloatArray:
    """``u`` as a (3,) array, or ``ValueError`` if it is not orthogonal to the unit ``heading``.

    Raises:
        ValueError: "u must be orthogonal to a: (a, u) = ..." naming the offending product.
    """
    uu = np.asarray(u, dtype=float)
    if uu.shape != (3,) or not np.all(np.isfinite(uu)):
        raise ValueError(f"u must be a finite 3-vector (got {np.asarray(u).tolist()!r})")
    dot = float(uu @ heading)
    if abs(dot) > ORTHO_TOL * max(1.0, float(np.linalg.norm(uu))):
        raise ValueError(f"u must be orthogonal to the heading a: (a, u) = {dot:.3g}, not 0")
    return uu


def vehicle3d_advance(
    position: FloatArray, heading: FloatArray, v: float, u: FloatArray, dt: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """One exact step without input checks (the simulator's inner loop; see :func:`vehicle3d_step`).

    Returns:
        ``(position, heading, u)`` after ``dt`` [s]; ``u`` is the held turn vector at the end of the
        step (rotated with the heading), to be used for the next step of the same hold.
    """
    disp = arc_displacement(heading, u, v, dt)
    a_new, u_new = rotate_on_sphere(heading, u, dt)
    return position + disp, a_new, u_new


def vehicle3d_step(state: Vehicle3DState, command: Vehicle3DCommand, dt: float) -> Vehicle3DState:
    """Exact motion (3.2)-(3.3) for ``dt`` [s] under ``command`` held (as an angular velocity).

    Raises:
        ValueError: the heading is not a unit vector, or ``command.u`` is not orthogonal to it
            (the limits (3.4)-(3.5) are the caller's to enforce; see
            :meth:`Vehicle3DCommand.clipped`).
    """
    a = check_unit(state.heading, name="heading")
    u = check_command(a, command.u)
    if not math.isfinite(dt) or dt < 0:
        raise ValueError(f"dt must be a number >= 0 (got {dt!r})")
    pos, a_new, _ = vehicle3d_advance(np.asarray(state.position, dtype=float), a, command.v, u, dt)
    return Vehicle3DState(position=pos, heading=a_new)
