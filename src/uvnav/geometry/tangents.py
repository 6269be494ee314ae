"""Tangent lines from a point to a circle (thesis Ch. 2, eqs. (2.11)-(2.13); Fig. 2.6).

The thesis builds a *forecast circle* around a boundary point of an obstacle and steers along one of
the two tangent lines drawn to it from the robot.  :func:`circle_tangents` returns both tangent
points, their directions and the half-angle gamma of the tangent cone (eq. (2.12) with the circle
radius in place of ||v_i||).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvnav.geometry.angles import FloatArray, wrap_scalar


@dataclass(frozen=True)
class CircleTangents:
    """The two tangents from a point to a circle.

    Attributes:
        points: (2, 2) tangent points p1, p2 [m]; p1 is the counter-clockwise one as seen from the
            external point (its direction angle is ``centre_angle + gamma``).
        angles: (2,) direction angles [rad] of the tangent lines from the point to p1, p2.
        length: distance [m] from the point to either tangent point (both are equal).
        gamma: half-angle [rad] of the tangent cone, ``asin(radius / distance)``, in [0, pi/2].
        inside: True when the point lies inside (or on) the circle; then no tangent exists and the
            returned lines are the two directions perpendicular to the radius through the point
            (gamma = pi/2, length = 0), the limit of the tangents as the point reaches the circle.
    """

    points: FloatArray
    angles: FloatArray
    length: float
    gamma: float
    inside: bool


def circle_tangents(point: FloatArray, centre: FloatArray, radius: float) -> CircleTangents:
    """Tangent lines from ``point`` to the circle (``centre``, ``radius``) [m].

    Degenerate cases never produce NaN: a zero radius gives two identical tangents through the
    centre (gamma = 0); a point inside or on the circle gives the perpendicular limit described in
    :class:`CircleTangents`; a point at the centre uses the +x axis as the radius direction.
    """
    p = np.asarray(point, dtype=float)
    c = np.asarray(centre, dtype=float)
    r = max(float(radius), 0.0)
    offset = c - p
    dist = float(np.hypot(offset[0], offset[1]))
    base = float(np.arctan2(offset[1], offset[0])) if dist > 0.0 else 0.0
    if dist <= r:
        gamma = 0.5 * np.pi
        length = 0.0
        inside = True
    else:
        gamma = float(np.arcsin(r / dist))
        length = float(np.sqrt(max(dist * dist - r * r, 0.0)))
        inside = False
    angles = np.array([wrap_scalar(base + gamma), wrap_scalar(base - gamma)])
    directions = np.stack([np.cos(angles), np.sin(angles)], axis=-1)
    points = p + length * directions
    return CircleTangents(points=points, angles=angles, length=length, gamma=gamma, inside=inside)


def disc_silhouette_angles(
    point: FloatArray, centre: FloatArray, radius: float
) -> tuple[float, float]:
    """Directions [rad] of the two rays from ``point`` grazing a disc: (clockwise,
    counter-clockwise).

    These are the boundary rays of the obstacle's vision cone used by Savkin & Wang (2013).  A point
    inside the disc gives the perpendicular limit (half-angle pi/2).
    """
    t = circle_tangents(point, centre, radius)
    return float(t.angles[1]), float(t.angles[0])
