"""Camera footprint, occlusion and the lowest altitude per waypoint (thesis Ch. 7 (7.2), Fig. 7.1).

Thesis: Y. Zhang, Ch. 7 (ICCAR 2020); occlusion model after J. Zhang and H. Huang,
"Occlusion-Aware UAV Path Planning for Reconnaissance and Surveillance", Drones 5 (2021) 98.

A downward camera of full cone angle θ ∈ (0, π) at ``p = (x, y, z)`` sees the ground point
``g = (x_g, y_g, F(x_g, y_g))`` when

1. ``g`` is inside the cone: horizontal distance ``|p_xy − g_xy| ≤ (z − z_g)·tan(θ/2)`` — (7.2)'s
   ``R := z·tan(θ/2)`` with the height measured *above that ground point* (the thesis states (7.2)
   over the plane z_g = 0; over terrain the height above the point is what makes the cone geometry
   right), and
2. the segment p–g is not blocked by terrain.

Line of sight (the "state" method, vectorised over many targets at once): the segment is sampled
at a fixed horizontal spacing (default half a DEM cell) *and* at every crossing with a DEM grid
line, and the bilinear terrain is compared with the segment's height at every sample; it is
blocked if the terrain is above the segment by more than ``eps`` (1 mm) anywhere strictly between
the camera and the target.  Bilinear terrain along a straight line is a quadratic inside each
cell, so the grid crossings catch every crest lying on a grid line (walls, building edges, ridges
between nodes) exactly; a crest inside a cell can still be missed by less than its curvature over
half a sample spacing.  :func:`los_disagreement` measures the disagreement against a 16x finer
reference (tests assert < 1 % of rays on fractal and urban terrain; the note records the figure).

Visibility is monotone in altitude (raising the camera keeps the cone's footprint growing, and it
lifts every point of the segment above the same ground abscissa), so the lowest altitude in
``[z_lo, z_hi]`` that sees a whole target set is found by bisection (:func:`lowest_altitude`,
which re-tests only the targets missed at the highest failing altitude).

Stage 1's altitudes (:func:`assign_altitudes`) make each waypoint see its *whole* clipped cell —
corners, edges and interior sampled every 0.5 m — not only the DEM nodes in it: on flat ground
the node rule (:func:`node_altitudes`, kept as the baseline) flew at 16.0–19.5 m for R = 20 m and
left 0.64–1.51 % of the ground unseen; the cell rule flies at R + 1 cm and leaves none
(:mod:`.coverage` has the checks and the figures).

Units: lengths [m], angles [rad].
"""

from __future__ import annotations

import math

import numpy as np
from shapely.geometry import Polygon

from uvnav.recon.cells import clipped_cells, sample_polygon
from uvnav.recon.terrain import Terrain

FloatArray = np.ndarray
LOS_EPS = 1e-3
#: Spacing [m] of the samples of a waypoint's cell (edges and interior) in :func:`assign_altitudes`.
CELL_STEP = 0.5
#: How far [m] past its cell's farthest sample a footprint reaches (:func:`assign_altitudes`).
FOOTPRINT_MARGIN = 0.01


def check_theta(theta: float) -> None:
    """Raise ``ValueError`` unless 0 < θ < π."""
    if not (0.0 < theta < math.pi):
        raise ValueError(f"theta: the camera cone angle must be in (0, pi) rad, got {theta}")


def footprint_radius(height: FloatArray | float, theta: float) -> FloatArray:
    """R = h·tan(θ/2) [m] for height ``h`` [m] above the ground and cone angle θ [rad] (7.2)."""
    check_theta(theta)
    return np.asarray(height, dtype=float) * math.tan(theta / 2.0)


def in_cone(cam: FloatArray, pts: FloatArray, theta: float) -> np.ndarray:
    """Whether ground points ``pts`` (m, 3) are inside the cone of a camera at ``cam`` (3,)."""
    cam = np.asarray(cam, dtype=float)
    d = np.hypot(pts[:, 0] - cam[0], pts[:, 1] - cam[1])
    h = cam[2] - pts[:, 2]
    return np.asarray((h > 0) & (d <= h * math.tan(theta / 2.0) + 1e-9), dtype=bool)


