"""The bodies of ``zhang2019-v2``'s decision (:mod:`uvnav.controllers.zhang2019_v2`): the readings
read into arrays, every body as discs on its boundary, the bodies that can reach the robot within
the horizon, the tangent directions of their forecast circles and the extra candidate
directions.  Pure numpy functions of the readings; the compiled loop
(:mod:`uvnav.controllers.zhang2019_v2_loop`) computes the same on floats.
Units: metres, seconds, radians.
"""

from __future__ import annotations

import math
from operator import attrgetter

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.sensors.observation import ObstacleReading, ReadingArrays, Readings, read_arrays

IntArray = np.ndarray

#: the readings as arrays (:data:`~uvnav.sensors.observation.ReadingArrays`)
BodyTable = ReadingArrays


def body_table(readings: tuple[ObstacleReading, ...], noise_sigmas: float = 0.0) -> BodyTable:
    """The readings as arrays (:data:`BodyTable`): the sensor's own arrays when it gave them
    (:class:`~uvnav.sensors.observation.Readings`), else read reading by reading (the one cost of
    a decision that grows with the readings outside the compiled loop); each body grown by
    ``noise_sigmas`` times the centre noise its reading declares (:func:`grown_by_noise`).

    Readings whose rates are all known (``Readings.all_known``: the exact sensors) declare no
    noise, and their arrays are returned as they are.

    >>> z = np.zeros(2)
    >>> rd = ObstacleReading(0, 1.5, z, np.array([2.0, 0.0]), z, 0.0, np.zeros((0, 2)), 0.5, 0.5,
    ...                      position_std=0.1)
    >>> body_table((rd,), 2.0)[0].round(6).tolist()
    [[1.3, 0.0, 0.7, 0.7]]
    """
    if isinstance(readings, Readings):
        if readings.all_known or noise_sigmas <= 0.0:
            return readings.arrays
        table = readings.arrays
    else:
        table = read_arrays(readings)
    if noise_sigmas <= 0.0 or not readings:
        return table
    std = np.fromiter(map(_STD, readings), float, count=len(readings))
    return grown_by_noise(table, noise_sigmas * std) if bool(np.any(std > 0.0)) else table


_STD = attrgetter("position_std")


def grown_by_noise(table: BodyTable, grow: FloatArray) -> BodyTable:
    """``table`` with each body k grown by ``grow[k]`` [m] (>= 0) wherever v2 reads its size:
    the distance less ``grow`` (at least 0), the bounding radius plus ``grow``; a disc's radius
    plus ``grow``, and a polygon's boundary discs (radius ``spacing / 2``) by ``grow`` through
    its radius column, which then reads ``-grow`` (a polygon's is <= 0, read as
    ``spacing / 2 - radius`` by :func:`boundary_discs` and the compiled loops).  A body whose
    centre is known to ``sigma`` [m] per axis lies beyond ``k sigma`` of its reading with
    probability ``exp(-k^2 / 2)`` (a Rayleigh tail): 0.14 for k = 2.

    >>> t = (np.array([[1.0, 0.0, 0.3, 0.3], [0.2, 0.0, 0.0, 0.8]]), np.zeros((2, 2)),
    ...      np.zeros((2, 2)))
    >>> grown_by_noise(t, np.array([0.1, 0.3]))[0].round(6).tolist()
    [[0.9, 0.0, 0.4, 0.4], [0.0, 0.0, -0.3, 1.1]]
    """
    scal, centre, vel = table
    out = scal.copy()
    out[:, 0] = np.maximum(scal[:, 0] - grow, 0.0)
    out[:, 2] = np.where(scal[:, 2] > 0.0, scal[:, 2] + grow, -grow)
    out[:, 3] = scal[:, 3] + grow
    return out, centre, vel


