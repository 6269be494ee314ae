"""Planar sonar with a viewing cone, thesis Ch. 4 §4.2 (Fig. 4.3).

Reference: Y. Zhang, *Algorithms of Real-Time Navigation and Control of Autonomous Unmanned
Vehicles*, UNSW — Chapter 4, §4.2: "We use a matrix to express the distance between the vehicle
and the obstacle i in its viewing angle, d_i(t) ... only the part without covering could be
detected" (Fig. 4.3), with d_imin(t), d_imax(t) and the boundary points r_imin(t), r_imax(t)
attaining them.

The sonar is modelled as ``n_beams`` rays spread evenly over the viewing cone ``fov`` [rad]
centred on the vehicle's heading.  Each beam returns the range to the *first* obstacle boundary it
meets (exact ray casting on the obstacles' outlines with
:func:`~uvnav.geometry.polygons.rays_rings_hit`), so boundary hidden behind a nearer part of the
same or another obstacle is never returned — the occlusion of Fig. 4.3 is exact up to the beam
spacing.  Per obstacle, d_imin/d_imax and r_imin/r_imax are taken over the beams that hit it.
Which obstacle a beam hit is reported (``hit_ids``): the thesis indexes d_i(t) by obstacle, i.e.
it assumes returns are segmented per obstacle; the mass centres are known (§4.2 "we suppose that
the mass centre of the obstacle is known").

Noise and dropout: Gaussian range noise of standard deviation ``noise_std`` [m] (clipped to the
range interval) and, with probability ``dropout``, a beam returns nothing (NaN), drawn from the
generator passed in — same generator state, same reading.

:func:`close_narrow_openings` is the Fig. 4.2(b) detector: an opening between two returns whose
lips are closer than the vehicle's width cannot be passed, so the beams that look through it are
clipped to the chord between the lips (the opening is treated as a wall).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.polygons import closed_rings, rays_rings_hit, rays_segments_hit
from uvnav.sensors.sonar2d_kernels import load_pairs_kernel


@dataclass(frozen=True)
class SonarConfig:
    """A viewing-cone sonar.

    Attributes:
        n_beams: number of beams (>= 2).
        fov: opening angle of the viewing cone [rad], centred on the heading (<= 2 pi).
        max_range: maximum range [m]; beams that hit nothing report ``max_range``.
        noise_std: standard deviation of the range noise [m].
        dropout: probability that a beam returns nothing (NaN).
    """

    n_beams: int = 91
    fov: float = 4.0 * np.pi / 3.0
    max_range: float = 5.0
    noise_std: float = 0.0
    dropout: float = 0.0

    def __post_init__(self) -> None:
        if self.n_beams < 2:
            raise ValueError(f"n_beams must be >= 2 (got {self.n_beams})")
        if not (0 < self.fov <= 2 * np.pi):
            raise ValueError(f"fov must be in (0, 2 pi] rad (got {self.fov})")
        if not (self.max_range > 0):
            raise ValueError(f"max_range must be > 0 m (got {self.max_range})")
        if self.noise_std < 0 or not (0 <= self.dropout < 1):
            raise ValueError("noise_std must be >= 0 and dropout in [0, 1)")

    def beam_offsets(self) -> FloatArray:
        """Beam angles [rad] relative to the heading, increasing (counter-clockwise)."""
        if self.fov >= 2 * np.pi - 1e-12:
            return np.linspace(-np.pi, np.pi, self.n_beams, endpoint=False)
        return np.linspace(-0.5 * self.fov, 0.5 * self.fov, self.n_beams)


@dataclass(frozen=True)
class SonarReading:
    """One sonar sweep.

    Attributes:
        origin: vehicle position [m], (2,).
        angles: (B,) world beam angles [rad], increasing.
        ranges: (B,) measured ranges [m]; ``max_range`` for no return, NaN on dropout.
        hit_ids: (B,) index of the obstacle a beam hit, -1 for none or dropout.
        max_range: the sonar's range [m].
        ids: (m,) obstacles seen (sorted).
        d_min, d_max: (m,) d_imin(t), d_imax(t) [m] of each seen obstacle (visible part only).
        r_min, r_max: (m, 2) r_imin(t), r_imax(t) [m].
        centres: (k, 2) known mass centres of all obstacles [m] (thesis §4.2 assumption).
    """

    origin: FloatArray
    angles: FloatArray
    ranges: FloatArray
    hit_ids: np.ndarray
    max_range: float
    ids: np.ndarray
    d_min: FloatArray
    d_max: FloatArray
    r_min: FloatArray
    r_max: FloatArray
    centres: FloatArray

    @property
    def points(self) -> FloatArray:
        """(B, 2) return points [m]; NaN for beams without a return."""
        valid = self.hit_ids >= 0
        r = np.where(valid, self.ranges, np.nan)
        return self.origin + r[:, None] * np.stack([np.cos(self.angles), np.sin(self.angles)], 1)

    def nearest(self) -> tuple[float, FloatArray | None, int]:
        """``(d_min [m], r_min, obstacle id)`` over all seen obstacles; ``(inf, None, -1)``."""
        if len(self.ids) == 0:
            return np.inf, None, -1
        j = int(np.argmin(self.d_min))
        return float(self.d_min[j]), self.r_min[j], int(self.ids[j])


def sonar_scan(
    pose: FloatArray,
    outlines: list[FloatArray],
    rng: np.random.Generator,
    config: SonarConfig,
    *,
    centres: FloatArray | None = None,
) -> SonarReading:
    """Sweep the viewing cone from ``pose`` = [x, y, heading] over the obstacles' ``outlines``.

    Args:
        pose: vehicle ``[x, y, theta]`` ([m], [m], [rad]).
        outlines: world vertices (n_i, 2) of every obstacle [m].
        rng: generator for noise and dropout (untouched when both are 0).
        config: the sonar.
        centres: (k, 2) known mass centres [m] passed through to the reading.

    Returns:
        The :class:`SonarReading`.
    """
    origin = np.asarray(pose[:2], dtype=float)
    angles = float(pose[2]) + config.beam_offsets()
    angles = np.pi - np.mod(np.pi - angles, 2.0 * np.pi)
    b = len(angles)
    dirs = np.stack([np.cos(angles), np.sin(angles)], axis=-1)
    if outlines:
        rings, _ = closed_rings(outlines)
        t = rays_rings_hit(origin, dirs, rings)  # (B, k): first hit per obstacle
        hit = t.argmin(axis=1)
        rng_true = t[np.arange(b), hit]
    else:
        hit = np.zeros(b, dtype=np.intp)
        rng_true = np.full(b, np.inf)
    seen = rng_true <= config.max_range
    hit_ids = np.where(seen, hit, -1).astype(np.intp)
    ranges = np.where(seen, rng_true, config.max_range)
    if config.noise_std > 0:
        noisy = ranges + rng.normal(0.0, config.noise_std, size=b)
        ranges = np.where(seen, np.clip(noisy, 0.0, config.max_range), ranges)
    if config.dropout > 0:
        drop = rng.random(b) < config.dropout
        ranges = np.where(drop, np.nan, ranges)
        hit_ids = np.where(drop, -1, hit_ids)
    ids, d_min, d_max, r_min, r_max = per_obstacle_extremes(origin, angles, ranges, hit_ids)
    cen = np.zeros((0, 2)) if centres is None else np.asarray(centres, dtype=float)
    return SonarReading(
        origin=origin,
        angles=angles,
        ranges=ranges,
        hit_ids=hit_ids,
        max_range=float(config.max_range),
        ids=ids,
        d_min=d_min,
        d_max=d_max,
        r_min=r_min,
        r_max=r_max,
        centres=cen,
    )


def per_obstacle_extremes(
    origin: FloatArray, angles: FloatArray, ranges: FloatArray, hit_ids: np.ndarray
) -> tuple[np.ndarray, FloatArray, FloatArray, FloatArray, FloatArray]:
    """d_imin, d_imax [m] and r_imin, r_imax [m] of every obstacle hit by some beam.

    Returns:
        ``(ids (m,), d_min (m,), d_max (m,), r_min (m, 2), r_max (m, 2))``.
    """
    valid = hit_ids >= 0
    ids = np.unique(hit_ids[valid])
    m = len(ids)
    d_min = np.empty(m)
    d_max = np.empty(m)
    r_min = np.empty((m, 2))
    r_max = np.empty((m, 2))
    dirs = np.stack([np.cos(angles), np.sin(angles)], axis=-1)
    for j, i in enumerate(ids):
        beams = np.flatnonzero(hit_ids == i)
        rr = ranges[beams]
        lo, hi = beams[int(np.argmin(rr))], beams[int(np.argmax(rr))]
        d_min[j], d_max[j] = ranges[lo], ranges[hi]
        r_min[j] = origin + ranges[lo] * dirs[lo]
        r_max[j] = origin + ranges[hi] * dirs[hi]
    return ids, d_min, d_max, r_min, r_max


def close_narrow_openings(
    origin: FloatArray,
    angles: FloatArray,
    ranges: FloatArray,
    hit_ids: np.ndarray,
    width: float,
    *,
    engine: str = "auto",
) -> tuple[FloatArray, np.ndarray]:
    """Treat openings narrower than ``width`` [m] as walls (the Fig. 4.2(b) detector).

    For every pair of returns i < j (by beam order) whose points are closer than ``width``, the
    beams strictly between them that see *beyond* the chord p_i p_j are clipped to the chord and
    attributed to the obstacle of return i.  A vehicle of that width could not pass between the
    two points, so what lies behind them (the inner space of Fig. 4.2(b), or the far side of a
    gap between two bodies) is unreachable and must not look free.

    Args:
        origin: sonar position [m].
        angles: (B,) beam angles [rad], in beam order.
        ranges: (B,) ranges [m] (NaN: dropout).
        hit_ids: (B,) obstacle per beam, -1 for none.
        width: the vehicle's width plus margin [m].
        engine: ``"auto"`` (the compiled pair search of :mod:`~uvnav.sensors.sonar2d_kernels`
            when numba is installed), ``"numpy"``; both give the same result.

    Returns:
        ``(ranges, hit_ids)`` with the closed beams clipped (copies).
    """
    valid = hit_ids >= 0
    idx = np.flatnonzero(valid)
    out_r = np.array(ranges, dtype=float)
    out_id = np.array(hit_ids)
    if len(idx) < 2:
        return out_r, out_id
    dirs = np.stack([np.cos(angles), np.sin(angles)], axis=-1)
    pts = origin + ranges[idx, None] * dirs[idx]
    rr = ranges[idx]
    kernel = None if engine == "numpy" else load_pairs_kernel()
    if kernel is not None:  # the same pairs in the same order, one compiled loop
        ii, jj = kernel(
            np.ascontiguousarray(pts[:, 0]), np.ascontiguousarray(pts[:, 1]), rr, idx, width
        )
    else:
        d = np.hypot(*(pts[:, None, :] - pts[None, :, :]).transpose(2, 0, 1))
        n = len(idx)
        # deepest return strictly between returns i and j (in return order): running max per row
        upper = np.where(np.arange(n)[None, :] > np.arange(n)[:, None], rr[None, :], -np.inf)
        runmax = np.maximum.accumulate(upper, axis=1)  # runmax[i, m] = max rr[i+1..m]
        ii, jj = np.nonzero(np.triu(d < width, k=1))
        # only pairs with something to close: a beam without a return between them, or a
        # return deeper than both lips (a flat or convex stretch between close returns is left)
        missing = (idx[jj] - idx[ii]) > (jj - ii)
        deeper = (jj - ii >= 2) & (runmax[ii, np.maximum(jj - 1, 0)] > np.maximum(rr[ii], rr[jj]))
        keep = (idx[jj] - idx[ii] >= 2) & (missing | deeper)
        ii, jj = ii[keep], jj[keep]
    if len(ii) == 0:
        return out_r, out_id
    t = rays_segments_hit(origin, dirs, pts[ii], pts[jj])  # (B, P)
    beam = np.arange(len(angles))[:, None]
    between = (beam > idx[ii][None, :]) & (beam < idx[jj][None, :])
    t = np.where(between, t, np.inf)
    clip = t.min(axis=1)
    src = t.argmin(axis=1)
    far = np.where(np.isnan(out_r), np.inf, np.where(valid, out_r, np.inf))
    closed = np.isfinite(clip) & (clip < far)
    out_r[closed] = clip[closed]
    out_id[closed] = hit_ids[idx[ii][src[closed]]]
    return out_r, out_id


@dataclass(frozen=True)
class SonarObservation:
    """Everything a Chapter-4 UUV law may use at one decision time.

    Attributes:
        time: simulation time [s].
        pose: the vehicle's own ``[x, y, theta]`` ([m], [m], [rad]).
        velocity: the velocity command being applied [m/s], (2,).
        goal: the end point E [m], (2,).
        sonar: the sweep taken now.
        period: the decision period T [s].
    """

    time: float
    pose: FloatArray
    velocity: FloatArray
    goal: FloatArray
    sonar: SonarReading
    period: float

    @property
    def position(self) -> FloatArray:
        return self.pose[:2]

    @property
    def heading(self) -> float:
        return float(self.pose[2])
