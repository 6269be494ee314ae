"""Vectorised segment-segment distances (exact), for batched "does this run hit that body" tests.

All inputs are arrays of shape (N, 2) describing N independent segment pairs ``p0-p1`` and
``q0-q1``; the result is their N exact Euclidean distances [m] (0 where they cross).
"""

from __future__ import annotations

import numpy as np

from uvnav.geometry.angles import FloatArray

_EPS = 1e-12


def points_to_segments(points: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Distance [m] from each point to the matching segment ``a``-``b``; all (N, 2) -> (N,)."""
    d = b - a
    len2 = np.maximum(np.einsum("ij,ij->i", d, d), _EPS)
    t = np.clip(np.einsum("ij,ij->i", points - a, d) / len2, 0.0, 1.0)
    diff = a + t[:, None] * d - points
    return np.sqrt(np.einsum("ij,ij->i", diff, diff))


def segments_distance(p0: FloatArray, p1: FloatArray, q0: FloatArray, q1: FloatArray) -> FloatArray:
    """Exact distance [m] between segments ``p0-p1`` and ``q0-q1``, pairwise; (N, 2) arrays -> (N,)."""
    r = p1 - p0
    s = q1 - q0
    w = q0 - p0
    denom = r[:, 0] * s[:, 1] - r[:, 1] * s[:, 0]
    safe = np.where(np.abs(denom) < _EPS, 1.0, denom)
    t = (w[:, 0] * s[:, 1] - w[:, 1] * s[:, 0]) / safe
    u = (w[:, 0] * r[:, 1] - w[:, 1] * r[:, 0]) / safe
    crossing = (np.abs(denom) >= _EPS) & (t >= 0.0) & (t <= 1.0) & (u >= 0.0) & (u <= 1.0)
    dist = np.minimum(
        np.minimum(points_to_segments(p0, q0, q1), points_to_segments(p1, q0, q1)),
        np.minimum(points_to_segments(q0, p0, p1), points_to_segments(q1, p0, p1)),
    )
    return np.where(crossing, 0.0, dist)


def segment_to_polygon_distance(a: FloatArray, b: FloatArray, starts: FloatArray, ends: FloatArray) -> float:
    """Exact distance [m] from the segment ``a``-``b`` to a polygon's boundary edges (0 if it crosses).

    One fused numpy pass (the hot path of "is this body in the robot's way"): the segment's two
    endpoints against every edge, every vertex against the segment, and the crossing test.  A
    segment lying wholly inside the polygon has a positive result; callers that care test
    containment separately.
    """
    ax, ay, bx, by = float(a[0]), float(a[1]), float(b[0]), float(b[1])
    sx, sy = starts[:, 0], starts[:, 1]
    ex, ey = ends[:, 0] - sx, ends[:, 1] - sy  # edge vectors
    rx, ry = bx - ax, by - ay
    # crossing test
    denom = rx * ey - ry * ex
    wx, wy = sx - ax, sy - ay
    ok = np.abs(denom) >= _EPS
    safe = np.where(ok, denom, 1.0)
    t = (wx * ey - wy * ex) / safe
    u = (wx * ry - wy * rx) / safe
    if np.any(ok & (t >= 0.0) & (t <= 1.0) & (u >= 0.0) & (u <= 1.0)):
        return 0.0
    # segment endpoints to the edges
    elen2 = np.maximum(ex * ex + ey * ey, _EPS)
    best = np.inf
    for px, py in ((ax, ay), (bx, by)):
        tt = np.clip(((px - sx) * ex + (py - sy) * ey) / elen2, 0.0, 1.0)
        dx, dy = sx + tt * ex - px, sy + tt * ey - py
        best = min(best, float(np.min(dx * dx + dy * dy)))
    # vertices to the segment
    rlen2 = max(rx * rx + ry * ry, _EPS)
    tv = np.clip(((sx - ax) * rx + (sy - ay) * ry) / rlen2, 0.0, 1.0)
    dx, dy = ax + tv * rx - sx, ay + tv * ry - sy
    best = min(best, float(np.min(dx * dx + dy * dy)))
    return float(np.sqrt(best))