def boundary_discs(
    readings: tuple[ObstacleReading, ...], spacing: float, table: BodyTable | None = None
) -> tuple[FloatArray, FloatArray, FloatArray, IntArray, FloatArray]:
    """Every body as discs on its boundary: centres (M, 2) [m], velocities (M, 2) [m/s], radii
    (M,) [m], the index of the body (M,), and per body (N, 6) its first and end disc index, its
    centre and velocity (the rows of :func:`uvnav.geometry.contact.candidate_risk_compiled`, less
    the reach).  ``table``: :func:`body_table` of ``readings`` when already read (then
    ``readings`` is read only for the outlines of polygons, and may be empty when there are none).

    A disc body is one disc; a polygon's edges are sampled so that no two neighbouring samples are
    farther apart than ``spacing`` (the vertices and evenly spaced points between them), each
    sample a disc of radius ``spacing / 2`` (which covers the edges) moving with
    ``v_i + u_i x (q - c_i)``.  One pass over all edges of all bodies.

    >>> from uvnav.sensors.observation import ObstacleReading, ReadingArrays, Readings, read_arrays
    >>> z = np.zeros(2)
    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> rd = ObstacleReading(0, 1.0, z, np.array([0.5, 0.5]), z, 0.0, sq, 0.0, 0.71)
    >>> boundary_discs((rd,), 0.5)[0].shape
    (8, 2)
    """
    scal, centre, vel = body_table(readings) if table is None else table
    n, omega, disc_r = len(scal), scal[:, 1], scal[:, 2]
    if n and bool(np.all(disc_r > 0.0)):  # discs only (a crowd): each body is its own disc
        idx = np.arange(n)
        rows = np.column_stack([idx, idx + 1, centre, vel]).astype(float)
        return centre, vel, disc_r, idx, rows
    rings = [np.asarray(rd.outline, dtype=float).reshape(-1, 2) if rd.radius <= 0.0
             else centre[k : k + 1] for k, rd in enumerate(readings)]  # fmt: skip
    sizes = np.array([len(x) for x in rings], dtype=int)
    start = np.concatenate(rings) if n else np.zeros((0, 2))
    first = np.repeat(np.cumsum(sizes) - sizes, sizes)
    nxt = np.arange(len(start)) + 1
    nxt = np.where(nxt - first >= np.repeat(sizes, sizes), first, nxt)
    edge = np.where(np.repeat(disc_r > 0.0, sizes)[:, None], 0.0, start[nxt] - start)
    n_sub = np.maximum(np.ceil(np.hypot(edge[:, 0], edge[:, 1]) / spacing).astype(int), 1)
    idx = np.repeat(np.arange(len(start)), n_sub)
    frac = np.arange(len(idx)) - np.repeat(np.cumsum(n_sub) - n_sub, n_sub)
    q = start[idx] + (frac / n_sub[idx])[:, None] * edge[idx]
    owner = np.repeat(np.repeat(np.arange(n), sizes), n_sub)
    rel = q - centre[owner]
    w = vel[owner] + omega[owner, None] * np.column_stack([-rel[:, 1], rel[:, 0]])
    r = np.where(disc_r[owner] > 0.0, disc_r[owner], 0.5 * spacing - disc_r[owner])
    counts = np.bincount(owner, minlength=n)
    ends = np.cumsum(counts)
    bodies = np.column_stack([ends - counts, ends, centre, vel]).astype(float)
    return q, w, r, owner, bodies


def tangent_directions(
    position: FloatArray, centres: FloatArray, radii: FloatArray, owner: IntArray
) -> FloatArray:
    """Per body, the outermost tangent direction [rad] on each side over the circles
    (``centres``, ``radii``) of that body (v1's note 3): two angles per body (``owner``: the
    body of each circle, non-decreasing).

    A circle that holds the robot gives the directions perpendicular to its radius.

    >>> t = tangent_directions(np.zeros(2), np.array([[2.0, 0.0]]), np.array([1.0]),
    ...                        np.array([0]))
    >>> np.round(np.degrees(t), 6).tolist()
    [-30.0, 30.0]
    """
    if not len(centres):
        return np.zeros(0)
    d = centres - position
    dist = np.hypot(d[:, 0], d[:, 1])
    base = np.arctan2(d[:, 1], d[:, 0])
    with np.errstate(divide="ignore", invalid="ignore"):
        half = np.where(dist > radii, np.arcsin(np.minimum(radii / dist, 1.0)), 0.5 * np.pi)
    starts = np.flatnonzero(np.r_[True, owner[1:] != owner[:-1]])
    group = np.repeat(np.arange(len(starts)), np.diff(np.r_[starts, len(owner)]))
    order = np.lexsort((dist, group))  # by body, nearest first
    ref = base[order[starts]]
    rel = (base - ref[group] + np.pi) % (2.0 * np.pi) - np.pi
    lo = ref + np.minimum.reduceat(rel - half, starts)
    hi = ref + np.maximum.reduceat(rel + half, starts)
    return np.concatenate([lo, hi])


def reachable(table: BodyTable, v_max: float, horizon: float) -> IntArray:
    """Indices of the bodies that can come into contact with the robot within ``horizon`` [s]:
    distance <= (V_max + the body's speed + |u_i| R_i) H."""
    scal, _, vel = table
    bound = np.hypot(vel[:, 0], vel[:, 1]) + np.abs(scal[:, 1]) * scal[:, 3]
    return np.flatnonzero(scal[:, 0] <= (v_max + bound) * horizon)


def extra_headings(n_headings: int, v_pref: FloatArray, v_prev: FloatArray) -> FloatArray:
    """The candidate directions [rad] besides the tangents: ``n_headings`` evenly spread ones,
    the direction of ``v_pref`` and that of ``v_prev`` (when it is not zero)."""
    spread = 2.0 * np.pi * np.arange(n_headings) / max(n_headings, 1)
    extra = [math.atan2(v_pref[1], v_pref[0])]
    if math.hypot(v_prev[0], v_prev[1]) > 1e-9:
        extra.append(math.atan2(v_prev[1], v_prev[0]))
    return np.concatenate([spread, np.asarray(extra)])
