"""3D frames and rotations: exact rotation on the sphere of headings, SO(3) exp/log, the thesis's
on-line frame, and the turn toward a direction.

Reference: Y. Zhang, *Algorithms of Real-Time Navigation and Control of Autonomous Unmanned
Vehicles*, UNSW — Chapter 3 ("Collision-free Navigation of Flying Robots in Outdoor Environments
with Dynamic Obstacles", ICCAR 2020), eqs. (3.1)-(3.7) (unit heading a_R, turn vector u_R with
(a_R, u_R) = 0), §3.3.2 (the on-line coordinate (X', Y')), eq. (3.17) (forecast sphere).

Rotations are written here (Rodrigues' formula and its inverse) rather than taken from
``scipy.spatial.transform.Rotation`` because they run once per integration step per obstacle and
the scipy object costs about 10x more per call; the test suite checks them against scipy.

On-line frame (§3.3.2): origin at the robot, Y' toward the end point E, X' *horizontal* and
perpendicular to Y'.  The thesis leaves X' undefined when E is straight above or below the robot
(Y' vertical); then X' is taken as the previous X' projected off Y' (continuity), or world +x when
there is none (docs/thesis-notes.md).  X' = Y' x z / ||Y' x z|| (points to the right of Y' seen
from above, so that (X', Y', Z') with Z' = X' x Y' is right-handed and Z' points up).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from uvnav.geometry.angles import FloatArray


def rotation_from_vector(rotvec: FloatArray) -> FloatArray:
    """exp([r]x): rotation by ||r|| [rad] about r / ||r|| (Rodrigues); identity for r = 0."""
    r = np.asarray(rotvec, dtype=float)
    x, y, z = float(r[0]), float(r[1]), float(r[2])
    theta = math.sqrt(x * x + y * y + z * z)
    if theta < 1e-12:
        return np.array([[1.0, -z, y], [z, 1.0, -x], [-y, x, 1.0]])
    # I + sin(t) K + (1 - cos(t)) K^2 with K = [k]x and K^2 = k k^T - I, on plain floats (one
    # array built instead of five numpy operations: this runs per obstacle per step)
    kx, ky, kz = x / theta, y / theta, z / theta
    s, c = math.sin(theta), 1.0 - math.cos(theta)
    return np.array(
        [
            [1.0 + c * (kx * kx - 1.0), c * kx * ky - s * kz, c * kx * kz + s * ky],
            [c * kx * ky + s * kz, 1.0 + c * (ky * ky - 1.0), c * ky * kz - s * kx],
            [c * kx * kz - s * ky, c * ky * kz + s * kx, 1.0 + c * (kz * kz - 1.0)],
        ]
    )


def rotation_to_vector(rot: FloatArray) -> FloatArray:
    """log of a rotation matrix as a rotation vector [rad] (angle in [0, pi])."""
    m = np.asarray(rot, dtype=float)
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = m.tolist()
    cos_t = min(max((m00 + m11 + m22 - 1.0) * 0.5, -1.0), 1.0)
    theta = math.acos(cos_t)
    w = np.array([m21 - m12, m02 - m20, m10 - m01])
    if theta < 1e-6:
        return 0.5 * w  # first order; exact to O(theta^3)
    if math.pi - theta < 1e-6:
        # axis from the symmetric part: R = I + 2 k k^T - 2 I at theta = pi
        b = (m + np.eye(3)) * 0.5
        i = int(np.argmax(np.diag(b)))
        axis = b[:, i] / math.sqrt(max(b[i, i], 1e-300))
        axis /= np.linalg.norm(axis)
        return theta * axis
    return theta / (2.0 * math.sin(theta)) * w


def check_unit(a: FloatArray, *, name: str = "heading", tol: float = 1e-9) -> FloatArray:
    """``a`` as a float (3,) array, or ``ValueError`` naming ``name`` if it is not a unit vector."""
    v = np.asarray(a, dtype=float)
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise ValueError(f"{name} must be a finite 3-vector (got {np.asarray(a).tolist()!r})")
    norm = math.sqrt(float(v @ v))
    if abs(norm - 1.0) > tol:
        raise ValueError(
            f"{name} must be a unit vector (||{name}|| = {norm:.12g}, tolerance {tol:g})"
        )
    return v


def rotate_on_sphere(a: FloatArray, u: FloatArray, dt: float) -> tuple[FloatArray, FloatArray]:
    """Exact solution of a' = u(t), (a, u) = 0, with the turn held about the fixed axis a x u.

    Over ``dt`` [s] the heading moves along the great circle through ``a`` toward ``u``:
    ``a(dt) = a cos(w dt) + (u / w) sin(w dt)`` with ``w = ||u||`` [rad/s], and the turn vector
    becomes ``u(dt) = -w a sin(w dt) + u cos(w dt)`` (still orthogonal to ``a(dt)``, same norm).

    Returns:
        ``(a(dt), u(dt))``; ``a(dt)`` is renormalised (a projection onto the sphere, which the exact
        flow preserves), so its norm is 1 to rounding however many steps are taken.
    """
    w = math.sqrt(float(u @ u))
    theta = w * dt
    if w == 0.0:
        return a.copy(), u.copy()
    c, s = math.cos(theta), math.sin(theta)
    a_new = a * c + u * (s / w)
    u_new = u * c - a * (w * s)
    a_new = a_new / math.sqrt(float(a_new @ a_new))
    u_new = u_new - float(u_new @ a_new) * a_new  # keep (a, u) = 0 to rounding
    return a_new, u_new


def arc_displacement(a: FloatArray, u: FloatArray, v: float, dt: float) -> FloatArray:
    """Exact displacement [m] of c' = v a(t) while a turns as in :func:`rotate_on_sphere`.

    ``∫ a(s) ds = a sin(w dt)/w + (u/w) (1 - cos(w dt))/w``, written with sinc so that it stays
    exact as w -> 0 (it tends to ``a dt``).
    """
    w = math.sqrt(float(u @ u))
    half = 0.5 * w * dt
    sinc_half = math.sin(half) / half if half > 1e-12 else 1.0 - half * half / 6.0
    full = w * dt
    sinc_full = math.sin(full) / full if full > 1e-12 else 1.0 - full * full / 6.0
    # (1 - cos(w dt)) / w^2 = dt^2 / 2 * sinc(half)^2
    return v * (a * (dt * sinc_full) + u * (0.5 * dt * dt * sinc_half * sinc_half))


def horizontal_perpendicular(y_axis: FloatArray, previous: FloatArray | None = None) -> FloatArray:
    """X' of the on-line frame: horizontal, perpendicular to ``y_axis`` (a unit vector).

    ``X' = Y' x z / ||Y' x z||``.  When Y' is (nearly) vertical the previous X' projected off Y' is
    used (or world +x when there is none) — a choice the thesis leaves open.
    """
    y0, y1 = float(y_axis[0]), float(y_axis[1])
    n = math.hypot(y0, y1)  # ||Y' x z||, with Y' x z = (y1, -y0, 0)
    if n > 1e-6:
        return np.array([y1 / n, -y0 / n, 0.0])
    ref = np.array([1.0, 0.0, 0.0]) if previous is None else np.asarray(previous, dtype=float)
    x = ref - float(ref @ y_axis) * y_axis
    n = math.sqrt(float(x @ x))
    if n < 1e-9:
        ref = np.array([0.0, 1.0, 0.0])
        x = ref - float(ref @ y_axis) * y_axis
        n = math.sqrt(float(x @ x))
    return x / n


@dataclass(frozen=True)
class OnlineFrame:
    """The thesis's on-line frame (§3.3.2) at one decision time.

    Attributes:
        origin: robot position c_R [m], (3,).
        x_axis: X', horizontal, perpendicular to Y'.
        y_axis: Y', unit vector from the robot toward E.
        z_axis: Z' = X' x Y' (normal of the on-line plane).
    """

    origin: FloatArray
    x_axis: FloatArray
    y_axis: FloatArray
    z_axis: FloatArray

    @property
    def basis(self) -> FloatArray:
        """(3, 3) matrix whose rows are X', Y', Z'."""
        return np.stack([self.x_axis, self.y_axis, self.z_axis])

    def to_plane(self, points: FloatArray) -> FloatArray:
        """World points (..., 3) [m] -> (X', Y') coordinates (..., 2) (projection along Z')."""
        rel = np.asarray(points, dtype=float) - self.origin
        return np.stack([rel @ self.x_axis, rel @ self.y_axis], axis=-1)

    def vector_to_plane(self, vectors: FloatArray) -> FloatArray:
        """World vectors (..., 3) -> their (X', Y') components (..., 2)."""
        v = np.asarray(vectors, dtype=float)
        return np.stack([v @ self.x_axis, v @ self.y_axis], axis=-1)


