"""Rigid obstacle bodies in 2D: discs and simple polygons (non-convex allowed), thesis Ch. 2 §2.2.

A body is described in its own frame with the mass centre (area centroid) at the origin, so that
"revolving around the mass centre with angular velocity u_i" (thesis §2.2) is a rotation of the
local frame.  :func:`rotation_boundary_growth` measures the thesis's Delta-distance of Fig. 2.2 /
constraint (2.8).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Any

import numpy as np
import shapely

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.kernels3d import compile_family, numba_enabled
from uvnav.geometry.polygons import (
    _EPS,
    polygon_area,
    polygon_centroid,
    polygon_edges,
    rays_segments_hit,
)


@dataclass(frozen=True)
class DiscBody:
    """A disc of ``radius`` [m] centred on the mass centre."""

    radius: float

    @property
    def bounding_radius(self) -> float:
        """Radius [m] of the smallest centroid-centred disc containing the body."""
        return float(self.radius)

    def outline(self, n: int = 48) -> FloatArray:
        """A counter-clockwise ``n``-gon inscribed in the disc, local frame [m] (for plots only)."""
        a = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
        return self.radius * np.stack([np.cos(a), np.sin(a)], axis=-1)


@dataclass(frozen=True)
class PolygonBody:
    """A simple polygon; ``vertices`` (n, 2) [m] are stored counter-clockwise about the centroid.

    Use :meth:`from_vertices` to build one from arbitrary coordinates: it re-centres the polygon on
    its area centroid and fixes the orientation.  ``offset`` is the centroid's position in the
    coordinates the vertices were given in.
    """

    vertices: FloatArray
    offset: FloatArray = field(default_factory=lambda: np.zeros(2))

    @classmethod
    def from_vertices(cls, vertices: FloatArray) -> PolygonBody:
        v = np.asarray(vertices, dtype=float)
        if v.ndim != 2 or v.shape[1] != 2 or len(v) < 3:
            raise ValueError("a polygon needs at least 3 vertices given as [x, y] pairs")
        if abs(polygon_area(v)) < 1e-12:
            raise ValueError("polygon has zero area")
        if not shapely.is_valid(shapely.polygons(v)):
            raise ValueError("polygon is not simple (its edges cross)")
        c = polygon_centroid(v)
        local = v - c
        if polygon_area(local) < 0:
            local = local[::-1].copy()
        return cls(vertices=local, offset=c)

    @property
    def bounding_radius(self) -> float:
        return float(np.hypot(self.vertices[:, 0], self.vertices[:, 1]).max())

    def outline(self, n: int = 0) -> FloatArray:
        return self.vertices


Body = DiscBody | PolygonBody


def radial_profile(body: Body, n_directions: int = 360) -> tuple[FloatArray, FloatArray]:
    """Farthest boundary distance [m] from the mass centre along ``n_directions`` rays.

    Returns ``(angles [rad], rho [m])``.  For a star-shaped body this is its radial function.
    """
    angles, dirs = _directions(n_directions)
    if isinstance(body, DiscBody):
        return angles.copy(), np.full(n_directions, body.radius)
    s, e = polygon_edges(body.vertices)
    t = rays_segments_hit(np.zeros(2), dirs, s, e)
    t = np.where(np.isfinite(t), t, -np.inf)
    return angles.copy(), t.max(axis=1)


@lru_cache(maxsize=8)
def _directions(n_directions: int) -> tuple[FloatArray, FloatArray]:
    """The ray angles [rad] of :func:`radial_profile` and their unit directions (read-only)."""
    angles = np.linspace(-np.pi, np.pi, n_directions, endpoint=False)
    dirs = np.stack([np.cos(angles), np.sin(angles)], axis=-1)
    angles.flags.writeable = dirs.flags.writeable = False
    return angles, dirs


def rotation_boundary_growth(body: Body, rotation: float, n_directions: int = 360) -> float:
    """The thesis's Delta-distance (Fig. 2.2, constraint (2.8)) for a rotation of ``rotation``
    [rad].

    Along a fixed ray from the mass centre, the boundary moves outward while the body turns; the
    thesis calls the largest outward excursion ``B_max - B_initial``.  This returns its maximum over
    all ray directions and over rotations of up to ``|rotation|`` in either sense [m].  Zero for a
    disc.  Compiled by numba when it is enabled (:func:`growth_py`, the same numbers).
    """
    if isinstance(body, DiscBody) or rotation == 0.0:
        return 0.0
    step = 2.0 * np.pi / n_directions
    shifts = int(np.ceil(abs(rotation) / step))
    if numba_enabled():
        if not _GROWTH:
            _GROWTH.append(compile_family([growth_py])["growth_py"])
        _, dirs = _directions(n_directions)
        verts = np.ascontiguousarray(body.vertices, dtype=float)
        return float(_GROWTH[0](verts, dirs, min(shifts, n_directions)))
    _, rho = radial_profile(body, n_directions)
    # every turn of k = 1..shifts samples in both senses at once: rho[i -+ k] - rho[i]
    n = len(rho)
    k = np.arange(1, min(shifts, n) + 1)[:, None]
    i = np.arange(n)[None, :]
    back = rho[(i - k) % n] - rho
    ahead = rho[(i + k) % n] - rho
    return max(0.0, float(back.max()), float(ahead.max()))


def growth_py(verts: FloatArray, dirs: FloatArray, kmax: int) -> float:
    """:func:`rotation_boundary_growth` of the polygon ``verts`` (n, 2) as loops, for numba:
    :func:`radial_profile` by :func:`~uvnav.geometry.polygons.rays_segments_hit`'s operations,
    then the largest ``rho[i -+ k] - rho[i]`` for k = 1..``kmax`` (NaN kept, as ``ndarray.max``
    keeps it, and skipped, as the builtin ``max`` skips it)."""
    n_rays, n_edges = dirs.shape[0], verts.shape[0]
    rho = np.empty(n_rays)
    for r in range(n_rays):
        d0, d1 = dirs[r, 0], dirs[r, 1]
        best = -np.inf
        for e in range(n_edges):
            sx, sy = verts[e, 0], verts[e, 1]
            f = e + 1 if e + 1 < n_edges else 0
            g0, g1 = verts[f, 0] - sx, verts[f, 1] - sy
            denom = d0 * g1 - d1 * g0
            safe = 1.0 if abs(denom) < _EPS else denom
            t = (sx * g1 - sy * g0) / safe
            u = (sx * d1 - sy * d0) / safe
            hit = abs(denom) >= _EPS and t >= 0.0 and u >= 0.0 and u <= 1.0
            if hit and t - t == 0.0 and t > best:  # a finite hit (a miss counts as -inf)
                best = t
        rho[r] = best
    tops = [0.0, 0.0]  # the largest growth turning back (-k) and ahead (+k)
    for side in range(2):
        top, nan = -np.inf, False
        for k in range(1, kmax + 1):
            for i in range(n_rays):
                j = (i - k) % n_rays if side == 0 else (i + k) % n_rays
                v = rho[j] - rho[i]
                if v != v:
                    nan = True
                elif v > top:
                    top = v
        tops[side] = np.nan if nan else top
    out = 0.0
    for v in tops:
        if v > out:
            out = v
    return out


#: the compiled :func:`growth_py`
_GROWTH: list[Callable[..., Any]] = []