def line_of_sight(
    terrain: Terrain,
    cam: FloatArray,
    pts: FloatArray,
    *,
    step: float | None = None,
    eps: float = LOS_EPS,
    chunk: int = 20000,
) -> np.ndarray:
    """Whether the segments cam → pts (m, 3) clear the terrain (see module doc).

    Args:
        terrain: The DEM.
        cam: Camera position (3,) [m], or one per target (m, 3).
        pts: Target ground points (m, 3) [m].
        step: Horizontal sample spacing [m] (default half the DEM cell).
        eps: Tolerance [m]: blocked only if the terrain is above the segment by more than this.
        chunk: Targets per vectorised batch.
    """
    pts = np.asarray(pts, dtype=float)
    cams = np.broadcast_to(np.asarray(cam, dtype=float), pts.shape)
    step = 0.5 * terrain.cell if step is None else float(step)
    out = np.ones(len(pts), dtype=bool)
    for s in range(0, len(pts), chunk):
        p = pts[s : s + chunk]
        c = cams[s : s + chunk]
        L = np.hypot(p[:, 0] - c[:, 0], p[:, 1] - c[:, 1])
        # per-ray sample count, so a ray's verdict never depends on the batch it is in
        n_i = np.ceil(L / step).astype(np.intp)
        n = int(n_i.max(initial=0))
        if n < 1:
            continue
        k = np.arange(1, n + 1)[None, :]
        t_u = k / (n_i[:, None] + 1.0)  # strictly between the ends, spacing <= step
        v_u = k <= n_i[:, None]
        t_x, v_x = _grid_crossings(c[:, 0], p[:, 0], terrain.x0, terrain.dx)
        t_y, v_y = _grid_crossings(c[:, 1], p[:, 1], terrain.y0, terrain.dy)
        t = np.concatenate([t_u, t_x, t_y], axis=1)
        valid = np.concatenate([v_u, v_x, v_y], axis=1)
        t = np.where(valid, t, 0.5)
        x = c[:, 0, None] + (p[:, 0] - c[:, 0])[:, None] * t
        y = c[:, 1, None] + (p[:, 1] - c[:, 1])[:, None] * t
        zl = c[:, 2, None] + (p[:, 2] - c[:, 2])[:, None] * t
        zt = terrain.height(x, y)
        out[s : s + chunk] = ~np.any(valid & (zt > zl + eps), axis=1)
    return out


def _grid_crossings(
    a: FloatArray, b: FloatArray, o: float, h: float
) -> tuple[FloatArray, FloatArray]:
    """Parameters t in (0, 1) where segments a→b (per ray, one axis) cross grid lines o + k·h."""
    fa = (a - o) / h
    fb = (b - o) / h
    lo = np.floor(np.minimum(fa, fb)) + 1.0
    cnt = np.maximum(np.ceil(np.maximum(fa, fb)) - lo, 0).astype(np.intp)
    m = int(cnt.max(initial=0))
    if m == 0:
        return np.zeros((len(a), 0)), np.zeros((len(a), 0), dtype=bool)
    kk = lo[:, None] + np.arange(m)[None, :]
    den = np.where(np.abs(fb - fa) > 1e-12, fb - fa, 1.0)[:, None]
    t = (kk - fa[:, None]) / den
    valid = (np.arange(m)[None, :] < cnt[:, None]) & (t > 1e-9) & (t < 1 - 1e-9)
    valid &= (np.abs(fb - fa) > 1e-12)[:, None]
    return t, valid


def visible(
    terrain: Terrain, cam: FloatArray, pts: FloatArray, theta: float, *, step: float | None = None
) -> np.ndarray:
    """In the cone and in line of sight: the thesis's "seen" predicate for one camera (3,)."""
    vis = in_cone(cam, pts, theta)
    if vis.any():
        idx = np.flatnonzero(vis)
        vis[idx] = line_of_sight(terrain, cam, pts[idx], step=step)
    return vis


