"""The nine-sonar array of the 3D underwater vehicle (thesis Ch. 5, §5.2.3, Fig. 5.2, eq. (5.8)).

Reference: Y. Zhang and J. Zhang, ICCAE 2022; thesis Chapter 5 §5.2.3: nine sonar sensors S1..S9
"arranged evenly" over "a smooth and convex space in the front of the robot", S1 at its centre
(the leading position); "the output of each sensor is the distance between the sensor and the
nearest point on the object in its vision cone"; the sensors "are not in the plane", so an
"adaptive coefficient" transfers each reading to a distance from S1; R(t) = [R1 ... R9] (5.8).

Geometry chosen (the thesis gives only a sketch, Fig. 5.2 — see docs/thesis-notes.md):

* the hull is the vehicle's sphere of radius ``rho`` (the ``radius`` of
  :class:`~uvnav.dynamics.vehicle3d.Vehicle3DSpec`); the convex front surface is its spherical cap
  about the heading a_R;
* S1 sits at the cap centre ``c + rho a``; S2..S9 on the cap's rim circle at polar angle ``beta``
  from a_R, 45 deg apart in azimuth, starting from "up" (S2) and going clockwise seen from behind
  (S3 up-right, S4 right, ..., S9 up-left).  "Up" is ``e_up = e_right x a`` with ``e_right =
  a x z / |a x z|`` (:func:`uvnav.geometry.frames3d.horizontal_perpendicular`), so the ring does
  not roll with the vehicle;
* each beam axis is the outward surface normal at its sensor, and the beam a circular cone of
  half-angle ``alpha`` with its apex at the sensor.

Reading (exact, :func:`cone_nearest`): the distance from the apex to the nearest point of the
obstacles' triangle meshes inside the cone (or ``max_range`` when there is none within range).  For
one triangle, the nearest point of (triangle ∩ cone) to the apex is one of: (1) the triangle's own
nearest point (Ericson's kernel) when it lies in the cone; (2) the nearest point of an edge clipped
to the cone (the clip is an interval, found from the roots of the quadratic cone equation); (3) the
point of the triangle's plane on the cone's lateral surface closest to the apex (the generator
maximising ``n . g``, closed form) when it lies in the triangle.  This is exact because the cone
(alpha < 90 deg) and the triangle are convex and the squared distance has a single critical point
on each piece of the boundary.  The nearest in-cone point of a solid is on its surface and visible
from the apex (the cone is star-shaped from its apex), so no occlusion test is needed.

Adaptive coefficient (:func:`adaptive_coefficients`): an echo at range ``R_i`` along beam i is
taken at ``s_i + R_i n_i``; its distance from S1 is ``D_i(R_i) = |s_i - s_1 + R_i n_i|`` and the
coefficient ``k_i(R_i) = D_i(R_i) / R_i`` (k_1 = 1) — it depends on the reading itself (hence
"adaptive") and on the array geometry only.  The network's inputs are ``k_i R_i`` (5.8).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.frames3d import horizontal_perpendicular
from uvnav.geometry.mesh3d import Triangles, closest_barycentric

N_SONARS = 9


@dataclass(frozen=True)
class SonarArray:
    """The array's geometry and its measurement options.

    Attributes:
        hull_radius: rho, radius of the vehicle's spherical hull [m] (> 0).
        ring_angle: beta, polar angle of S2..S9 from the heading [rad] (0 < beta < pi/2).
        half_angle: alpha, half-angle of every beam cone [rad] (0 < alpha < pi/2).
        max_range: largest range a sonar reports [m]; "no echo" reads ``max_range``.
        noise_std: std of Gaussian range noise [m] (0: exact).
        dropout: probability that a sensor misses its echo (reads ``max_range``).
    """

    hull_radius: float = 0.5
    ring_angle: float = math.radians(35.0)
    half_angle: float = math.radians(20.0)
    max_range: float = 8.0
    noise_std: float = 0.0
    dropout: float = 0.0

    def __post_init__(self) -> None:
        if not (math.isfinite(self.hull_radius) and self.hull_radius > 0):
            raise ValueError(f"hull_radius must be > 0 (got {self.hull_radius!r})")
        for name in ("ring_angle", "half_angle"):
            v = getattr(self, name)
            if not (0.0 < v < 0.5 * math.pi):
                raise ValueError(f"{name} must be in (0, pi/2) rad (got {v!r})")
        if not (math.isfinite(self.max_range) and self.max_range > 0):
            raise ValueError(f"max_range must be > 0 (got {self.max_range!r})")
        if not (self.noise_std >= 0 and math.isfinite(self.noise_std)):
            raise ValueError(f"noise_std must be >= 0 (got {self.noise_std!r})")
        if not 0.0 <= self.dropout <= 1.0:
            raise ValueError(f"dropout must be in [0, 1] (got {self.dropout!r})")

    def body_directions(self) -> FloatArray:
        """Beam axes n_1..n_9 in the body frame (x forward, y right, z up), (9, 3)."""
        out = [np.array([1.0, 0.0, 0.0])]
        cb, sb = math.cos(self.ring_angle), math.sin(self.ring_angle)
        for k in range(8):
            psi = k * math.pi / 4.0
            out.append(np.array([cb, sb * math.sin(psi), sb * math.cos(psi)]))
        return np.stack(out)

    def placement(self, position: FloatArray, heading: FloatArray) -> tuple[FloatArray, FloatArray]:
        """World positions s_i [m] and beam axes n_i of S1..S9 for a vehicle at ``position`` with
        unit ``heading``: ``((9, 3), (9, 3))``."""
        a = np.asarray(heading, dtype=float)
        right = horizontal_perpendicular(a)
        up = np.cross(right, a)
        body = self.body_directions()
        axes = body[:, :1] * a + body[:, 1:2] * right + body[:, 2:3] * up
        return np.asarray(position, dtype=float) + self.hull_radius * axes, axes


def _inside_cone(
    points: FloatArray, apex: FloatArray, axis: FloatArray, cos_a: float, tol: float = 1e-9
) -> np.ndarray:
    rel = points - apex
    dist = np.sqrt(np.einsum("ij,ij->i", rel, rel))
    return np.asarray(rel @ axis >= cos_a * dist - tol * np.maximum(1.0, dist))


def cone_nearest(
    apex: FloatArray,
    axis: FloatArray,
    half_angle: float,
    tri: Triangles,
    max_range: float = math.inf,
    *,
    chunk: int = 32,
) -> tuple[float, FloatArray | None]:
    """Distance [m] from ``apex`` to the nearest point of the triangles inside the cone of unit
    ``axis`` and ``half_angle`` [rad] (< pi/2), and that point; ``(inf, None)`` when no point lies
    within ``max_range`` [m].  Exact (module docstring), vectorised over triangles.

    Triangles whose bounding sphere misses the cone or the range are culled; the rest are taken in
    ``chunk``-sized groups in order of the lower bound ``|centre - apex| - radius`` and the search
    stops when that bound exceeds the best distance found (branch and bound: the result is the
    same as with all triangles)."""
    p0 = np.asarray(apex, dtype=float)
    ax = np.asarray(axis, dtype=float)
    cos_a, sin_a = math.cos(half_angle), math.sin(half_angle)
    if len(tri) == 0:
        return math.inf, None
    gap = tri.centre - p0
    dc = np.sqrt(np.einsum("ij,ij->i", gap, gap))
    with np.errstate(invalid="ignore", divide="ignore"):
        ang = np.arccos(np.clip((gap @ ax) / np.maximum(dc, 1e-300), -1.0, 1.0))
        spread = np.arcsin(np.clip(tri.radius / np.maximum(dc, 1e-300), 0.0, 1.0))
    lower = dc - tri.radius
    keep = (lower <= max_range) & ((dc <= tri.radius) | (ang <= half_angle + spread))
    idx = np.flatnonzero(keep)
    if len(idx) == 0:
        return math.inf, None
    idx = idx[np.argsort(lower[idx], kind="stable")]
    best, best_p = math.inf, None
    for start in range(0, len(idx), chunk):
        part = idx[start : start + chunk]
        if lower[part[0]] > best:
            break
        d, q = _cone_nearest_subset(p0, ax, cos_a, sin_a, tri.subset(part))
        if d < best:
            best, best_p = d, q
    if best > max_range:
        return math.inf, None
    return best, best_p


def _cone_nearest_subset(
    p0: FloatArray, ax: FloatArray, cos_a: float, sin_a: float, t: Triangles
) -> tuple[float, FloatArray | None]:
    """The exact kernel of :func:`cone_nearest` on a set of triangles."""
    cands: list[FloatArray] = []
    # (1) each triangle's own nearest point, when it is in the cone
    v, w = closest_barycentric(p0, t)
    q = t.a + t.ab * v[:, None] + t.ac * w[:, None]
    cands.append(q[_inside_cone(q, p0, ax, cos_a)])
    # (2) edges clipped to the cone
    P = np.concatenate([t.a, t.b, t.c])
    E = np.concatenate([t.ab, t.c - t.b, t.a - t.c])
    wv = P - p0
    aE, aw = E @ ax, wv @ ax
    EE = np.einsum("ij,ij->i", E, E)
    wE = np.einsum("ij,ij->i", wv, E)
    ww = np.einsum("ij,ij->i", wv, wv)
    c2 = cos_a * cos_a
    A = aE * aE - c2 * EE
    B = 2.0 * (aw * aE - c2 * wE)
    C = aw * aw - c2 * ww
    with np.errstate(invalid="ignore", divide="ignore"):
        disc = B * B - 4.0 * A * C
        sq = np.sqrt(np.maximum(disc, 0.0))
        quad = np.abs(A) > 1e-14 * np.maximum(EE, 1e-300)
        r1 = np.where(quad, (-B - sq) / (2.0 * A), np.where(np.abs(B) > 0, -C / B, np.nan))
        r2 = np.where(quad, (-B + sq) / (2.0 * A), np.nan)
        r1 = np.where(quad & (disc < 0), np.nan, r1)
        r2 = np.where(quad & (disc < 0), np.nan, r2)
    svals = np.stack([np.zeros_like(A), np.ones_like(A), r1, r2], axis=1)  # (k, 4)
    valid = np.isfinite(svals) & (svals >= 0.0) & (svals <= 1.0)
    s_safe = np.where(valid, svals, 0.0)
    pts = P[:, None, :] + s_safe[:, :, None] * E[:, None, :]
    ins = _inside_cone(pts.reshape(-1, 3), p0, ax, cos_a).reshape(-1, 4) & valid
    has = ins.any(axis=1)
    s_lo = np.where(ins, s_safe, np.inf).min(axis=1)
    s_hi = np.where(ins, s_safe, -np.inf).max(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        s_star = np.where(EE > 0, -wE / EE, 0.0)
    s_star = np.clip(s_star[has], s_lo[has], s_hi[has])
    cands.append(P[has] + s_star[:, None] * E[has])
    # (3) the plane's point on the lateral surface nearest the apex, when inside the triangle
    nrm = np.cross(t.ab, t.ac)
    nn = np.linalg.norm(nrm, axis=1)
    ok = nn > 0
    nrm = nrm[ok] / nn[ok][:, None]
    a3, ab3, ac3 = t.a[ok], t.ab[ok], t.ac[ok]
    h = np.einsum("ij,ij->i", nrm, a3 - p0)
    na = nrm @ ax
    nperp = nrm - na[:, None] * ax
    npn = np.linalg.norm(nperp, axis=1)
    fallback = horizontal_perpendicular(ax)
    e = np.where(npn[:, None] > 1e-12, nperp / np.maximum(npn, 1e-300)[:, None], fallback)
    sg = np.sign(h)
    e = e * sg[:, None]
    m = sg * cos_a * na + sin_a * npn
    good = (m > 1e-12) & (sg != 0)
    if np.any(good):
        tt = np.abs(h[good]) / m[good]
        g = cos_a * ax + sin_a * e[good]
        X = p0 + tt[:, None] * g
        v0, v1, v2 = ab3[good], ac3[good], X - a3[good]
        d00 = np.einsum("ij,ij->i", v0, v0)
        d01 = np.einsum("ij,ij->i", v0, v1)
        d11 = np.einsum("ij,ij->i", v1, v1)
        d20 = np.einsum("ij,ij->i", v2, v0)
        d21 = np.einsum("ij,ij->i", v2, v1)
        den = d00 * d11 - d01 * d01
        with np.errstate(invalid="ignore", divide="ignore"):
            bv = (d11 * d20 - d01 * d21) / den
            bw = (d00 * d21 - d01 * d20) / den
        tol = 1e-9
        in_tri = (den > 0) & (bv >= -tol) & (bw >= -tol) & (bv + bw <= 1.0 + tol)
        cands.append(X[in_tri])
    allc = np.concatenate(cands) if cands else np.zeros((0, 3))
    if len(allc) == 0:
        return math.inf, None
    rel = allc - p0
    d = np.sqrt(np.einsum("ij,ij->i", rel, rel))
    k = int(np.argmin(d))
    return float(d[k]), allc[k]


def merge_triangles(parts: Sequence[Triangles]) -> Triangles:
    """One :class:`Triangles` holding all of ``parts`` (for a single vectorised query)."""
    if len(parts) == 1:
        return parts[0]
    if not parts:
        z = np.zeros((0, 3))
        return Triangles.from_corners(z, z, z)
    return Triangles.from_corners(
        np.concatenate([p.a for p in parts]),
        np.concatenate([p.b for p in parts]),
        np.concatenate([p.c for p in parts]),
    )


@dataclass(frozen=True)
class SonarScan:
    """One reading of the array.

    Attributes:
        ranges: R(t) = [R1..R9] [m] (5.8), ``max_range`` where there is no echo.
        echo: (9,) booleans, True where the sensor got an echo (not dropped, within range).
        points: (9, 3) exact echo points [m] (NaN without echo) — ground truth, for tests/figures.
        sensor_positions: (9, 3) s_i [m].
        axes: (9, 3) beam axes n_i.
    """

    ranges: FloatArray
    echo: np.ndarray
    points: FloatArray
    sensor_positions: FloatArray
    axes: FloatArray


def sonar_scan(
    array: SonarArray,
    position: FloatArray,
    heading: FloatArray,
    tri: Triangles,
    rng: np.random.Generator | None = None,
) -> SonarScan:
    """R(t) of the array on a vehicle at ``position`` [m] with unit ``heading`` among the obstacle
    triangles ``tri`` (exact cone returns, then noise and dropout drawn from ``rng``).

    Raises:
        ValueError: noise or dropout requested without a generator.
    """
    if (array.noise_std > 0 or array.dropout > 0) and rng is None:
        raise ValueError("sonar noise/dropout need a numpy Generator (rng)")
    s, n = array.placement(position, heading)
    ranges = np.full(N_SONARS, array.max_range)
    points = np.full((N_SONARS, 3), np.nan)
    echo = np.zeros(N_SONARS, dtype=bool)
    for i in range(N_SONARS):
        d, q = cone_nearest(s[i], n[i], array.half_angle, tri, array.max_range)
        if q is not None:
            ranges[i], points[i], echo[i] = d, q, True
    if rng is not None and (array.noise_std > 0 or array.dropout > 0):
        noise = rng.normal(0.0, array.noise_std, N_SONARS) if array.noise_std > 0 else 0.0
        drop = rng.random(N_SONARS) < array.dropout if array.dropout > 0 else np.zeros(9, bool)
        ranges = np.where(echo, np.clip(ranges + noise, 0.0, array.max_range), ranges)
        echo = echo & ~drop
        ranges = np.where(drop, array.max_range, ranges)
    return SonarScan(ranges=ranges, echo=echo, points=points, sensor_positions=s, axes=n)


def adaptive_coefficients(array: SonarArray, ranges: FloatArray) -> FloatArray:
    """k_i(R_i) = |s_i - s_1 + R_i n_i| / R_i (k_1 = 1): maps each reading to a distance from S1
    (module docstring).  Depends only on the array geometry and the readings [m], (9,) -> (9,).
    A zero reading is divided by a tiny epsilon instead of 0 (its product k R stays exact).
    """
    r = np.asarray(ranges, dtype=float)
    body = array.body_directions()
    s = array.hull_radius * body
    rel = s - s[0] + r[:, None] * body
    dist = np.linalg.norm(rel, axis=1)
    return np.asarray(dist / np.maximum(r, 1e-9))


def adapted_ranges(array: SonarArray, ranges: FloatArray) -> FloatArray:
    """The network's inputs k_i R_i = distance [m] of each echo point from S1, (..., 9)."""
    r = np.asarray(ranges, dtype=float)
    body = array.body_directions()
    s = array.hull_radius * body
    rel = (s - s[0])[None] + r.reshape(-1, N_SONARS)[:, :, None] * body[None]
    return np.asarray(np.linalg.norm(rel, axis=2).reshape(r.shape))


def nearest_beam(
    array: SonarArray, position: FloatArray, heading: FloatArray, point: FloatArray
) -> int:
    """1-based index of the sensor whose beam axis makes the smallest angle with the direction
    from that sensor to ``point`` [m] (the target "marked sensor" of the thesis's Fig. 5.4)."""
    s, n = array.placement(position, heading)
    rel = np.asarray(point, dtype=float) - s
    cosang = np.einsum("ij,ij->i", rel, n) / np.maximum(np.linalg.norm(rel, axis=1), 1e-300)
    return int(np.argmax(cosang)) + 1


def beam_point(
    array: SonarArray, position: FloatArray, heading: FloatArray, index: float, distance: float
) -> FloatArray:
    """The point to evade [m] that a (distance, sensor index) estimate designates: ``distance``
    [m] out along the beam axis of sensor ``round(index)`` (clipped to 1..9) from its sensor."""
    k = int(min(max(round(float(index)), 1), N_SONARS)) - 1
    s, n = array.placement(position, heading)
    return np.asarray(s[k] + max(float(distance), 0.0) * n[k])
