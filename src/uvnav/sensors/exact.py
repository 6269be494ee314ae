"""Exact range-limited obstacle sensing (thesis Ch. 2 §2.2, eq. (2.5)) and a lidar range scanner.

Both are pure functions of the robot pose, the :class:`~uvnav.obstacles.ObstacleField` and, for
noise and dropout, a ``numpy.random.Generator``.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from uvnav.geometry.angles import FloatArray, wrap_to_pi
from uvnav.obstacles.obstacle import ObstacleField
from uvnav.sensors.observation import LidarScan, ObstacleReading, ReadingArrays, Readings

_EMPTY = np.zeros((0, 2))


def sense_obstacles(
    position: FloatArray,
    field: ObstacleField,
    *,
    sensing_range: float = np.inf,
) -> tuple[ObstacleReading, ...]:
    """Readings of every obstacle whose set lies within ``sensing_range`` [m], nearest first.

    Velocities and angular velocities are the true ones (``velocity_source="known"``); the
    simulator swaps in estimates when configured to (see :mod:`uvnav.prediction.finite_difference`).

    The distances come from :meth:`ObstacleField.query`, which culls far obstacles exactly and
    remembers its last answer: the simulator makes that query for its collision check at every
    integration step (covering ``sensing_range`` before a decision), so sensing reuses it.  Ties
    in distance keep obstacle order.
    """
    if len(field) == 0:
        return ()
    q = field.query(position, sensing_range, nearest=False)
    dist = q.distance
    ids = q.ids
    if len(dist) == 0:
        return ()
    by = np.argsort(dist, kind="stable")
    beyond = dist[by] > sensing_range  # nearest first: the readings end at the first beyond
    kept = by[: int(np.argmax(beyond))] if bool(beyond.any()) else by
    if len(kept) == 0:
        return ()
    j = ids[kept]
    d, centre, vel, near = dist[kept], field.centres[j], field.velocities[j], q.nearest[kept]
    omega, radius, bound = field.angular_velocities[j], field.radii[j], field.bounding_radii[j]
    rows = zip(j.tolist(), d.tolist(), omega.tolist(), radius.tolist(), bound.tolist(),
               map(q.outline, kept.tolist()), strict=True)  # fmt: skip
    make = ObstacleReading.known  # each reading's arrays are views of the rows gathered above
    out = [
        make(jk, dk, near[k], centre[k], vel[k], w, _EMPTY if poly is None else poly, r, b)
        for k, (jk, dk, w, r, b, poly) in enumerate(rows)
    ]

    def arrays() -> ReadingArrays:
        scal = np.column_stack((d, omega, radius, bound)).astype(float, copy=False)
        return scal, centre, vel

    return Readings.lazy(out, arrays, all_known=True)


@functools.lru_cache(maxsize=64)
def beam_offsets(n_rays: int, fov: float) -> FloatArray:
    """The beams' angles relative to the heading [rad]: ``n_rays`` evenly over a full turn
    (from -pi, the last short of pi) or over ``fov`` (both ends included); read-only, shared.

    >>> beam_offsets(4, 2.0 * np.pi).tolist() == [-np.pi, -np.pi / 2, 0.0, np.pi / 2]
    True
    """
    if fov >= 2.0 * np.pi - 1e-9:
        rel = np.linspace(-np.pi, np.pi, n_rays, endpoint=False)
    else:
        rel = np.linspace(-0.5 * fov, 0.5 * fov, n_rays)
    rel.flags.writeable = False
    return rel


def beam_turns(rel: FloatArray) -> FloatArray:
    """The beams' offsets ``rel`` (R,) [rad] as rotations (2, R): libm's cos and sin of each
    (``math.cos``, ``math.sin``, as the compiled lidar computes them).

    >>> beam_turns(np.array([0.0, np.pi / 2])).round(12).tolist()
    [[1.0, 0.0], [0.0, 1.0]]
    """
    return np.array([[math.cos(a) for a in rel.tolist()], [math.sin(a) for a in rel.tolist()]],
                    dtype=float).reshape(2, len(rel))  # fmt: skip


@functools.lru_cache(maxsize=64)
def _offset_turns(n_rays: int, fov: float) -> FloatArray:
    """:func:`beam_turns` of :func:`beam_offsets`, read-only, shared."""
    turns = beam_turns(beam_offsets(n_rays, fov))
    turns.flags.writeable = False
    return turns


def beam_directions(theta: float, turns: FloatArray) -> FloatArray:
    """Unit directions (R, 2) of the beams at offsets ``turns`` (:func:`beam_turns`) from the
    heading ``theta`` [rad]: each offset's rotation turned by libm's cos and sin of ``theta``,
    the way a range sensor's beams are fixed in its frame.  The compiled lidar
    (:mod:`uvnav.sim.packed_sense`) computes the same products, so both casts see the same
    beams bit for bit; each is within a few 1e-16 of ``(cos, sin)`` of ``theta`` plus the
    offset.

    >>> d = beam_directions(0.3, beam_turns(np.array([0.0, 0.2])))
    >>> bool(np.allclose(d, [[math.cos(0.3), math.sin(0.3)], [math.cos(0.5), math.sin(0.5)]]))
    True
    """
    c, s = math.cos(theta), math.sin(theta)
    return np.stack([c * turns[0] - s * turns[1], s * turns[0] + c * turns[1]], axis=-1)


def lidar_scan(
    pose: FloatArray,
    field: ObstacleField,
    rng: np.random.Generator | None = None,
    *,
    n_rays: int = 72,
    max_range: float = 5.0,
    fov: float = 2.0 * np.pi,
    noise_std: float = 0.0,
    dropout: float = 0.0,
) -> LidarScan:
    """A planar range scan centred on the robot's heading.

    Beam angles are in the world frame, wrapped to (-pi, pi]; the beams cast along
    :func:`beam_directions` (the sensor's fixed offsets turned by the heading).  Obstacles whose
    bounding disc lies beyond ``max_range`` are not ray-cast (they cannot change a range).

    Args:
        pose: ``[x, y, theta]``.
        n_rays: number of beams, evenly spread over ``fov`` [rad].
        max_range: range [m] reported when a beam hits nothing.
        noise_std: standard deviation [m] of additive Gaussian range noise (needs ``rng``).
        dropout: probability that a beam returns NaN (needs ``rng``).
    """
    x, y, th = float(pose[0]), float(pose[1]), float(pose[2])
    angles = wrap_to_pi(th + beam_offsets(int(n_rays), float(fov)))
    dirs = beam_directions(th, _offset_turns(int(n_rays), float(fov)))
    ranges = np.full(n_rays, max_range)
    if len(field):
        hits = field.ray_hits(np.array([x, y]), dirs, max_range=max_range).min(axis=1)
        ranges = np.minimum(hits, max_range)
    if (noise_std > 0 or dropout > 0) and rng is None:
        raise ValueError("lidar noise or dropout needs a numpy.random.Generator")
    if noise_std > 0 and rng is not None:
        hit = ranges < max_range
        ranges = np.where(
            hit, np.clip(ranges + rng.normal(0.0, noise_std, n_rays), 0.0, max_range), ranges
        )
    if dropout > 0 and rng is not None:
        ranges = np.where(rng.random(n_rays) < dropout, np.nan, ranges)
    return LidarScan(angles=angles, ranges=ranges, max_range=max_range)
