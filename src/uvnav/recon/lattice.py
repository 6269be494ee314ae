"""Stage 1 of thesis Ch. 7 (§7.3.1, Figs. 7.2–7.3): the fewest lattice waypoints that cover D.

Papers: J. Zhang and Y. Zhang, "A Method for UAV Reconnaissance and Surveillance in Complex
Environments", ICCAR 2020 (thesis Ch. 7); the regular triangulation ``T(λ, x0, y0)`` comes from
A. V. Savkin and H. Huang, "Asymptotically Optimal Deployment of Drones for Surveillance and
Monitoring", Sensors 19 (2019) 2068, after R. Kershner, "The number of circles covering a set",
Amer. J. Math. 61 (1939).

The triangulation consists of equilateral triangles of side ``√3·R`` (the thesis prints
"v = √3", i.e. unit footprint radius; we scale by R so that every triangle's circumradius is R).
``λ ∈ [0, π/3)`` is the angle of one lattice direction to the x axis and ``(x0, y0)`` one vertex.
The Voronoi cell of a vertex is the regular hexagon of circumradius R whose corners are the centres
C of the six triangles around it (Fig. 7.2(b)); so every point of a cell is within R of its vertex.
The waypoints are the vertices whose cell meets D (interiors overlap, so a cell that only touches
D's boundary is not needed): their cells cover D and every point of D is within R of a waypoint.

Minimising their number over ``(λ, x0, y0)``: for a fixed λ the count is a piecewise-constant,
lower-semicontinuous function of the offset whose pieces are cut by the lines where a hexagon's
side touches D (separating-axis equalities ``(o + v)·n = p_min(n) − h(n)`` or ``p_max(n) + h(n)``
for the hexagon and D normals n).  Its minimum is therefore attained at an intersection of two
such lines, i.e. at an *edge-aligned* offset; the optimum is often a point or a thin plateau that
a uniform grid misses.  :func:`optimal_lattice` evaluates, for every λ of a uniform grid plus the
λ that align hexagon sides with D's edges, the uniform offset grid *and* all pairwise intersections
of those lines (exhaustive for small areas, nearest ``max_pairs_k`` lattice vectors otherwise),
then refines λ locally around the best values.

Counting uses the separating-axis theorem (exact for convex pieces; a non-convex D is split into
triangles by ``shapely.constrained_delaunay_triangles``), with the hexagon shrunk by 1e-9 so that
touching does not count; the tests compare it with shapely's own intersection areas.

The "naive" baseline the counts are compared with is the axis-aligned lattice (λ = 0) with a
vertex at the lower-left corner of D's bounding box: it moves with D, so the same area gives the
same count wherever it sits (anchored at the world origin it did not: 600 m square, R = 50 m,
68 naive waypoints with D's corner at the origin, 67 centred on it, 78 centred at (397.3, 494.1)).

The thesis's (7.1) asks waypoints to lie in D; a vertex whose cell meets D can lie up to R outside
D.  It is kept there (moving it would break the covering) and :class:`LatticeSolution` reports
how many such vertices there are.

Units: lengths [m], angles [rad].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import Polygon

FloatArray = np.ndarray
_SHRINK = 1e-9
PI3 = math.pi / 3.0


@dataclass(frozen=True)
class LatticeSolution:
    """The chosen triangulation and its waypoints.

    Attributes:
        lam: λ [rad] in [0, π/3).
        x0: Lattice vertex x [m].
        y0: Lattice vertex y [m].
        R: Footprint radius [m] (triangle side √3·R).
        xy: Waypoints (N, 2) [m]: the vertices whose Voronoi cell meets D.
        n: N.
        n_naive: Count of the naive lattice (λ = 0, vertex at D's lower-left corner).
        bound_disc: A / (π R²), the area bound (no covering by discs can use fewer).
        bound_kershner: A / (1.5·√3·R²), Kershner's asymptotic minimum for discs of radius R.
        n_outside: Waypoints lying outside D (allowed, see module doc).
        evaluations: Number of (λ, x0, y0) evaluated.
    """

    lam: float
    x0: float
    y0: float
    R: float
    xy: FloatArray
    n: int
    n_naive: int
    bound_disc: float
    bound_kershner: float
    n_outside: int
    evaluations: int


def lattice_basis(lam: float, R: float) -> tuple[FloatArray, FloatArray]:
    """Basis vectors a1, a2 [m] of T(λ, ·, ·): side √3·R at angles λ and λ + π/3."""
    s = math.sqrt(3.0) * R
    a1 = s * np.array([math.cos(lam), math.sin(lam)])
    a2 = s * np.array([math.cos(lam + PI3), math.sin(lam + PI3)])
    return a1, a2


def hexagon_vertices(center: FloatArray, lam: float, R: float) -> FloatArray:
    """The Voronoi cell of a vertex: hexagon corners (6, 2) [m] at angles λ + π/6 + kπ/3."""
    ang = lam + math.pi / 6 + PI3 * np.arange(6)
    c = np.asarray(center, dtype=float)
    return c + R * np.column_stack([np.cos(ang), np.sin(ang)])


def _convex_pieces(area: Polygon) -> list[FloatArray]:
    """D as convex pieces (its own ring if convex, else constrained Delaunay triangles)."""
    hull = area.convex_hull
    if hull.area - area.area <= 1e-9 * area.area and len(area.interiors) == 0:
        ring = np.asarray(area.exterior.coords)[:-1]
        return [ring]
    tris = shapely.constrained_delaunay_triangles(area)
    return [np.asarray(t.exterior.coords)[:-1] for t in shapely.get_parts(tris)]


def _edge_normals(poly: FloatArray) -> FloatArray:
    e = np.roll(poly, -1, axis=0) - poly
    n = np.column_stack([e[:, 1], -e[:, 0]])
    norm = np.linalg.norm(n, axis=1)
    return n[norm > 1e-12] / norm[norm > 1e-12, None]


@dataclass(frozen=True)
class _Axes:
    """Separating axes of one convex piece at one λ: normals (A, 2), piece extent, hex support."""

    n: FloatArray
    pmin: FloatArray
    pmax: FloatArray
    h: FloatArray


def _piece_axes(piece: FloatArray, lam: float, R: float) -> _Axes:
    hex_n = np.column_stack([np.cos(lam + PI3 * np.arange(3)), np.sin(lam + PI3 * np.arange(3))])
    n = np.vstack([hex_n, _edge_normals(piece)])
    proj = piece @ n.T  # (V, A)
    corners = hexagon_vertices(np.zeros(2), lam, R)
    h = (corners @ n.T).max(axis=0) * (1.0 - _SHRINK)
    return _Axes(n, proj.min(axis=0), proj.max(axis=0), h)


def _lattice_vectors(area: Polygon, lam: float, R: float) -> FloatArray:
    """Lattice vectors v (K, 2) such that o + v can have a cell meeting D for o in the cell."""
    a1, a2 = lattice_basis(lam, R)
    B = np.column_stack([a1, a2])
    Binv = np.linalg.inv(B)
    xmin, ymin, xmax, ymax = area.bounds
    pad = R + 2.0 * math.sqrt(3.0) * R
    corners = np.array(
        [
            [xmin - pad, ymin - pad],
            [xmax + pad, ymin - pad],
            [xmax + pad, ymax + pad],
            [xmin - pad, ymax + pad],
        ]
    )
    ij = corners @ Binv.T
    lo = np.floor(ij.min(axis=0)).astype(int)
    hi = np.ceil(ij.max(axis=0)).astype(int)
    I, J = np.meshgrid(  # noqa: E741
        np.arange(lo[0], hi[0] + 1), np.arange(lo[1], hi[1] + 1), indexing="ij"
    )
    v = np.column_stack([I.ravel(), J.ravel()]) @ B.T
    return np.asarray(v, dtype=float)


def meets_mask(centers: FloatArray, pieces: list[FloatArray], lam: float, R: float) -> FloatArray:
    """Whether each hexagon cell (centres (..., 2)) meets D's interior (separating axes)."""
    c = np.asarray(centers, dtype=float)
    out = np.zeros(c.shape[:-1], dtype=bool)
    for piece in pieces:
        ax = _piece_axes(piece, lam, R)
        proj = c @ ax.n.T
        ok = np.all((proj + ax.h > ax.pmin) & (proj - ax.h < ax.pmax), axis=-1)
        out |= ok
    return out


def count_cells(
    offsets: FloatArray, area: Polygon, lam: float, R: float, *, chunk: int = 4096
) -> np.ndarray:
    """Number of lattice vertices whose cell meets D, for many offsets (M, 2) at one λ."""
    pieces = _convex_pieces(area)
    return _count(np.atleast_2d(offsets), pieces, _lattice_vectors(area, lam, R), lam, R, chunk)


def _count(
    offsets: FloatArray,
    pieces: list[FloatArray],
    vecs: FloatArray,
    lam: float,
    R: float,
    chunk: int,
) -> np.ndarray:
    # both kernels assume o in the fundamental cell: ``vecs`` only spans D's box widened by a cell
    a1, a2 = lattice_basis(lam, R)
    offsets = _reduce(np.asarray(offsets, dtype=float), a1, a2)
    if len(pieces) == 1:
        return _count_rows(offsets, pieces[0], vecs, lam, R, chunk)
    return _count_sat(offsets, pieces, vecs, lam, R, chunk)


def _count_rows(
    offsets: FloatArray, piece: FloatArray, vecs: FloatArray, lam: float, R: float, chunk: int
) -> np.ndarray:
    """Convex D: lattice points in the open Minkowski sum D ⊕ hexagon, counted row by row.

    The sum is the intersection of the slabs ``p_min(n) − h(n) < p·n < p_max(n) + h(n)`` over the
    hexagon and D normals (normals of a Minkowski sum of convex polygons are the union of both), so
    along a lattice row ``o + j a2 + t a1`` it is an open interval of t; its integers are counted
    directly.  Same predicate as :func:`_count_sat`, about 15x fewer operations.
    """
    ax = _piece_axes(piece, lam, R)
    a1, a2 = lattice_basis(lam, R)
    offsets = _reduce(np.asarray(offsets, dtype=float), a1, a2)  # same lattices, o in the cell
    # rows j whose line o + j·a2 + t·a1 can cross the sum: its projection on the normal of a1 is
    # D's projection widened by the hexagon's support R there; o·n⊥ lies in [0, 1.5 R)
    n_perp = np.array([-a1[1], a1[0]]) / np.linalg.norm(a1)
    proj = piece @ n_perp
    step = float(a2 @ n_perp)  # 1.5 R
    rows = np.arange(
        math.floor((proj.min() - R) / step) - 1, math.ceil((proj.max() + R) / step) + 1
    )
    del vecs  # rows come from the geometry; kept in the signature for symmetry with _count_sat
    an = a1 @ ax.n.T  # (A,)
    lo_b = ax.pmin - ax.h
    hi_b = ax.pmax + ax.h
    par = np.abs(an) < 1e-12
    safe = np.where(par, 1.0, an)
    out = np.empty(len(offsets), dtype=np.intp)
    row_pts = rows[:, None] * a2[None, :]  # (J, 2)
    for s in range(0, len(offsets), chunk):
        o = offsets[s : s + chunk]
        q = (o[:, None, :] + row_pts[None, :, :]) @ ax.n.T  # (M, J, A)
        t1 = (lo_b - q) / safe
        t2 = (hi_b - q) / safe
        tlo = np.where(par, -np.inf, np.minimum(t1, t2)).max(axis=2)
        thi = np.where(par, np.inf, np.maximum(t1, t2)).min(axis=2)
        inside_par = np.all(~par | ((q > lo_b) & (q < hi_b)), axis=2)
        n = np.ceil(thi) - np.floor(tlo) - 1.0
        n = np.where(inside_par & (thi > tlo), np.maximum(n, 0.0), 0.0)
        out[s : s + chunk] = n.sum(axis=1).astype(np.intp)
    return out


def _count_sat(
    offsets: FloatArray,
    pieces: list[FloatArray],
    vecs: FloatArray,
    lam: float,
    R: float,
    chunk: int,
) -> np.ndarray:
    """Any D (convex pieces): separating-axis test of every lattice cell against every piece.

    ``offsets`` must lie in the fundamental cell (see :func:`_reduce`): ``vecs`` only reaches D's
    bounding box widened by one cell.
    """
    axes = [_piece_axes(p, lam, R) for p in pieces]
    out = np.empty(len(offsets), dtype=np.intp)
    # per piece and axis: projections of the lattice vectors, computed once
    vproj = [vecs @ ax.n.T for ax in axes]  # (K, A)
    for s in range(0, len(offsets), chunk):
        o = offsets[s : s + chunk]
        hit = np.zeros((len(o), len(vecs)), dtype=bool)
        for ax, vp in zip(axes, vproj, strict=True):
            op = o @ ax.n.T  # (M, A)
            ok = np.ones((len(o), len(vecs)), dtype=bool)
            for a in range(len(ax.n)):
                p = op[:, a, None] + vp[None, :, a]
                ok &= (p + ax.h[a] > ax.pmin[a]) & (p - ax.h[a] < ax.pmax[a])
            hit |= ok
        out[s : s + chunk] = hit.sum(axis=1)
    return out


def lattice_waypoints(area: Polygon, lam: float, x0: float, y0: float, R: float) -> FloatArray:
    """Vertices (N, 2) [m] of T(λ, x0, y0) whose Voronoi cell meets D's interior."""
    pieces = _convex_pieces(area)
    vecs = _lattice_vectors(area, lam, R)
    a1, a2 = lattice_basis(lam, R)
    o = _reduce(np.array([[x0, y0]]), a1, a2)[0]  # same lattice, offset in the fundamental cell
    pts = o + vecs
    mask = meets_mask(pts, pieces, lam, R)
    return np.asarray(pts[mask], dtype=float)


def _reduce(o: FloatArray, a1: FloatArray, a2: FloatArray) -> FloatArray:
    """Offsets reduced into the fundamental parallelogram {u a1 + v a2 : u, v in [0, 1)}."""
    B = np.column_stack([a1, a2])
    uv = o @ np.linalg.inv(B).T
    uv -= np.floor(uv)
    return np.asarray(uv @ B.T, dtype=float)


def _seed_offsets(
    pieces: list[FloatArray], lam: float, R: float, vecs: FloatArray, max_pairs_k: int
) -> FloatArray:
    """Edge-aligned offsets: intersections of two touching lines (see module doc)."""
    lines_n: list[FloatArray] = []
    lines_b: list[float] = []
    for piece in pieces:
        ax = _piece_axes(piece, lam, R)
        for a in range(len(ax.n)):
            lines_n += [ax.n[a], ax.n[a]]
            lines_b += [float(ax.pmin[a] - ax.h[a]), float(ax.pmax[a] + ax.h[a])]
    N = np.array(lines_n)
    b = np.array(lines_b)
    # de-duplicate identical lines
    key = np.round(np.column_stack([N, b[:, None] / R]), 9)
    _, idx = np.unique(key, axis=0, return_index=True)
    N, b = N[np.sort(idx)], b[np.sort(idx)]
    order = np.argsort(np.linalg.norm(vecs, axis=1))
    vk = vecs[order[:max_pairs_k]]
    i1, i2 = np.triu_indices(len(N), k=1)
    det = N[i1, 0] * N[i2, 1] - N[i1, 1] * N[i2, 0]
    good = np.abs(det) > 1e-9
    i1, i2, det = i1[good], i2[good], det[good]
    if len(i1) == 0:
        return np.zeros((0, 2))
    # o·n1 = b1 ; o·n2 = b2 - v·n2  (hex 0 on line 1, hex v on line 2)
    b2 = b[i2][:, None] - (N[i2] @ vk.T)  # (P, K)
    b1 = np.broadcast_to(b[i1][:, None], b2.shape)
    n1 = N[i1]
    n2 = N[i2]
    ox = (b1 * n2[:, 1, None] - b2 * n1[:, 1, None]) / det[:, None]
    oy = (n1[:, 0, None] * b2 - n2[:, 0, None] * b1) / det[:, None]
    o = np.column_stack([ox.ravel(), oy.ravel()])
    a1, a2 = lattice_basis(lam, R)
    return _unique_offsets(o, a1, a2)


def _unique_offsets(o: FloatArray, a1: FloatArray, a2: FloatArray) -> FloatArray:
    """Offsets reduced into the fundamental cell, duplicates (to 1e-8 of a cell) removed."""
    B = np.column_stack([a1, a2])
    uv = o @ np.linalg.inv(B).T
    uv -= np.floor(uv)
    q = np.round(uv * 1e8).astype(np.int64) % 100_000_000
    _, idx = np.unique(q[:, 0] * 100_000_000 + q[:, 1], return_index=True)
    return np.asarray(uv[idx] @ B.T, dtype=float)


def _grid_offsets(lam: float, R: float, n: int) -> FloatArray:
    a1, a2 = lattice_basis(lam, R)
    u = (np.arange(n) + 0.5) / n
    U, V = np.meshgrid(u, u)
    return np.asarray(np.column_stack([U.ravel(), V.ravel()]) @ np.vstack([a1, a2]), dtype=float)


def best_offset(
    area: Polygon,
    lam: float,
    R: float,
    *,
    n_grid: int = 16,
    max_pairs_k: int = 120,
    pieces: list[FloatArray] | None = None,
) -> tuple[int, FloatArray, int]:
    """Minimum count over offsets at one λ: (count, offset (2,), evaluations)."""
    pieces = _convex_pieces(area) if pieces is None else pieces
    vecs = _lattice_vectors(area, lam, R)
    cand = np.vstack(
        [_grid_offsets(lam, R, n_grid), _seed_offsets(pieces, lam, R, vecs, max_pairs_k)]
    )
    counts = _count(cand, pieces, vecs, lam, R, 4096)
    k = int(np.argmin(counts))
    return int(counts[k]), cand[k], len(cand)


def aligned_angles(area: Polygon) -> FloatArray:
    """λ values in [0, π/3) putting a hexagon side or corner along an edge of D."""
    ring = np.asarray(area.exterior.coords)
    e = np.diff(ring, axis=0)
    phi = np.arctan2(e[:, 1], e[:, 0])
    lam = np.concatenate([phi, phi + math.pi / 6]) % PI3
    lam = np.where(lam > PI3 - 1e-12, 0.0, lam)
    return np.unique(np.round(lam, 12))


def naive_anchor(area: Polygon) -> FloatArray:
    """The naive lattice's vertex (2,) [m]: the lower-left corner of D's bounding box."""
    xmin, ymin, _, _ = area.bounds
    return np.array([xmin, ymin])


def naive_count(area: Polygon, R: float) -> int:
    """Count of the naive lattice: λ = 0, a vertex at D's lower-left corner (module doc)."""
    return int(count_cells(naive_anchor(area)[None, :], area, 0.0, R)[0])


def optimal_lattice(
    area: Polygon,
    R: float,
    *,
    n_lambda: int = 60,
    n_grid: int = 16,
    max_pairs_k: int = 120,
    refine: int = 3,
) -> LatticeSolution:
    """Search T(λ, x0, y0) for the fewest cells meeting D (see module doc).

    Args:
        area: Target area D (shapely polygon) [m].
        R: Footprint radius [m] (> 0).
        n_lambda: Uniform λ samples in [0, π/3) (plus the edge-aligned λ).
        n_grid: Uniform offset grid per side in the fundamental cell.
        max_pairs_k: Lattice vectors paired with the edge-aligned lines (nearest first).
        refine: Rounds of local λ refinement around the best values.
    """
    if not R > 0:
        raise ValueError(f"footprint radius R must be positive, got {R}")
    if area.is_empty or area.area <= 0:
        raise ValueError("area: D is empty")
    pieces = _convex_pieces(area)
    lams = np.unique(np.concatenate([np.arange(n_lambda) * PI3 / n_lambda, aligned_angles(area)]))
    results: dict[float, tuple[int, FloatArray]] = {}
    evals = 0
    for lam in lams:
        c, o, e = best_offset(
            area, float(lam), R, n_grid=n_grid, max_pairs_k=max_pairs_k, pieces=pieces
        )
        results[float(lam)] = (c, o)
        evals += e
    step = PI3 / n_lambda
    for _ in range(refine):
        best_c = min(c for c, _ in results.values())
        tops = [lam for lam, (c, _) in results.items() if c <= best_c][:4]
        step /= 4.0
        for lam0 in tops:
            for d in (-2, -1, 1, 2):
                lam = float((lam0 + d * step) % PI3)
                if lam in results:
                    continue
                c, o, e = best_offset(
                    area, lam, R, n_grid=n_grid, max_pairs_k=max_pairs_k, pieces=pieces
                )
                results[lam] = (c, o)
                evals += e
    lam_best = min(results, key=lambda k: (results[k][0], k))
    c_best, o_best = results[lam_best]
    n_naive = naive_count(area, R)
    if n_naive < c_best:  # the naive lattice is one candidate of the search space
        lam_best, c_best, o_best = 0.0, n_naive, naive_anchor(area)
    xy = lattice_waypoints(area, lam_best, float(o_best[0]), float(o_best[1]), R)
    A = float(area.area)
    outside = ~(
        shapely.contains_xy(area, xy[:, 0], xy[:, 1])
        | shapely.intersects_xy(area.boundary, xy[:, 0], xy[:, 1])
    )
    return LatticeSolution(
        lam=float(lam_best),
        x0=float(o_best[0]),
        y0=float(o_best[1]),
        R=float(R),
        xy=xy,
        n=len(xy),
        n_naive=n_naive,
        bound_disc=A / (math.pi * R * R),
        bound_kershner=A / (1.5 * math.sqrt(3.0) * R * R),
        n_outside=int(outside.sum()),
        evaluations=evals,
    )


def naive_lattice(area: Polygon, R: float) -> FloatArray:
    """Waypoints (N, 2) [m] of the naive lattice (:func:`naive_count`)."""
    x0, y0 = naive_anchor(area)
    return lattice_waypoints(area, 0.0, float(x0), float(y0), R)


def check_margins(R: float, delta: float, c1: float, c2: float) -> None:
    """Validate the safety margins of (7.4): c1 > 2δ > 0, c2 > δ > 0, and lattice spacing ≥ c1.

    Raises:
        ValueError: naming the violated inequality.
    """
    if not delta > 0:
        raise ValueError(f"delta: must be > 0 (7.4), got {delta}")
    if not c1 > 2 * delta:
        raise ValueError(f"c1: must exceed 2*delta = {2 * delta:g} m (7.4), got {c1:g}")
    if not c2 > delta:
        raise ValueError(f"c2: must exceed delta = {delta:g} m (7.4), got {c2:g}")
    if math.sqrt(3.0) * R < c1:
        raise ValueError(
            f"c1: lattice spacing sqrt(3)*R = {math.sqrt(3.0) * R:.2f} m is below c1 = {c1:g} m, "
            "so waypoint separation (7.4) cannot hold"
        )