def lowest_altitude(
    terrain: Terrain,
    xy: FloatArray,
    targets: FloatArray,
    theta: float,
    z_lo: float,
    z_hi: float,
    *,
    tol: float = 0.25,
) -> float:
    """Lowest altitude z ∈ [z_lo, z_hi] [m] from which a camera at ``xy`` sees all ``targets``.

    Bisection on the monotone predicate (module doc).  Targets must be visible at ``z_hi``
    (the caller keeps only those); returns ``z_lo`` if they are already seen there.

    Raises:
        ValueError: if some target is not visible from ``z_hi``.
    """
    if len(targets) == 0:
        return float(z_lo)

    def missed(z: float, idx: FloatArray) -> FloatArray:
        """Indices of ``targets[idx]`` not seen from altitude z."""
        return idx[~visible(terrain, np.array([xy[0], xy[1], z]), targets[idx], theta)]

    # the cone alone needs z >= z_g + d / tan(θ/2) for every target: an exact lower bound
    d = np.hypot(targets[:, 0] - xy[0], targets[:, 1] - xy[1])
    z_cone = float(np.max(targets[:, 2] + d / math.tan(theta / 2.0)))
    lo = min(max(float(z_lo), z_cone), float(z_hi))
    # monotone in altitude (module doc): what is seen from lo is seen from every z above it, so
    # only the targets missed at the highest failing altitude are tested again
    pending = missed(lo, np.arange(len(targets)))
    if len(pending) == 0:
        return lo
    hi = float(z_hi)
    if len(missed(hi, pending)):
        raise ValueError(f"lowest_altitude: targets not all visible from z_hi = {z_hi:.2f} m")
    while hi - lo > tol:
        mid = 0.5 * (lo + hi)
        still = missed(mid, pending)
        if len(still) == 0:
            hi = mid
        else:
            lo, pending = mid, still
    return hi


def clearance_altitude(terrain: Terrain, xy: FloatArray, c2: float) -> float:
    """Lowest z [m] at ``xy`` whose 3D distance to the terrain is ≥ ``c2`` (7.4), by sampling.

    The terrain is sampled on a disc of radius c2 around ``xy`` at a quarter of a cell; z must
    clear every sample s by ``sqrt(c2² − d²)`` where d is its horizontal distance.
    """
    h = 0.25 * terrain.cell
    k = math.ceil(c2 / h)
    g = np.arange(-k, k + 1) * h
    X, Y = np.meshgrid(g, g)
    d2 = X**2 + Y**2
    m = d2 <= c2 * c2
    zs = terrain.height(xy[0] + X[m], xy[1] + Y[m])
    return float(np.max(zs + np.sqrt(np.maximum(c2 * c2 - d2[m], 0.0))))


def terrain_distance(terrain: Terrain, pts: FloatArray, radius: float) -> FloatArray:
    """Approximate 3D distance [m] from points (m, 3) to the terrain, searched within ``radius``.

    Sampled on a horizontal grid at a quarter cell (the same sampling as
    :func:`clearance_altitude`); values above ``radius`` are clipped to the vertical gap.
    """
    pts = np.asarray(pts, dtype=float)
    h = 0.25 * terrain.cell
    k = math.ceil(radius / h)
    g = np.arange(-k, k + 1) * h
    X, Y = np.meshgrid(g, g)
    m = radius * radius >= X**2 + Y**2
    ox, oy = X[m], Y[m]
    out = np.empty(len(pts))
    for i, p in enumerate(pts):
        zs = terrain.height(p[0] + ox, p[1] + oy)
        out[i] = float(np.sqrt(ox**2 + oy**2 + (p[2] - zs) ** 2).min())
    return out


def los_disagreement(
    terrain: Terrain, cams: FloatArray, pts: FloatArray, *, refine: int = 16
) -> float:
    """Fraction of rays cams (m, 3) → pts (m, 3) whose verdict differs from a ``refine``x finer."""
    a = line_of_sight(terrain, cams, pts)
    b = line_of_sight(terrain, cams, pts, step=0.5 * terrain.cell / refine)
    return float(np.mean(a != b)) if len(a) else 0.0


def seen_by_any(terrain: Terrain, cams: FloatArray, pts: FloatArray, theta: float) -> np.ndarray:
    """Whether each ground point (m, 3) is seen by at least one camera of ``cams`` (k, 3)."""
    seen = np.zeros(len(pts), dtype=bool)
    tan_h = math.tan(theta / 2.0)
    for cam in np.asarray(cams, dtype=float):
        d = np.hypot(pts[:, 0] - cam[0], pts[:, 1] - cam[1])
        cand = np.flatnonzero(~seen & (d <= (cam[2] - pts[:, 2]) * tan_h + 1e-9))
        if len(cand):
            seen[cand] = line_of_sight(terrain, cam, pts[cand])
    return seen


