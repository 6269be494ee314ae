"""The closed smooth trajectory τ of cubic Bézier curves (thesis Ch. 7 §7.2–7.3.2, eq. (7.3)).

Thesis: Y. Zhang, Ch. 7 (J. Zhang and Y. Zhang, ICCAR 2020): τ is a closed sequence of cubic
Béziers ``τ(t) = B0(1−t)³ + 3B1 t(1−t)² + 3B2 t²(1−t) + B3 t³`` (7.3) that passes through the
δ-neighbourhood of every waypoint, "consists of straight segments and Dubins curves", has no
jumps and "shares the same direction" at the joints (tangent continuity), and respects the UAV's
turning radius.  Dubins paths: L. E. Dubins, Amer. J. Math. 79 (1957); closed forms after
A. M. Shkel and V. Lumelsky, Automatica 37 (2001).  Heading selection by alternating coordinate
descent in the spirit of K. Savla, E. Frazzoli and F. Bullo's "alternating algorithm" (IEEE TAC
53 (2008)); written here because the ``dubins`` package does not build on this platform and no
maintained library offers vectorised Dubins paths.

Construction (horizontal plane, then altitude):

1. Each waypoint i of the tour gets a pass point Q_i with |Q_i − p_i| ≤ δ (p_i itself or one of 6
   points at 0.9·δ around it) and a heading ψ_i (16 directions plus the bisector of the tour's
   neighbours).  Consecutive (Q_i, ψ_i) are joined by the shortest Dubins path of radius
   ``r_min·(1 + 1e-3)``; coordinate descent over (Q_i, ψ_i), a few sweeps, shortens the tour.
2. Every arc is split into pieces of at most π/4 and each piece is the standard cubic Bézier of a
   circular arc (handles ``4/3·tan(α/4)·r``, curvature between −0.15 % and +0.05 % of 1/r for a
   π/4 piece, hence ≤ 1/r_min with the 1e-3 margin); straight parts are Béziers of at most
   20 m with handles at thirds.
   Headings are shared at joints, so the unit tangent is continuous (G¹; C¹ after arc-length
   reparametrisation — the parametric speed changes at arc/line joints, which is why the check
   reports the tangent *angle* jump).
3. Altitude: along each Dubins connection z goes from z_i to z_{i+1} by a smoothstep
   ``3u² − 2u³`` plus, where the terrain needs it, a bump ``b·16u²(1 − u)²`` (zero value and
   slope at both ends) raising it to clear ``F + c2``; the z control points follow the profile's
   slope, so the 3D tangent is continuous too.

The "r_min too large for δ" rule: a turn of heading change φ flown on an arc of radius r touching
both legs passes at ``r·(1/cos(φ/2) − 1)`` from the corner; the lattice's basic 60° turns must fit
inside the δ-ball, so ``r_min ≤ δ / (1/cos(π/6) − 1) ≈ 6.46·δ`` (:func:`check_turn_radius`).
Sharper turns are flown as Dubins detours.

Units: lengths [m], angles [rad].
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

FloatArray = np.ndarray
TWO_PI = 2.0 * math.pi
#: r_plan = r_min·(1 + this): margin for the cubic approximation of circular arcs
ARC_MARGIN = 1e-3
MAX_ARC_PIECE = math.pi / 4
#: longest straight Bézier piece [m] (keeps the cubic altitude close to its profile)
MAX_LINE_PIECE = 20.0


def check_turn_radius(r_min: float, delta: float) -> None:
    """Raise ``ValueError`` unless 0 < r_min ≤ δ / (1/cos(π/6) − 1) (module doc)."""
    if not r_min > 0:
        raise ValueError(f"r_min: turning radius must be positive, got {r_min}")
    limit = delta / (1.0 / math.cos(math.pi / 6) - 1.0)
    if r_min > limit:
        raise ValueError(
            f"r_min: {r_min:g} m is too large for delta = {delta:g} m: a 60 deg lattice turn "
            f"needs r_min <= {limit:.2f} m to stay inside the delta-neighbourhood"
        )


def _mod2pi(a: FloatArray) -> FloatArray:
    return np.mod(a, TWO_PI)


# word: (segment types, function) — types 'L', 'S', 'R'
_WORDS = ("LSL", "RSR", "LSR", "RSL", "RLR", "LRL")


def dubins_words(start: FloatArray, end: FloatArray, r: float) -> tuple[FloatArray, FloatArray]:
    """All six Dubins words for configurations (M, 3) → (M, 3) [x, y, ψ].

    Returns:
        (params (M, 6, 3) normalised segment lengths t, p, q [rad or m/r], lengths (M, 6) [m],
        inf where a word does not exist).
    """
    s = np.atleast_2d(np.asarray(start, dtype=float))
    e = np.atleast_2d(np.asarray(end, dtype=float))
    dx = e[:, 0] - s[:, 0]
    dy = e[:, 1] - s[:, 1]
    d = np.hypot(dx, dy) / r
    th = np.arctan2(dy, dx)
    a = _mod2pi(s[:, 2] - th)
    b = _mod2pi(e[:, 2] - th)
    sa, sb, ca, cb = np.sin(a), np.sin(b), np.cos(a), np.cos(b)
    cab = np.cos(a - b)
    d2 = d * d
    M = len(s)
    P = np.full((M, 6, 3), np.nan)
    with np.errstate(invalid="ignore"):
        # LSL
        p2 = 2 + d2 - 2 * cab + 2 * d * (sa - sb)
        t1 = np.arctan2(cb - ca, d + sa - sb)
        P[:, 0] = np.column_stack([_mod2pi(t1 - a), np.sqrt(p2), _mod2pi(b - t1)])
        P[p2 < 0, 0] = np.nan
        # RSR
        p2 = 2 + d2 - 2 * cab + 2 * d * (sb - sa)
        t1 = np.arctan2(ca - cb, d - sa + sb)
        P[:, 1] = np.column_stack([_mod2pi(a - t1), np.sqrt(p2), _mod2pi(t1 - b)])
        P[p2 < 0, 1] = np.nan
        # LSR
        p2 = -2 + d2 + 2 * cab + 2 * d * (sa + sb)
        p = np.sqrt(p2)
        t0 = np.arctan2(-ca - cb, d + sa + sb) - np.arctan2(-2.0, p)
        P[:, 2] = np.column_stack([_mod2pi(t0 - a), p, _mod2pi(t0 - b)])
        P[p2 < 0, 2] = np.nan
        # RSL
        p2 = -2 + d2 + 2 * cab - 2 * d * (sa + sb)
        p = np.sqrt(p2)
        t0 = np.arctan2(ca + cb, d - sa - sb) - np.arctan2(2.0, p)
        P[:, 3] = np.column_stack([_mod2pi(a - t0), p, _mod2pi(b - t0)])
        P[p2 < 0, 3] = np.nan
        # RLR
        c = (6.0 - d2 + 2 * cab + 2 * d * (sa - sb)) / 8.0
        phi = np.arctan2(ca - cb, d - sa + sb)
        p = _mod2pi(TWO_PI - np.arccos(c))
        t = _mod2pi(a - phi + _mod2pi(p / 2.0))
        P[:, 4] = np.column_stack([t, p, _mod2pi(a - b - t + _mod2pi(p))])
        P[np.abs(c) > 1, 4] = np.nan
        # LRL
        c = (6.0 - d2 + 2 * cab + 2 * d * (sb - sa)) / 8.0
        phi = np.arctan2(ca - cb, d + sa - sb)
        p = _mod2pi(TWO_PI - np.arccos(c))
        t = _mod2pi(-a - phi + p / 2.0)
        P[:, 5] = np.column_stack([t, p, _mod2pi(b - a - t + _mod2pi(p))])
        P[np.abs(c) > 1, 5] = np.nan
    L = np.nansum(P, axis=2) * r
    L[np.isnan(P).any(axis=2)] = np.inf
    return P, L


def dubins_length(start: FloatArray, end: FloatArray, r: float) -> FloatArray:
    """Shortest Dubins path length [m] for configurations (M, 3) → (M, 3)."""
    return np.asarray(dubins_words(start, end, r)[1].min(axis=1), dtype=float)


@dataclass(frozen=True)
class DubinsPath:
    """One Dubins path: start (x, y, ψ), word like ``"LSR"``, segment lengths [m], radius [m]."""

    start: FloatArray
    word: str
    lengths: FloatArray
    r: float

    @property
    def length(self) -> float:
        """Total length [m]."""
        return float(np.sum(self.lengths))


def shortest_dubins(start: FloatArray, end: FloatArray, r: float) -> DubinsPath:
    """The shortest valid Dubins path between two configurations (x, y, ψ).

    Every word is integrated and kept only if it ends at ``end`` (guards the closed forms).
    """
    P, L = dubins_words(start, end, r)
    order = np.argsort(L[0])
    for k in order:
        if not np.isfinite(L[0, k]):
            break
        path = DubinsPath(np.asarray(start, float), _WORDS[k], P[0, k] * r, r)
        endp = _integrate(path)
        err = math.hypot(endp[0] - end[0], endp[1] - end[1])
        herr = abs((endp[2] - end[2] + math.pi) % TWO_PI - math.pi)
        if err < 1e-6 * max(1.0, r) and herr < 1e-6:
            return path
    raise RuntimeError("no valid Dubins path found")  # pragma: no cover - Dubins always exists


def _step(
    x: float, y: float, h: float, kind: str, length: float, r: float
) -> tuple[float, float, float]:
    if kind == "S":
        return x + length * math.cos(h), y + length * math.sin(h), h
    sgn = 1.0 if kind == "L" else -1.0
    dh = sgn * length / r
    cx, cy = x - sgn * r * math.sin(h), y + sgn * r * math.cos(h)
    h2 = h + dh
    return cx + sgn * r * math.sin(h2), cy - sgn * r * math.cos(h2), h2


def _integrate(path: DubinsPath) -> tuple[float, float, float]:
    x, y, h = (float(v) for v in path.start)
    for kind, length in zip(path.word, path.lengths, strict=True):
        x, y, h = _step(x, y, h, kind, float(length), path.r)
    return x, y, h


def dubins_beziers_xy(path: DubinsPath) -> list[FloatArray]:
    """The path as planar cubic Béziers, each (4, 2): arcs in ≤ π/4 pieces, lines at thirds."""
    out: list[FloatArray] = []
    x, y, h = (float(v) for v in path.start)
    r = path.r
    for kind, length in zip(path.word, path.lengths, strict=True):
        length = float(length)
        if length <= 1e-9:
            continue
        if kind == "S":
            # straight parts in pieces of <= MAX_LINE_PIECE so the altitude profile is followed
            m = max(1, math.ceil(length / MAX_LINE_PIECE))
            u = np.array([math.cos(h), math.sin(h)])
            for j in range(m):
                b0 = np.array([x, y]) + u * length * j / m
                b3 = np.array([x, y]) + u * length * (j + 1) / m
                piece = length / m
                out.append(np.array([b0, b0 + u * piece / 3, b0 + u * 2 * piece / 3, b3]))
            x, y = x + length * math.cos(h), y + length * math.sin(h)
            continue
        ang = length / r
        n = max(1, math.ceil(ang / MAX_ARC_PIECE - 1e-12))
        piece = length / n
        alpha = ang / n
        k = 4.0 / 3.0 * math.tan(alpha / 4.0) * r
        for _ in range(n):
            x1, y1, h1 = _step(x, y, h, kind, piece, r)
            b0 = np.array([x, y])
            b3 = np.array([x1, y1])
            out.append(
                np.array(
                    [
                        b0,
                        b0 + k * np.array([math.cos(h), math.sin(h)]),
                        b3 - k * np.array([math.cos(h1), math.sin(h1)]),
                        b3,
                    ]
                )
            )
            x, y, h = x1, y1, h1
    return out


def bezier_eval(B: FloatArray, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Points, first and second derivatives of cubic Béziers B (K, 4, d) at t (m,): (K, m, d)."""
    t = np.asarray(t, dtype=float)[None, :, None]
    b0, b1, b2, b3 = (B[:, i, None, :] for i in range(4))
    u = 1 - t
    pos = b0 * u**3 + 3 * b1 * t * u**2 + 3 * b2 * t**2 * u + b3 * t**3
    d1 = 3 * ((b1 - b0) * u**2 + 2 * (b2 - b1) * t * u + (b3 - b2) * t**2)
    d2 = 6 * ((b2 - 2 * b1 + b0) * u + (b3 - 2 * b2 + b1) * t)
    return pos, d1, d2


