"""Exact, vectorised kernels on simple polygons (convex or not) and discs.

Every kernel works on *edge soups*: the edges of one or many polygons stacked into ``starts`` and
``ends`` arrays of shape (E, 2), with ``offsets`` (k + 1,) marking where polygon ``j`` owns edges
``offsets[j]:offsets[j + 1]``.  One numpy pass then answers a query against all obstacles of a
world, which is what keeps the simulator and the sensors fast (no per-obstacle Python loop, no
shapely object construction per step).  Results are exact up to floating point; the property tests
compare them with shapely 2's ``distance``/``contains``/``intersection``.

Units: lengths [m], angles [rad].
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.kernels3d import compile_family, numba_enabled

_EPS = 1e-12


def cyclic_next(a: np.ndarray) -> np.ndarray:
    """``a`` shifted one row up cyclically (row i holds row i + 1, the last the first): the value
    of ``np.roll(a, -1, axis=0)``, in a fifth of its time on short arrays (a polygon's vertices:
    scene generation calls it hundreds of times per scene)."""
    return np.concatenate((a[1:], a[:1]))


def cyclic_prev(a: np.ndarray) -> np.ndarray:
    """``a`` shifted one row down cyclically: the value of ``np.roll(a, 1, axis=0)``."""
    return np.concatenate((a[-1:], a[:-1]))


def polygon_edges(vertices: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Edges (starts, ends), each (n, 2), of the closed polygon with ``vertices`` (n, 2)."""
    v = np.asarray(vertices, dtype=float)
    return v, cyclic_next(v)


def edge_soup(polygons: Sequence[FloatArray]) -> tuple[FloatArray, FloatArray, np.ndarray]:
    """Stack the edges of several polygons: returns ``(starts, ends, offsets)``."""
    if not polygons:
        empty = np.zeros((0, 2))
        return empty, empty, np.zeros(1, dtype=np.intp)
    verts = [np.asarray(p, dtype=float) for p in polygons]
    starts = np.concatenate(verts, axis=0)
    ends = np.concatenate([cyclic_next(v) for v in verts], axis=0)
    offsets = np.zeros(len(verts) + 1, dtype=np.intp)
    offsets[1:] = np.cumsum([len(v) for v in verts])
    return starts, ends, offsets


def polygon_area(vertices: FloatArray) -> float:
    """Signed area [m^2] (shoelace); positive for counter-clockwise vertex order."""
    v = np.asarray(vertices, dtype=float)
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.dot(x, cyclic_next(y)) - np.dot(cyclic_next(x), y))


def polygon_centroid(vertices: FloatArray) -> FloatArray:
    """Area centroid ("mass centre", uniform density) [m] of a simple polygon."""
    v = np.asarray(vertices, dtype=float)
    x, y = v[:, 0], v[:, 1]
    xn, yn = cyclic_next(x), cyclic_next(y)
    cross = x * yn - xn * y
    area = 0.5 * cross.sum()
    if abs(area) < _EPS:
        return np.asarray(v.mean(axis=0), dtype=float)
    cx = ((x + xn) * cross).sum() / (6.0 * area)
    cy = ((y + yn) * cross).sum() / (6.0 * area)
    return np.array([cx, cy])