def assign_altitudes(
    terrain: Terrain,
    xy: FloatArray,
    area: Polygon,
    theta: float,
    z_min: float,
    z_max: float,
    c2: float,
    *,
    step: float = CELL_STEP,
    tol: float = 0.25,
    margin: float = FOOTPRINT_MARGIN,
) -> tuple[FloatArray, dict[str, float]]:
    """Stage 1's altitudes: the lowest z_i per waypoint that sees its whole clipped cell (§7.3.1).

    1. Each waypoint's cell is its Voronoi cell clipped to D (:func:`.cells.clipped_cells`),
       sampled by its corners, its edges every ``step`` and the grid ``step·(i, j)`` inside it
       (:func:`.cells.sample_polygon`) — not the DEM nodes: the cell's corners and edges are
       where the footprint must reach.
    2. z_i starts at ``max(z_min, clearance_altitude(xy_i, c2))`` (waypoint–terrain margin (7.4)).
    3. z_i = the lowest altitude that sees every sample of its cell that is visible from
       ``(x_i, y_i, z_max)`` (bisection, :func:`lowest_altitude`; the cone bound is exact, so on
       flat ground z_i = z_g + (distance to the cell's farthest corner)/tan(θ/2)), then raised by
       ``margin``/tan(θ/2) (the footprint reaches ``margin`` past the corners; capped at z_max).
    4. Orphans — samples occluded from their own waypoint at ``z_max`` — go to the nearest camera
       that sees them at its step-3 altitude, else to the nearest that sees them from ``z_max``,
       with the samples within 1.5·``step`` around them (the band where the ground changes
       hands); that camera is raised to see them all.  Raising a camera only adds ground it sees
       (module doc), so one pass leaves every sample seen that some waypoint sees from
       ``z_max``.

    Returns:
        (z (N,), info) with counts of ``samples``, ``orphans``, ``visible_at_zmax`` (samples seen
        from some waypoint at z_max), ``seen`` and ``raised`` (waypoints raised in step 4).

    Raises:
        ValueError: if ``z_max`` cannot give the clearance c2 at some waypoint.
    """
    xy = np.asarray(xy, dtype=float)
    samples = []
    for cell in clipped_cells(xy, area) if len(xy) else []:
        p = sample_polygon(cell, step)
        samples.append(np.column_stack([p, terrain.height(p[:, 0], p[:, 1])]))
    return altitudes_for_samples(
        terrain, xy, samples, theta, z_min, z_max, c2, tol=tol, margin=margin, ring=1.5 * step
    )


def node_altitudes(
    terrain: Terrain,
    xy: FloatArray,
    nodes: FloatArray,
    theta: float,
    z_min: float,
    z_max: float,
    c2: float,
    *,
    tol: float = 0.25,
) -> tuple[FloatArray, dict[str, float]]:
    """The earlier rule, kept as the baseline: each waypoint sees the DEM nodes (m, 3) nearest it.

    Same steps as :func:`assign_altitudes` with the cell's samples replaced by the DEM nodes of
    D nearest the waypoint and no margin.  On flat ground it stops at the farthest *node* of the
    cell, short of the cell's corners: the independent checks of :mod:`.coverage` find the gaps.
    """
    from scipy.spatial import cKDTree

    xy = np.asarray(xy, dtype=float)
    owner = cKDTree(xy).query(nodes[:, :2])[1] if len(xy) else np.zeros(0, dtype=np.intp)
    samples = [nodes[owner == i] for i in range(len(xy))]
    return altitudes_for_samples(
        terrain, xy, samples, theta, z_min, z_max, c2, tol=tol, margin=0.0, ring=0.0
    )