@dataclass(frozen=True)
class Trajectory:
    """A closed trajectory τ of 3D cubic Béziers.

    Attributes:
        beziers: Control points (K, 4, 3) [m], piece k ends where piece k+1 starts (cyclic).
        pass_points: Q_i (n, 3) [m], the points of τ assigned to the tour's waypoints (joints).
        headings: ψ_i (n,) [rad] at the pass points.
        order: Waypoint indices (global) in visiting order.
        r_min: Turning radius bound [m].
    """

    beziers: FloatArray
    pass_points: FloatArray
    headings: FloatArray
    order: FloatArray
    r_min: float

    def sample(self, per_piece: int = 24) -> FloatArray:
        """Points (K·per_piece + 1, 3) [m] along τ, closed (last equals first)."""
        t = np.linspace(0.0, 1.0, per_piece, endpoint=False)
        pos = bezier_eval(self.beziers, t)[0].reshape(-1, 3)
        return np.vstack([pos, pos[:1]])


def plan_dubins_tour(
    P: FloatArray,
    *,
    r_min: float,
    delta: float,
    n_headings: int = 16,
    sweeps: int = 4,
) -> tuple[FloatArray, FloatArray, list[DubinsPath]]:
    """Pass points Q (n, 2), headings ψ (n,) and the closed tour's Dubins paths (module doc, 1.).

    ``P`` (n, 2) are the waypoints in visiting order.
    """
    P = np.asarray(P, dtype=float)[:, :2]
    n = len(P)
    r = r_min * (1.0 + ARC_MARGIN)
    ring = (
        0.9
        * delta
        * np.column_stack([np.cos(np.arange(6) * math.pi / 3), np.sin(np.arange(6) * math.pi / 3)])
    )
    offsets = np.vstack([np.zeros((1, 2)), ring])
    H = np.arange(n_headings) * TWO_PI / n_headings
    nxt = np.roll(P, -1, axis=0) - np.roll(P, 1, axis=0)
    psi = np.arctan2(nxt[:, 1], nxt[:, 0])
    Q = P.copy()
    if n < 2:
        return Q, psi, []
    # alternating (Jacobi) sweeps: waypoints of one colour class share no tour edge, so all of
    # them are updated at once against their fixed neighbours (classes i % 2, odd n: last alone)
    cls = np.arange(n) % 2
    if n % 2 == 1:
        cls[-1] = 2
    cq = np.repeat(offsets, len(H) + 1, axis=0)  # (C, 2) candidate offsets
    nc = len(cq)
    for _ in range(sweeps):
        changed = False
        for c in range(int(cls.max()) + 1):
            idx = np.flatnonzero(cls == c)
            prv = np.column_stack([Q[idx - 1], psi[idx - 1]])
            nxi = (idx + 1) % n
            nx_ = np.column_stack([Q[nxi], psi[nxi]])
            heads = np.column_stack([np.broadcast_to(H, (len(idx), len(H))), psi[idx]])  # (k, h)
            CH = np.tile(heads, (1, len(offsets)))  # (k, C)
            CQ = P[idx][:, None, :] + cq[None, :, :]  # (k, C, 2)
            C = np.concatenate([CQ, CH[..., None]], axis=2).reshape(-1, 3)
            A = np.repeat(prv, nc, axis=0)
            Bn = np.repeat(nx_, nc, axis=0)
            cost = (dubins_length(A, C, r) + dubins_length(C, Bn, r)).reshape(len(idx), nc)
            cur_c = np.column_stack([Q[idx], psi[idx]])
            cur = dubins_length(prv, cur_c, r) + dubins_length(cur_c, nx_, r)
            k = np.argmin(cost, axis=1)
            best = cost[np.arange(len(idx)), k]
            better = best < cur - 1e-9
            if better.any():
                sel = idx[better]
                Q[sel] = CQ[np.flatnonzero(better), k[better]]
                psi[sel] = CH[np.flatnonzero(better), k[better]]
                changed = True
        if not changed:
            break
    paths = [
        shortest_dubins(np.array([*Q[i], psi[i]]), np.array([*Q[(i + 1) % n], psi[(i + 1) % n]]), r)
        for i in range(n)
    ]
    return Q, psi, paths