def online_frame(
    position: FloatArray, goal: FloatArray, previous_x: FloatArray | None = None
) -> OnlineFrame:
    """The on-line frame at ``position`` toward ``goal`` [m] (see the module docstring).

    A robot exactly at the goal gets Y' = world +y (the frame is then irrelevant)."""
    p = np.asarray(position, dtype=float)
    g = np.asarray(goal, dtype=float)
    # scalar arithmetic on Python floats: a decision builds one frame, and numpy's per-call
    # overhead (~1 µs) dominates 3-vectors
    (p0, p1, p2), (e0, e1, e2) = p.tolist(), g.tolist()
    g0, g1, g2 = e0 - p0, e1 - p1, e2 - p2
    n = math.sqrt(g0 * g0 + g1 * g1 + g2 * g2)
    if n > 1e-12:
        y0, y1, y2 = g0 / n, g1 / n, g2 / n
    else:
        y0, y1, y2 = 0.0, 1.0, 0.0
    h = math.hypot(y0, y1)
    if h > 1e-6:  # the usual case of horizontal_perpendicular, inlined
        x0, x1, x2 = y1 / h, -y0 / h, 0.0
        x = np.array([x0, x1, x2])
    else:
        x = horizontal_perpendicular(np.array([y0, y1, y2]), previous_x)
        x0, x1, x2 = float(x[0]), float(x[1]), float(x[2])
    y = np.array([y0, y1, y2])
    z = np.array([x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0])
    return OnlineFrame(origin=p, x_axis=x, y_axis=y, z_axis=z)


