"""Coverage of D on ground truth, independent of the planning samples (thesis Ch. 7 §7.3.1).

Thesis: Y. Zhang, Ch. 7 (J. Zhang and Y. Zhang, ICCAR 2020): after Stage 1 "the target area D is
covered completely" by the cameras at the waypoints' lowest altitudes.  The camera model is the
one of :mod:`.visibility` ((7.2) with the height above the seen point, plus line of sight).

The clipped cells of :mod:`.cells` partition D, so D is covered when every cell is seen.

Two checks that share nothing with the planner's samples:

* :func:`check_coverage_polygons` — the footprint of each camera on the terrain as a polygon
  (cone only, no occlusion): along ``n_az`` azimuths the largest r such that the ground stays in
  the cone from the nadir out to r (marched at ``step``, then bisected to 1 mm); on flat ground
  that is the inscribed polygon of the circle of radius (z − z_g)·tan(θ/2).  Shapely then gives
  D minus the union of footprints (its area and the largest distance from an uncovered point to
  a footprint) and, per waypoint, its clipped cell minus its own footprint.
* :func:`check_coverage_points` — ground points on a regular grid (default 0.5 m, offset by half a
  step from D's lower-left corner, so it meets neither the DEM nodes nor the planner's samples) and
  seeded uniform random points in D, each tested against every camera in cone *and* line of sight
  over the DEM; reported against all points and against those seen from some waypoint at Z_max
  (the ground a camera can see at all).

Measured (``uvnav run``'s Chapter 7 rows, :func:`uvnav.experiments.ch7.coverage_rows`; 300 m
and 600 m squares, R = 20/30/50 m, θ = 90°): altitudes that see the 5 m DEM nodes of each cell
(:func:`.visibility.node_altitudes`) see only
98.49 [ev:ch7-coverage.flat_600_R20_node_rule_grid_pct]–
99.36 % [ev:ch7-coverage.flat_300_R50_node_rule_grid_pct]
of flat ground on the 0.5 m grid (largest gap 2.0–2.6 m past a footprint) and
91.99 [ev:ch7-coverage.jacksboro_600_R20_node_rule_grid_pct]–
99.39 % [ev:ch7-coverage.jacksboro_300_R50_node_rule_grid_pct]
of the Jacksboro crop; the cell rule (:func:`.visibility.assign_altitudes`) reads 100.00 % on all
three checks for both terrains (0 [ev:ch7-coverage.grid_points_unseen] grid points unseen;
``python -m uvnav.experiments.evidence --only ch7-coverage`` regenerates these figures).

Units: lengths [m], areas [m²], angles [rad].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import Polygon

from uvnav.recon.cells import clipped_cells, grid_points, random_points
from uvnav.recon.terrain import Terrain
from uvnav.recon.visibility import check_theta, seen_by_any

FloatArray = np.ndarray


def footprint_polygon(
    terrain: Terrain, cam: FloatArray, theta: float, *, n_az: int = 720, step: float = 0.25
) -> Polygon:
    """The camera's ground footprint (cone only) as a star-shaped polygon (module doc) [m]."""
    check_theta(theta)
    tan_h = math.tan(theta / 2.0)
    cam = np.asarray(cam, dtype=float)
    z_low = float(terrain.z.min())
    r_max = max((cam[2] - z_low) * tan_h, 0.0)
    phi = 2.0 * math.pi * np.arange(n_az) / n_az
    u = np.column_stack([np.cos(phi), np.sin(phi)])

    def inside(r: FloatArray) -> FloatArray:  # r (n_az, k) -> in cone
        x = cam[0] + u[:, 0, None] * r
        y = cam[1] + u[:, 1, None] * r
        return np.asarray(r <= (cam[2] - terrain.height(x, y)) * tan_h)

    rs = np.append(np.arange(0.0, r_max, step), r_max)[None, :]
    ok = inside(np.broadcast_to(rs, (n_az, rs.shape[1])))
    first_bad = np.where(ok.all(axis=1), rs.shape[1], np.argmin(ok, axis=1))
    lo = np.where(first_bad > 0, rs[0, np.maximum(first_bad - 1, 0)], 0.0)
    hi = np.where(first_bad < rs.shape[1], rs[0, np.minimum(first_bad, rs.shape[1] - 1)], lo)
    while np.any(hi - lo > 1e-3):
        mid = 0.5 * (lo + hi)
        good = inside(mid[:, None])[:, 0]
        lo = np.where(good, mid, lo)
        hi = np.where(good, hi, mid)
    return Polygon(cam[None, :2] + u * lo[:, None])