def build_trajectory(
    P3: FloatArray,
    order: FloatArray,
    *,
    r_min: float,
    delta: float,
    terrain_height: Callable[[FloatArray, FloatArray], FloatArray] | None = None,
    c2: float = 0.0,
    n_headings: int = 16,
    sweeps: int = 4,
) -> Trajectory:
    """The closed smooth trajectory through the δ-neighbourhoods of ``P3[order]`` (module doc).

    Args:
        P3: Waypoints (N, 3) [m].
        order: Visiting order (indices into P3), closed back to ``order[0]``.
        r_min: UAV turning radius [m].
        delta: δ [m].
        terrain_height: F(x, y) for the altitude bump; ``None`` skips the terrain.
        c2: Clearance the altitude profile keeps above the terrain [m].
    """
    check_turn_radius(r_min, delta)
    order = np.asarray(order, dtype=np.intp)
    W = np.asarray(P3, dtype=float)[order]
    n = len(W)
    if n == 0:
        raise ValueError("trajectory: no waypoints")
    if n == 1:  # a loiter circle of radius r_min through the waypoint
        r = r_min * (1.0 + ARC_MARGIN)
        Q = W[:, :2].copy()
        psi = np.zeros(1)
        paths = [
            DubinsPath(
                np.array([W[0, 0], W[0, 1], 0.0]), "LSL", np.array([TWO_PI * r, 0.0, 0.0]), r
            )
        ]
    else:
        Q, psi, paths = plan_dubins_tour(
            W[:, :2], r_min=r_min, delta=delta, n_headings=n_headings, sweeps=sweeps
        )
    pieces: list[FloatArray] = []
    for i, path in enumerate(paths):
        z0 = W[i, 2]
        z1 = W[(i + 1) % len(W), 2]
        xy = dubins_beziers_xy(path)
        if not xy:
            continue
        seg_len = _bezier_lengths(np.asarray(xy))
        s_edges = np.concatenate([[0.0], np.cumsum(seg_len)])
        Ltot = float(s_edges[-1])
        bump = _bump_height(xy, s_edges, Ltot, z0, z1, terrain_height, c2)
        for k, b in enumerate(xy):
            sa, sb = s_edges[k], s_edges[k + 1]
            za, ga = _profile(sa / Ltot, z0, z1, bump)
            zb, gb = _profile(sb / Ltot, z0, z1, bump)
            la = float(np.linalg.norm(b[1] - b[0]))
            lb = float(np.linalg.norm(b[3] - b[2]))
            z = np.array([za, za + ga / Ltot * la, zb - gb / Ltot * lb, zb])
            pieces.append(np.column_stack([b, z]))
    B = np.asarray(pieces)
    pass_pts = np.column_stack([Q, W[:, 2]])
    return Trajectory(B, pass_pts, psi, order, float(r_min))