def altitudes_for_samples(
    terrain: Terrain,
    xy: FloatArray,
    samples: list[FloatArray],
    theta: float,
    z_min: float,
    z_max: float,
    c2: float,
    *,
    tol: float,
    margin: float,
    ring: float,
) -> tuple[FloatArray, dict[str, float]]:
    """Steps 2–4 of :func:`assign_altitudes` for given ground samples (m_i, 3) per waypoint;
    ``ring`` [m]: the band of samples around an orphan that its new camera must see too."""
    n = len(xy)
    lift = margin / math.tan(theta / 2.0)
    z_floor = np.array([_floor_altitude(terrain, xy[i], i, z_min, z_max, c2) for i in range(n)])
    targets: list[FloatArray] = []
    orphans: list[FloatArray] = []
    z = np.empty(n)
    for i, mine in enumerate(samples):
        vis = visible(terrain, np.array([xy[i, 0], xy[i, 1], z_max]), mine, theta)
        targets.append(mine[vis])
        orphans.append(mine[~vis])
        z_i = lowest_altitude(terrain, xy[i], targets[i], theta, z_floor[i], z_max, tol=tol)
        z[i] = min(z_i + lift, z_max)
    lost = np.vstack(orphans) if n else np.zeros((0, 3))
    owned = sum(len(t) for t in targets)
    every = np.vstack(samples) if n else np.zeros((0, 3))
    cams = np.column_stack([xy, z])
    raised, found = _adopt_orphans(
        terrain, cams, targets, lost, every, theta, z_max, tol=tol, lift=lift, ring=ring
    )
    z = cams[:, 2]
    seen = seen_by_any(terrain, cams, lost, theta)
    info = {
        "samples": float(owned + len(lost)),
        "orphans": float(len(lost)),
        "visible_at_zmax": float(owned + found),
        "seen": float(owned + seen.sum()),
        "raised": float(raised),
    }
    return z, info


def _floor_altitude(
    terrain: Terrain, xy: FloatArray, i: int, z_min: float, z_max: float, c2: float
) -> float:
    """max(z_min, clearance altitude) at waypoint ``i``; ``ValueError`` if above z_max."""
    zc = max(z_min, clearance_altitude(terrain, xy, c2))
    if zc > z_max:
        raise ValueError(
            f"z_max: {z_max:.1f} m is below the terrain clearance {zc:.1f} m (c2 = {c2:g} m) "
            f"needed at waypoint {i} ({xy[0]:.1f}, {xy[1]:.1f})"
        )
    return zc


def _adopt_orphans(
    terrain: Terrain,
    cams: FloatArray,
    targets: list[FloatArray],
    lost: FloatArray,
    every: FloatArray,
    theta: float,
    z_max: float,
    *,
    tol: float,
    lift: float,
    ring: float,
) -> tuple[int, int]:
    """Step 4 of :func:`assign_altitudes`, in place on ``cams`` (N, 3) and ``targets``.

    Every orphan (m, 3) goes to the nearest camera that sees it at its current altitude, else to
    the nearest that sees it from ``z_max``, together with the samples of ``every`` within
    ``ring`` [m] of it that this camera sees from ``z_max``: between an orphan and its neighbours
    the ground changes hands, and a camera seeing both sides leaves no sliver unseen.  The camera
    is raised until it sees all of them.  Returns (cameras raised, orphans visible at z_max).
    """
    n = len(cams)
    if len(lost) == 0 or n == 0:
        return 0, 0
    from scipy.spatial import cKDTree

    k = min(n, 24)  # the cone at z_max reaches ~2R: the 19 lattice points within 2R, and more
    near = cKDTree(cams[:, :2]).query(lost[:, :2], k=k)[1].reshape(len(lost), k)
    owner = np.full(len(lost), -1)
    for at_max in (False, True):
        for rank in range(k):
            for j in np.unique(near[owner < 0, rank]):
                idx = np.flatnonzero((owner < 0) & (near[:, rank] == j))
                cam = np.array([cams[j, 0], cams[j, 1], z_max if at_max else cams[j, 2]])
                owner[idx[visible(terrain, cam, lost[idx], theta)]] = j
    tree = cKDTree(every[:, :2]) if ring > 0 else None
    raised = 0
    for j in np.unique(owner[owner >= 0]):
        mine = lost[owner == j]
        cam_top = np.array([cams[j, 0], cams[j, 1], z_max])
        if tree is not None:
            hits = tree.query_ball_point(mine[:, :2], ring)
            band = every[np.unique(np.concatenate([np.asarray(h, dtype=np.intp) for h in hits]))]
            mine = np.vstack([mine, band[visible(terrain, cam_top, band, theta)]])
        targets[j] = np.vstack([targets[j], mine])
        z_j = lowest_altitude(
            terrain, cams[j, :2], targets[j], theta, cams[j, 2] - lift, z_max, tol=tol
        )
        z_new = min(max(z_j + lift, cams[j, 2]), z_max)
        raised += int(z_new > cams[j, 2])
        cams[j, 2] = z_new
    return raised, int((owner >= 0).sum())
