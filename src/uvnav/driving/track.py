"""Track geometry kernels for the Chapter 6 simulator and expert (pure numpy).

The track is CarRacing's closed centreline (points about 3.5 m apart).  These kernels give the
arc length, the tangent heading and the curvature of the centreline, project a position onto it
(signed distance, + to the left of the direction of travel) and compute the corner-speed profile
that the expert tracks.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from uvnav.geometry.angles import wrap_to_pi


@dataclass(frozen=True)
class TrackGeometry:
    """Closed centreline with derived quantities.

    Attributes:
        points: ``(N, 2)`` centreline points, in driving order [m].
        heading: ``(N,)`` direction of travel from point i to point i+1 [rad].
        seg_len: ``(N,)`` length of segment i → i+1 [m].
        s: ``(N,)`` arc length at point i [m].
        curvature: ``(N,)`` unsigned curvature at point i [1/m].
        length: total length [m].
    """

    points: NDArray[np.float64]
    heading: NDArray[np.float64]
    seg_len: NDArray[np.float64]
    s: NDArray[np.float64]
    curvature: NDArray[np.float64]
    length: float


def track_geometry(points: NDArray[np.float64]) -> TrackGeometry:
    """Derive headings, arc length and curvature of a closed centreline.

    Args:
        points: ``(N, 2)`` centreline points [m], N ≥ 3, the last joined back to the first.

    Returns:
        The geometry.
    """
    p = np.asarray(points, dtype=float)
    d = np.roll(p, -1, axis=0) - p
    seg = np.hypot(d[:, 0], d[:, 1])
    heading = np.arctan2(d[:, 1], d[:, 0])
    dtheta = np.abs(wrap_to_pi(heading - np.roll(heading, 1)))
    ds = 0.5 * (seg + np.roll(seg, 1))
    curv = dtheta / np.maximum(ds, 1e-9)
    # smooth over ±2 points: CarRacing's centreline turns in small steps
    k = np.ones(5) / 5
    curv = np.convolve(np.concatenate([curv[-2:], curv, curv[:2]]), k, mode="valid")
    s = np.concatenate([[0.0], np.cumsum(seg)[:-1]])
    return TrackGeometry(p, heading, seg, s, curv, float(seg.sum()))


def project(geom: TrackGeometry, x: float, y: float) -> tuple[int, float, float]:
    """Nearest centreline segment to a position.

    Args:
        geom: track geometry.
        x: position x [m].
        y: position y [m].

    Returns:
        ``(i, t, d)``: segment index, fraction along it in [0, 1], signed distance [m]
        (+ left of the direction of travel).
    """
    p = geom.points
    d = np.roll(p, -1, axis=0) - p
    rel = np.array([x, y]) - p
    t = np.clip(np.sum(rel * d, axis=1) / np.maximum(np.sum(d * d, axis=1), 1e-12), 0.0, 1.0)
    foot = p + t[:, None] * d
    dist = np.hypot(x - foot[:, 0], y - foot[:, 1])
    i = int(np.argmin(dist))
    cross = d[i, 0] * rel[i, 1] - d[i, 1] * rel[i, 0]
    return i, float(t[i]), float(np.copysign(dist[i], cross))


def point_ahead(geom: TrackGeometry, i: int, t: float, distance: float) -> NDArray[np.float64]:
    """The centreline point ``distance`` [m] ahead of the foot point (segment i, fraction t)."""
    n = len(geom.points)
    remaining = distance + t * geom.seg_len[i]
    j = i
    while remaining > geom.seg_len[j]:
        remaining -= geom.seg_len[j]
        j = (j + 1) % n
    frac = remaining / max(geom.seg_len[j], 1e-12)
    return np.asarray(geom.points[j] + frac * (geom.points[(j + 1) % n] - geom.points[j]))


def corner_speed_profile(
    geom: TrackGeometry, *, v_max: float, a_lat: float, a_brake: float
) -> NDArray[np.float64]:
    """Highest speed at every centreline point that corners and brakes within limits.

    ``v_i = min(v_max, sqrt(a_lat / κ_i))``, then a backward pass (twice round the closed loop)
    ``v_i ≤ sqrt(v_{i+1}² + 2 a_brake ds_i)`` so the car can slow down before every corner.

    Args:
        geom: track geometry.
        v_max: top speed [m/s].
        a_lat: lateral acceleration limit [m/s²].
        a_brake: braking deceleration [m/s²].

    Returns:
        ``(N,)`` target speed [m/s].
    """
    v = np.minimum(v_max, np.sqrt(a_lat / np.maximum(geom.curvature, 1e-9)))
    n = len(v)
    for k in range(2 * n - 1, -1, -1):
        i = k % n
        nxt = (i + 1) % n
        v[i] = min(v[i], np.sqrt(v[nxt] ** 2 + 2 * a_brake * geom.seg_len[i]))
    return v