def _bezier_lengths(B: FloatArray, m: int = 32) -> FloatArray:
    """Lengths [m] of cubic Béziers (K, 4, d) by a 32-chord polyline each."""
    pos = bezier_eval(B, np.linspace(0, 1, m + 1))[0]
    return np.asarray(np.linalg.norm(np.diff(pos, axis=1), axis=2).sum(axis=1), dtype=float)


def _profile(u: float, z0: float, z1: float, bump: float) -> tuple[float, float]:
    """Altitude and its derivative d z / d u of the smoothstep + bump profile."""
    z = z0 + (z1 - z0) * (3 * u * u - 2 * u**3) + bump * 16 * u * u * (1 - u) ** 2
    dz = (z1 - z0) * (6 * u - 6 * u * u) + bump * 16 * (2 * u * (1 - u) ** 2 - 2 * u * u * (1 - u))
    return float(z), float(dz)


def _bump_height(
    xy: list[FloatArray],
    s_edges: FloatArray,
    Ltot: float,
    z0: float,
    z1: float,
    terrain_height: Callable[[FloatArray, FloatArray], FloatArray] | None,
    c2: float,
) -> float:
    """Smallest bump b ≥ 0 keeping the profile ≥ F + c2 where the bump can act (u in [0.1, 0.9])."""
    if terrain_height is None or Ltot <= 0:
        return 0.0
    t = np.linspace(0, 1, 16, endpoint=False)
    pts = bezier_eval(np.asarray(xy), t)[0]  # (K, m, 2)
    s = s_edges[:-1, None] + np.diff(s_edges)[:, None] * t[None, :]
    u = (s / Ltot).ravel()
    need = terrain_height(pts[..., 0].ravel(), pts[..., 1].ravel()) + c2 + 0.5
    base = z0 + (z1 - z0) * (3 * u * u - 2 * u**3)
    shape = 16 * u * u * (1 - u) ** 2
    ok = (u > 0.1) & (u < 0.9)
    if not ok.any():
        return 0.0
    return float(max(0.0, np.max((need[ok] - base[ok]) / shape[ok])))