def turn_toward(a: FloatArray, direction: FloatArray, u_max: float, period: float) -> FloatArray:
    """Turn vector u (orthogonal to the unit heading ``a``, ||u|| <= ``u_max``) turning ``a`` toward
    ``direction`` along the great circle: rate ``u_max`` outside a boundary layer, and the rate that
    closes the angle in one ``period`` [s] inside it (the 3D form of the sliding-mode law with a
    boundary layer used in Ch. 2).  Zero for a zero direction or one already aligned."""
    d0, d1, d2 = np.asarray(direction, dtype=float).tolist()
    nd = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    if nd < 1e-12:
        return np.zeros(3)
    a0, a1, a2 = np.asarray(a, dtype=float).tolist()
    d0, d1, d2 = d0 / nd, d1 / nd, d2 / nd
    cos_da = d0 * a0 + d1 * a1 + d2 * a2
    p0, p1, p2 = d0 - cos_da * a0, d1 - cos_da * a1, d2 - cos_da * a2
    n_perp = math.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
    angle = math.atan2(n_perp, cos_da)
    if n_perp < 1e-12:
        if angle < 0.5 * math.pi:
            return np.zeros(3)
        # exactly opposite: turn about any axis, horizontal first
        hp = horizontal_perpendicular(np.asarray(a, dtype=float))
        p0, p1, p2 = float(hp[0]), float(hp[1]), float(hp[2])
        n_perp = 1.0
    rate = min(u_max, angle / period) if period > 0 else u_max
    k = rate / n_perp
    return np.array([p0 * k, p1 * k, p2 * k])
