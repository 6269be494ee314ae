"""Tangent lines from a point to a circle (thesis Ch. 2, eqs. (2.11)-(2.13); Fig. 2.6).

The thesis builds a *forecast circle* around a boundary point of an obstacle and steers along one of
the two tangent lines drawn to it from the robot.  :func:`circle_tangents` returns both tangent
points, their directions and the half-angle gamma of the tangent cone (eq. (2.12) with the circle
radius in place of ||v_i||).
"""

from __future__ import annotations

import math
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
    # scalar arithmetic (a 2D point and circle: numpy's per-call overhead would dominate)
    p0, p1 = float(point[0]), float(point[1])
    o0, o1 = float(centre[0]) - p0, float(centre[1]) - p1
    r = max(float(radius), 0.0)
    dist = math.hypot(o0, o1)
    base = math.atan2(o1, o0) if dist > 0.0 else 0.0
    if dist <= r:
        gamma = 0.5 * math.pi
        length = 0.0
        inside = True
    else:
        gamma = math.asin(r / dist)
        length = math.sqrt(max(dist * dist - r * r, 0.0))
        inside = False
    a0, a1 = wrap_scalar(base + gamma), wrap_scalar(base - gamma)
    angles = np.array([a0, a1])
    points = np.array(
        [
            [p0 + length * math.cos(a0), p1 + length * math.sin(a0)],
            [p0 + length * math.cos(a1), p1 + length * math.sin(a1)],
        ]
    )
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