@dataclass(frozen=True)
class PolygonCoverage:
    """Shapely coverage of D by the footprint polygons (cone only)."""

    area: float  # area of D [m²]
    uncovered_area: float  # D minus the union of footprints [m²]
    largest_gap: float  # farthest uncovered point from a footprint [m]
    cells_not_seen: int  # clipped cells not inside their own waypoint's footprint
    largest_cell_gap: float  # same distance, cell minus own footprint [m]

    @property
    def coverage(self) -> float:
        """Covered share of D's area."""
        return 1.0 - self.uncovered_area / self.area if self.area > 0 else 1.0


def _largest_gap(gaps: object, feet: list[Polygon]) -> float:
    """Farthest point of ``gaps`` from the footprints [m]: their boundaries densified to 5 cm and
    their inscribed-circle centres, measured to the nearest footprint (an STR tree)."""
    tree = shapely.STRtree(feet)
    worst = 0.0
    for g in shapely.get_parts(gaps):
        if g.is_empty or g.area <= 0:
            continue
        pts = shapely.get_coordinates(shapely.segmentize(g.boundary, 0.05))
        centre = shapely.get_coordinates(shapely.maximum_inscribed_circle(g, 1e-3))[:1]
        _, d = tree.query_nearest(shapely.points(np.vstack([pts, centre])), return_distance=True)
        worst = max(worst, float(np.max(d)))
    return worst


def check_coverage_polygons(
    terrain: Terrain,
    waypoints: FloatArray,
    area: Polygon,
    theta: float,
    *,
    n_az: int = 720,
    tol: float = 1e-3,
) -> PolygonCoverage:
    """Footprint polygons vs D and vs each clipped cell (module doc); gaps under ``tol`` [m²] of
    area are rounding of the polygons and not counted."""
    W = np.asarray(waypoints, dtype=float)
    feet = [footprint_polygon(terrain, w, theta, n_az=n_az) for w in W]
    union = shapely.union_all(feet)
    gaps = area.difference(union)
    cells = clipped_cells(W[:, :2], area)
    cell_gaps = [c.difference(f) for c, f in zip(cells, feet, strict=True)]
    bad = [g for g in cell_gaps if g.area > tol]
    return PolygonCoverage(
        area=float(area.area),
        uncovered_area=float(gaps.area) if gaps.area > tol else 0.0,
        largest_gap=_largest_gap(gaps, feet) if gaps.area > tol else 0.0,
        cells_not_seen=len(bad),
        largest_cell_gap=max(
            (_largest_gap(g, [f]) for g, f in zip(cell_gaps, feet, strict=True) if g.area > tol),
            default=0.0,
        ),
    )


@dataclass(frozen=True)
class PointCoverage:
    """Coverage of ground points of D by the cameras (cone and line of sight)."""

    points: int
    visible_at_zmax: int
    seen: int
    seen_of_visible: int

    @property
    def coverage_all(self) -> float:
        """Seen / all points."""
        return self.seen / self.points if self.points else 1.0

    @property
    def coverage_visible(self) -> float:
        """Seen / points seen from some waypoint at Z_max (the target: 1.0)."""
        return self.seen_of_visible / self.visible_at_zmax if self.visible_at_zmax else 1.0


def check_coverage_points(
    terrain: Terrain, waypoints: FloatArray, pts_xy: FloatArray, theta: float, z_max: float
) -> PointCoverage:
    """Which ground points (m, 2) [m] the cameras at ``waypoints`` (N, 3) see (module doc)."""
    W = np.asarray(waypoints, dtype=float)
    xy = np.asarray(pts_xy, dtype=float)
    pts = np.column_stack([xy, terrain.height(xy[:, 0], xy[:, 1])])
    seen = seen_by_any(terrain, W, pts, theta)
    vis = seen.copy()
    rest = np.flatnonzero(~seen)
    if len(rest):
        top = np.column_stack([W[:, :2], np.full(len(W), z_max)])
        vis[rest] = seen_by_any(terrain, top, pts[rest], theta)
    return PointCoverage(len(pts), int(vis.sum()), int(seen.sum()), int((seen & vis).sum()))


def check_grid(
    terrain: Terrain,
    waypoints: FloatArray,
    area: Polygon,
    theta: float,
    z_max: float,
    *,
    step: float = 0.5,
) -> PointCoverage:
    """:func:`check_coverage_points` on the grid D's lower-left corner + step·(i + ½, j + ½)."""
    xmin, ymin, _, _ = area.bounds
    pts = grid_points(area, step, anchor=(xmin + 0.5 * step, ymin + 0.5 * step))
    return check_coverage_points(terrain, waypoints, pts, theta, z_max)


def check_random(
    terrain: Terrain,
    waypoints: FloatArray,
    area: Polygon,
    theta: float,
    z_max: float,
    *,
    n: int = 200_000,
    seed: int = 0,
) -> PointCoverage:
    """:func:`check_coverage_points` on ``n`` seeded uniform random points of D."""
    pts = random_points(area, n, np.random.default_rng(seed))
    return check_coverage_points(terrain, waypoints, pts, theta, z_max)
