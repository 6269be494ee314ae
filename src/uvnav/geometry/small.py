"""Pure-Python kernels for a handful of points.

A controller decides on one obstacle outline of 5-20 vertices at a time; there numpy's per-call
overhead (a few microseconds per operation on the machines we target) costs more than the
arithmetic, so these loops over Python floats are several times faster than the vectorised
kernels of :mod:`uvnav.geometry.polygons`, which remain the choice for large batches (the
simulator's edge soup of every obstacle).  Results are identical up to floating-point rounding;
the property tests compare the two.  Points are ``(x, y)`` tuples or length-2 sequences,
lengths in [m], angles in [rad].
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.kernels3d import compile_family, numba_enabled

Point = Sequence[float]

#: the hypotenuse of :func:`point_segment_distance` (its compiled copy binds :func:`pyhypot`)
_hypot = math.hypot
#: the compiled kernels by name (:func:`segment_ring_distance`)
_KERNELS: dict[str, Callable[..., Any]] = {}

_DBL_MIN = 2.2250738585072014e-308
_VELTKAMP = 134217729.0  # 2**27 + 1


def pyhypot(x: float, y: float) -> float:
    """CPython's ``math.hypot(x, y)`` (its ``vector_norm``: scaled, error-free squares and sums,
    one differential correction), operation for operation, so compiled code gets its numbers.

    libm's ``hypot`` (numpy's, numba's) differs from it in the last bit for about 0.6 % of
    inputs; the simulator's arrival test and the env's distances use ``math.hypot``.

    >>> import math
    >>> pyhypot(3.0, 4.0), pyhypot(-0.0, 0.0), pyhypot(1e-310, 0.0) == math.hypot(1e-310, 0.0)
    (5.0, 0.0, True)
    >>> pyhypot(math.inf, math.nan), math.isnan(pyhypot(1.0, math.nan))
    (inf, True)
    """
    x = abs(x)
    y = abs(y)
    if math.isinf(x) or math.isinf(y):
        return math.inf
    if x != x or y != y:
        return math.nan
    big = x if x > y else y
    if big == 0.0:
        return big
    outer = 1.0
    _, e = math.frexp(big)
    if e < -1021:  # subnormal: scaled up first, as CPython does
        x /= _DBL_MIN
        y /= _DBL_MIN
        outer = _DBL_MIN
        _, e = math.frexp(x if x > y else y)
    scale = math.ldexp(1.0, -e)
    csum, frac1, frac2 = 1.0, 0.0, 0.0
    for v in (x * scale, y * scale):
        t = v * _VELTKAMP  # Dekker's exact square v * v = z + zz
        hi = t - (t - v)
        lo = v - hi
        p, q = hi * hi, hi * lo + lo * hi
        z = p + q
        zz = p - z + q + lo * lo
        s = csum + z  # exact sum csum + z = s + (csum - s) + z
        frac1 += zz
        frac2 += (csum - s) + z
        csum = s
    h = math.sqrt(csum - 1.0 + (frac1 + frac2))
    t, t2 = -h * _VELTKAMP, h * _VELTKAMP  # exact product -h * h
    hi, hi2 = t - (t + h), t2 - (t2 - h)
    lo, lo2 = -h - hi, h - hi2
    p, q = hi * hi2, hi * lo2 + lo * hi2
    z = p + q
    zz = p - z + q + lo * lo2
    s = csum + z
    frac1 += zz
    frac2 += (csum - s) + z
    csum = s
    h += (csum - 1.0 + (frac1 + frac2)) / (2.0 * h)
    return outer * (h / scale)


def wrap(angle: float) -> float:
    """``angle`` [rad] wrapped to (-pi, pi]."""
    if -math.pi < angle <= math.pi:
        return angle
    w = math.pi - (math.pi - angle) % (2.0 * math.pi)
    return w if w > -math.pi else math.pi


def point_segment_distance(
    px: float, py: float, ax: float, ay: float, bx: float, by: float
) -> float:
    """Distance [m] from point p to segment a-b."""
    rx, ry = bx - ax, by - ay
    len2 = rx * rx + ry * ry
    t = 0.0 if len2 < 1e-24 else min(max(((px - ax) * rx + (py - ay) * ry) / len2, 0.0), 1.0)
    return _hypot(ax + t * rx - px, ay + t * ry - py)


def segment_polygon_distance(a: Point, b: Point, ring: Sequence[Point]) -> float:
    """Distance [m] from segment a-b to the closed polygon boundary ``ring`` (0 if they cross)."""
    ax, ay, bx, by = float(a[0]), float(a[1]), float(b[0]), float(b[1])
    rx, ry = bx - ax, by - ay
    best = math.inf
    n = len(ring)
    for i in range(n):
        sx, sy = ring[i][0], ring[i][1]
        ex, ey = ring[(i + 1) % n][0], ring[(i + 1) % n][1]
        qx, qy = ex - sx, ey - sy
        denom = rx * qy - ry * qx
        if denom != 0.0:
            wx, wy = sx - ax, sy - ay
            t = (wx * qy - wy * qx) / denom
            u = (wx * ry - wy * rx) / denom
            if 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0:
                return 0.0
        best = min(
            best,
            point_segment_distance(ax, ay, sx, sy, ex, ey),
            point_segment_distance(bx, by, sx, sy, ex, ey),
            point_segment_distance(sx, sy, ax, ay, bx, by),
        )
    return best


def segment_ring_distance(ax: float, ay: float, bx: float, by: float, ring: FloatArray) -> float:
    """:func:`segment_polygon_distance` from segment ``(ax, ay)``-``(bx, by)`` to the polygon of
    vertices ``ring`` (n, 2) [m], compiled by numba when it is enabled (the same numbers: its
    copy of :func:`point_segment_distance` takes :func:`pyhypot` for ``math.hypot``)."""
    if not numba_enabled():
        return segment_polygon_distance((ax, ay), (bx, by), ring.tolist())
    if not _KERNELS:
        _KERNELS.update(
            compile_family([("_hypot", pyhypot), point_segment_distance, segment_polygon_distance])
        )
    return float(_KERNELS["segment_polygon_distance"]((ax, ay), (bx, by), ring))


def ray_polygon_distance(ox: float, oy: float, angle: float, ring: Sequence[Point]) -> float:
    """Distance [m] along the ray from o at ``angle`` to its first crossing of ``ring``.

    ``inf`` when the ray misses.
    """
    dx, dy = math.cos(angle), math.sin(angle)
    best = math.inf
    n = len(ring)
    for i in range(n):
        sx, sy = ring[i][0], ring[i][1]
        qx, qy = ring[(i + 1) % n][0] - sx, ring[(i + 1) % n][1] - sy
        denom = dx * qy - dy * qx
        if abs(denom) < 1e-12:
            continue
        wx, wy = sx - ox, sy - oy
        t = (wx * qy - wy * qx) / denom
        s = (wx * dy - wy * dx) / denom
        if t >= 0.0 and 0.0 <= s <= 1.0 and t < best:
            best = t
    return best


def ray_circle_distance(
    ox: float, oy: float, angle: float, cx: float, cy: float, r: float
) -> float:
    """Distance [m] along the ray from o at ``angle`` to its first crossing of a circle.

    ``inf`` when the ray misses; a ray starting inside meets the circle on the way out.
    """
    dx, dy = math.cos(angle), math.sin(angle)
    mx, my = cx - ox, cy - oy
    b = dx * mx + dy * my
    disc = b * b - (mx * mx + my * my - r * r)
    if disc < 0.0:
        return math.inf
    sq = math.sqrt(disc)
    t = b - sq if b - sq >= 0.0 else b + sq
    return t if t >= 0.0 else math.inf