def segment_nearest(
    point: FloatArray, starts: FloatArray, ends: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Distance [m] and nearest point from ``point`` to every segment; shapes (E,), (E, 2)."""
    p = np.asarray(point, dtype=float)
    d = ends - starts
    len2 = np.einsum("ij,ij->i", d, d)
    t = np.einsum("ij,ij->i", p - starts, d) / np.maximum(len2, _EPS)
    t = np.clip(t, 0.0, 1.0)
    nearest = starts + t[:, None] * d
    diff = nearest - p
    return np.sqrt(np.einsum("ij,ij->i", diff, diff)), nearest


def crossing_parity(point: FloatArray, starts: FloatArray, ends: FloatArray) -> np.ndarray:
    """Per-edge crossing indicator (int) of the +x ray from ``point`` (even-odd rule)."""
    px, py = float(point[0]), float(point[1])
    y0, y1 = starts[:, 1], ends[:, 1]
    straddles = (y0 > py) != (y1 > py)
    dy = np.where(straddles, y1 - y0, 1.0)
    x_cross = starts[:, 0] + (py - y0) * (ends[:, 0] - starts[:, 0]) / dy
    return (straddles & (x_cross > px)).astype(np.intp)


def nearest_on_polygons(
    point: FloatArray, starts: FloatArray, ends: FloatArray, offsets: np.ndarray
) -> tuple[FloatArray, FloatArray, np.ndarray]:
    """Nearest boundary point of each polygon of an edge soup.

    For repeated queries against the same polygons, pack them once with :func:`closed_rings`
    and use :func:`rings_nearest`, which needs no per-call grouping.

    Returns:
        ``(distance (k,), nearest (k, 2), inside (k,) bool)``; ``distance`` is to the boundary,
        so a point inside a polygon has ``inside`` True and a positive boundary distance.
    """
    k = len(offsets) - 1
    if k == 0:
        return np.zeros(0), np.zeros((0, 2)), np.zeros(0, dtype=bool)
    dists, nearest = segment_nearest(point, starts, ends)
    first = offsets[:-1]
    mins = np.minimum.reduceat(dists, first)
    owner = np.repeat(np.arange(k), np.diff(offsets))
    # first edge of each group attaining the group's minimum (same tie-break as a stable sort)
    hit = np.flatnonzero(dists == mins[owner])
    idx = hit[np.searchsorted(owner[hit], np.arange(k))]
    crossings = np.add.reduceat(crossing_parity(point, starts, ends), first)
    return mins, nearest[idx], (crossings % 2) == 1


def polygon_nearest(point: FloatArray, vertices: FloatArray) -> tuple[float, FloatArray, bool]:
    """Nearest boundary point of one polygon: ``(distance [m], point (2,), inside)``."""
    s, e = polygon_edges(vertices)
    d, n, inside = nearest_on_polygons(point, s, e, np.array([0, len(s)]))
    return float(d[0]), n[0], bool(inside[0])


def rays_segments_hit(
    origin: FloatArray, directions: FloatArray, starts: FloatArray, ends: FloatArray
) -> FloatArray:
    """Ray parameter t [m along unit directions] at which each ray meets each segment.

    Args:
        origin: (2,) common ray origin.
        directions: (R, 2) unit ray directions.
        starts, ends: (E, 2) segments.

    Returns:
        (R, E) hit distances, ``inf`` where the ray misses the segment (parallel rays never hit).
    """
    o = np.asarray(origin, dtype=float)
    dvec = np.asarray(directions, dtype=float)[:, None, :]  # (R,1,2)
    seg = (ends - starts)[None, :, :]  # (1,E,2)
    w = (starts - o)[None, :, :]  # (1,E,2)
    denom = dvec[..., 0] * seg[..., 1] - dvec[..., 1] * seg[..., 0]  # (R,E)
    safe = np.where(np.abs(denom) < _EPS, 1.0, denom)
    t = (w[..., 0] * seg[..., 1] - w[..., 1] * seg[..., 0]) / safe
    s = (w[..., 0] * dvec[..., 1] - w[..., 1] * dvec[..., 0]) / safe
    ok = (np.abs(denom) >= _EPS) & (t >= 0.0) & (s >= 0.0) & (s <= 1.0)
    return np.where(ok, t, np.inf)


def rays_circles_hit(
    origin: FloatArray, directions: FloatArray, centres: FloatArray, radii: FloatArray
) -> FloatArray:
    """(R, C) distance [m] along each unit ray to the first boundary crossing of each circle.

    A ray starting inside a circle hits its boundary on the way out; misses are ``inf``.  Every
    entry is computed on its own (elementwise products, no matrix product), so it does not depend
    on which other rays or circles are in the call.
    """
    o = np.asarray(origin, dtype=float)
    dvec = np.asarray(directions, dtype=float)
    m = np.asarray(centres, dtype=float) - o  # (C,2)
    b = dvec[:, 0, None] * m[:, 0] + dvec[:, 1, None] * m[:, 1]  # (R,C) projection on the ray
    c = (m[:, 0] * m[:, 0] + m[:, 1] * m[:, 1]) - np.asarray(radii, dtype=float) ** 2  # (C,)
    disc = b * b - c[None, :]
    sq = np.sqrt(np.maximum(disc, 0.0))
    t_near = b - sq
    t_far = b + sq
    t = np.where(t_near >= 0.0, t_near, t_far)
    return np.where((disc >= 0.0) & (t >= 0.0), t, np.inf)


def ray_polygon_hit(
    origin: FloatArray, angle: float, vertices: FloatArray
) -> tuple[float, FloatArray | None]:
    """First hit of the ray from ``origin`` at ``angle`` [rad] with a polygon's boundary.

    Returns ``(distance [m], hit point)``; ``(inf, None)`` when the ray misses.
    """
    s, e = polygon_edges(vertices)
    direction = np.array([[np.cos(angle), np.sin(angle)]])
    t = rays_segments_hit(origin, direction, s, e)[0]
    tmin = float(t.min()) if t.size else np.inf
    if not np.isfinite(tmin):
        return np.inf, None
    return tmin, np.asarray(origin, dtype=float) + tmin * direction[0]


def angular_extent(
    point: FloatArray, vertices: FloatArray, reference_angle: float
) -> tuple[float, float]:
    """Silhouette of a polygon seen from an outside ``point``.

    Returns the (min, max) angle [rad] of the polygon's vertices measured from ``reference_angle``
    (both wrapped to (-pi, pi]); the rays at ``reference_angle + min`` and ``+ max`` graze the
    polygon.  Valid while the polygon does not surround the point (angular span < 2*pi), which holds
    for the obstacles the thesis admits (no narrow U-traps, Fig. 2.1(c)).
    """
    rel = np.asarray(vertices, dtype=float) - np.asarray(point, dtype=float)
    ang = np.arctan2(rel[:, 1], rel[:, 0]) - reference_angle
    ang = np.pi - np.mod(np.pi - ang, 2.0 * np.pi)
    return float(ang.min()), float(ang.max())


def transform_points(local: FloatArray, position: FloatArray, heading: float) -> FloatArray:
    """Rigid transform (rotate by ``heading`` [rad], then translate by ``position`` [m])."""
    c, s = np.cos(heading), np.sin(heading)
    loc = np.asarray(local, dtype=float)
    out = np.empty_like(loc)
    out[:, 0] = c * loc[:, 0] - s * loc[:, 1] + position[0]
    out[:, 1] = s * loc[:, 0] + c * loc[:, 1] + position[1]
    return out


def segment_intersects_polygon(
    a: FloatArray, b: FloatArray, vertices: FloatArray, *, margin: float = 0.0
) -> bool:
    """True when segment ``a``-``b`` comes within ``margin`` [m] of (or crosses) the polygon."""
    s, e = polygon_edges(vertices)
    if segments_min_distance(a, b, s, e) <= margin:
        return True
    _, _, inside = polygon_nearest(a, vertices)
    return inside


def segments_min_distance(
    a: FloatArray, b: FloatArray, starts: FloatArray, ends: FloatArray
) -> float:
    """Minimum distance [m] between segment ``a``-``b`` and a set of segments (0 if they cross)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    d = b - a
    # proper crossing test
    e = ends - starts
    denom = d[0] * e[:, 1] - d[1] * e[:, 0]
    w = starts - a
    safe = np.where(np.abs(denom) < _EPS, 1.0, denom)
    t = (w[:, 0] * e[:, 1] - w[:, 1] * e[:, 0]) / safe
    s = (w[:, 0] * d[1] - w[:, 1] * d[0]) / safe
    if np.any((np.abs(denom) >= _EPS) & (t >= 0) & (t <= 1) & (s >= 0) & (s <= 1)):
        return 0.0
    d1, _ = segment_nearest(a, starts, ends)
    d2, _ = segment_nearest(b, starts, ends)
    # endpoints of the other segments against a-b
    ab_s = np.broadcast_to(a, starts.shape)
    ab_e = np.broadcast_to(b, starts.shape)
    d3 = points_to_segments(starts, ab_s, ab_e)
    d4 = points_to_segments(ends, ab_s, ab_e)
    return float(min(d1.min(), d2.min(), d3.min(), d4.min())) if len(starts) else np.inf


def points_to_segments(points: FloatArray, starts: FloatArray, ends: FloatArray) -> FloatArray:
    """Distance [m] from each point to the matching segment ``starts[i]``-``ends[i]``;
    (N, 2) arrays -> (N,)."""
    d = ends - starts
    len2 = np.maximum(np.einsum("ij,ij->i", d, d), _EPS)
    t = np.clip(np.einsum("ij,ij->i", points - starts, d) / len2, 0.0, 1.0)
    diff = starts + t[:, None] * d - points
    return np.sqrt(np.einsum("ij,ij->i", diff, diff))


def polygons_gap(a: FloatArray, b: FloatArray) -> float:
    """Distance [m] between the boundaries of two polygons (vertices (n, 2) and (m, 2)): the
    least distance from a vertex of one to an edge of the other (exact for disjoint polygons).

    The numbers of :func:`points_to_segments` over every vertex-edge pair, compiled by numba when
    it is enabled (:func:`polygons_gap_py`, the same operations), else in arrays.

    Overlapping polygons give the distance of their nearest non-crossing parts, not 0:

    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> polygons_gap(sq, sq + (3.0, 0.0)), polygons_gap(sq, sq + (1.0, 0.5))
    (2.0, 0.0)
    >>> polygons_gap(sq, sq + 0.5)
    0.5
    """
    if numba_enabled():
        if not _GAP:
            _GAP.append(compile_family([point_segment_np, polygons_gap_py])["polygons_gap_py"])
        return float(_GAP[0](np.asarray(a, dtype=float), np.asarray(b, dtype=float)))
    ea, eb = np.roll(a, -1, axis=0), np.roll(b, -1, axis=0)
    na, nb = len(a), len(b)
    d_ab = points_to_segments(np.repeat(a, nb, axis=0), np.tile(b, (na, 1)), np.tile(eb, (na, 1)))
    d_ba = points_to_segments(np.repeat(b, na, axis=0), np.tile(a, (nb, 1)), np.tile(ea, (nb, 1)))
    return float(min(d_ab.min(), d_ba.min()))


def point_segment_np(px: float, py: float, sx: float, sy: float, ex: float, ey: float) -> float:
    """:func:`points_to_segments` for one point and one segment, its operations in its order."""
    dx, dy = ex - sx, ey - sy
    len2 = dx * dx + dy * dy
    if not len2 >= _EPS and len2 == len2:  # np.maximum(len2, EPS), NaN kept
        len2 = _EPS
    t = ((px - sx) * dx + (py - sy) * dy) / len2
    if t < 0.0:  # np.clip(t, 0, 1), NaN kept
        t = 0.0
    if t > 1.0:
        t = 1.0
    qx, qy = sx + t * dx - px, sy + t * dy - py
    return math.sqrt(qx * qx + qy * qy)


def polygons_gap_py(a: FloatArray, b: FloatArray) -> float:
    """:func:`polygons_gap` as loops (compiled by numba): the least vertex-edge distance each
    way, NaN kept as ``ndarray.min`` keeps it, then the builtin ``min`` of the two."""
    low = [math.inf, math.inf]
    for k in range(2):
        p, q = (a, b) if k == 0 else (b, a)
        n = q.shape[0]
        best = math.inf
        for i in range(p.shape[0]):
            for j in range(n):
                e = j + 1 if j + 1 < n else 0
                d = point_segment_np(p[i, 0], p[i, 1], q[j, 0], q[j, 1], q[e, 0], q[e, 1])
                if d < best or d != d:
                    best = d
                if best != best:
                    break
            if best != best:
                break
        low[k] = best
    return low[1] if low[1] < low[0] else low[0]


_GAP: list[Callable[..., Any]] = []


def points_to_segment(
    points: FloatArray,
    start: FloatArray | tuple[float, float],
    end: FloatArray | tuple[float, float],
) -> FloatArray:
    """Distance [m] from each point (N, 2) to ONE segment ``start``-``end`` (2,), -> (N,).

    The one-segment case of :func:`points_to_segments` in a few array calls (no broadcast copies
    of the segment, no einsum): a controller asks it at every decision."""
    p0, p1 = float(start[0]), float(start[1])
    d0, d1 = float(end[0]) - p0, float(end[1]) - p1
    len2 = max(d0 * d0 + d1 * d1, _EPS)
    rx, ry = points[:, 0] - p0, points[:, 1] - p1
    t = np.minimum(np.maximum((rx * d0 + ry * d1) / len2, 0.0), 1.0)
    return np.asarray(np.hypot(rx - t * d0, ry - t * d1))


# --------------------------------------------------------------------------------------------
# padded closed rings: many polygons as one (2, m, n_max + 1) array, no per-call grouping


def closed_rings(polygons: Sequence[FloatArray]) -> tuple[FloatArray, np.ndarray]:
    """Pack polygons into padded closed rings for the ``rings_*`` kernels.

    ``rings[0]`` holds x and ``rings[1]`` y coordinates; row ``i`` holds the ``n_i`` vertices of
    polygon ``i`` followed by its first vertex, repeated up to ``n_max + 1`` columns.  The edges
    ``rings[:, :, :-1]`` -> ``rings[:, :, 1:]`` are then the polygon's own edges followed by
    zero-length edges at its first vertex, which are never strictly nearer than the real edge
    starting there, never straddle a horizontal line and never meet a ray: every kernel is exact
    on the padded rows, and per-polygon results need no grouping (one row, one polygon).

    Returns:
        ``(rings, counts)``: the (2, m, n_max + 1) array [m] and the (m,) vertex counts.
    """
    m = len(polygons)
    counts = np.array([len(p) for p in polygons], dtype=np.intp)
    width = int(counts.max()) + 1 if m else 1
    rings = np.empty((2, m, width))
    for i, poly in enumerate(polygons):
        v = np.asarray(poly, dtype=float)
        n = len(v)
        rings[:, i, :n] = v.T
        rings[:, i, n:] = v[0, :, None]
    return rings, counts


def transform_rings(
    rings: FloatArray,
    centres: FloatArray,
    headings: FloatArray,
    *,
    perp: FloatArray | None = None,
) -> FloatArray:
    """Rigid transforms of packed rings: ring ``i`` rotated by ``headings[i]`` [rad] about the
    origin, then moved by ``centres[i]`` (m, 2) [m].

    The same numbers as :func:`transform_points` (``c x - s y + cx``, ``s x + c y + cy``).  Pass
    ``perp = ring_perp(rings)`` when transforming the same rings repeatedly.
    """
    h = np.asarray(headings, dtype=float)[None, :, None]
    if perp is None:
        perp = ring_perp(rings)
    # c * x + s * (-y) is bit for bit c * x - s * y
    return np.cos(h) * rings + np.sin(h) * perp + np.asarray(centres, dtype=float).T[:, :, None]


def ring_perp(rings: FloatArray) -> FloatArray:
    """``(-y, x)`` of packed rings (every point turned by +90 degrees), for
    :func:`transform_rings`."""
    return np.stack((-rings[1], rings[0]))


def rings_nearest(
    point: FloatArray | tuple[float, float], rings: FloatArray, *, parity: bool = True
) -> tuple[FloatArray, FloatArray, np.ndarray | None]:
    """Nearest boundary point of each polygon of a :func:`closed_rings` pack.

    Args:
        point: (2,) query point [m].
        rings: (2, m, w) closed rings.
        parity: also run the even-odd containment test; pass False when ``point`` is known to be
            outside every polygon (e.g. outside their bounding discs) to skip it.

    Returns:
        ``(distance (m,), nearest (2, m), inside (m,) bool or None)``: ``distance`` is to the
        boundary (positive inside too), ``nearest`` holds x and y of the nearest points, and
        ``inside`` is None without ``parity``.  Ties between edges go to the first edge, and the
        numbers are those of :func:`nearest_on_polygons`.
    """
    px = float(point[0])
    py = float(point[1])
    if numba_enabled() and rings.shape[1] and rings.shape[2] > 1:
        m = rings.shape[1]
        dist, nearest, inside = np.empty(m), np.empty((2, m)), np.empty(m, dtype=np.bool_)
        _rings_kernel()(px, py, np.ascontiguousarray(rings, dtype=float), parity, dist, nearest,
                        inside)  # fmt: skip
        return dist, nearest, (inside if parity else None)
    p = np.array((px, py)).reshape(2, 1, 1)
    starts = rings[:, :, :-1]
    e = rings[:, :, 1:] - starts
    we = (p - starts) * e
    ee = e * e
    t = (we[0] + we[1]) / np.maximum(ee[0] + ee[1], _EPS)
    t = np.minimum(np.maximum(t, 0.0, out=t), 1.0, out=t)
    q = starts + t * e
    dq = q - p
    dq *= dq
    d = np.sqrt(dq[0] + dq[1])
    m, n = d.shape
    flat = d.argmin(axis=1)
    flat += np.arange(0, m * n, n)
    dist = d.ravel().take(flat)
    nearest = q.reshape(2, m * n).take(flat, axis=1)
    if not parity:
        return dist, nearest, None
    sy = starts[1]
    straddles = (sy > py) != (rings[1, :, 1:] > py)
    x_cross = starts[0] + (py - sy) * e[0] / np.where(straddles, e[1], 1.0)
    crossings = np.count_nonzero(straddles & (x_cross > px), axis=1)
    return dist, nearest, (crossings % 2) == 1


def ring_nearest_py(
    px: float, py: float, xs: FloatArray, ys: FloatArray, parity: bool
) -> tuple[float, float, float, bool]:
    """One closed ring (``xs``, ``ys``: its padded vertices [m]) of :func:`rings_nearest_py`:
    ``(distance to the boundary, nearest x, nearest y, inside)`` from ``(px, py)``; ``inside``
    is the even-odd test, False without ``parity``."""
    best, bx, by, seen_nan = math.inf, math.nan, math.nan, False
    crossings = 0
    for j in range(xs.shape[0] - 1):
        sx, sy = xs[j], ys[j]
        ex, ey = xs[j + 1] - sx, ys[j + 1] - sy
        ee = ex * ex + ey * ey
        if not ee >= _EPS and ee == ee:  # np.maximum(ee, EPS), NaN kept
            ee = _EPS
        t = ((px - sx) * ex + (py - sy) * ey) / ee
        if t < 0.0:
            t = 0.0
        if t > 1.0:
            t = 1.0
        qx, qy = sx + t * ex, sy + t * ey
        dx, dy = qx - px, qy - py
        d = math.sqrt(dx * dx + dy * dy)
        if not seen_nan and (d != d or d < best or j == 0):
            best, bx, by, seen_nan = d, qx, qy, d != d
        straddles = (sy > py) != (ys[j + 1] > py)
        if parity and straddles and sx + (py - sy) * ex / ey > px:
            crossings += 1
    return best, bx, by, crossings % 2 == 1


def rings_nearest_py(
    px: float,
    py: float,
    rings: FloatArray,
    parity: bool,
    dist: FloatArray,
    nearest: FloatArray,
    inside: np.ndarray,
) -> None:
    """:func:`rings_nearest` as one loop over the rings' edges (:func:`ring_nearest_py` per
    ring), writing ``dist`` (m,), ``nearest`` (2, m) and, with ``parity``, ``inside`` (m,)
    (compiled by numba when it is enabled).  The same operations in the same order as the array
    version, so the same numbers bit for bit (NaN included: the first NaN distance wins, as
    ``argmin`` picks it)."""
    for i in range(rings.shape[1]):
        d, qx, qy, ins = ring_nearest_py(px, py, rings[0, i], rings[1, i], parity)
        dist[i], nearest[0, i], nearest[1, i], inside[i] = d, qx, qy, ins


_RINGS: list[Callable[..., Any]] = []


def _rings_kernel() -> Callable[..., Any]:
    """:func:`rings_nearest_py`, compiled on the first call (or loaded from numba's cache)."""
    if not _RINGS:
        _RINGS.append(compile_family([ring_nearest_py, rings_nearest_py])["rings_nearest_py"])
    return _RINGS[0]


def rays_rings_hit(
    origin: FloatArray | tuple[float, float], directions: FloatArray, rings: FloatArray
) -> FloatArray:
    """(R, m) distance [m] along each unit ray to the first boundary crossing of each ring.

    The same test and numbers as :func:`rays_segments_hit` (zero-length padding edges never hit);
    ``inf`` where a ray misses.
    """
    ox = float(origin[0])
    oy = float(origin[1])
    dirs = np.asarray(directions, dtype=float)
    dx = dirs[:, 0, None, None]  # (R,1,1)
    dy = dirs[:, 1, None, None]
    sx = rings[0, :, :-1]
    sy = rings[1, :, :-1]
    ex = rings[0, :, 1:] - sx
    ey = rings[1, :, 1:] - sy
    wx = sx - ox
    wy = sy - oy
    denom = dx * ey - dy * ex  # (R,m,n)
    bad = np.abs(denom) < _EPS
    safe = np.where(bad, 1.0, denom)
    t = (wx * ey - wy * ex) / safe
    s = (wx * dy - wy * dx) / safe
    ok = ~bad & (t >= 0.0) & (s >= 0.0) & (s <= 1.0)
    return np.where(ok, t, np.inf).min(axis=2, initial=np.inf)
