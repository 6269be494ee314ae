"""The two-stage reconnaissance planner of thesis Ch. 7 (§7.3), end to end, with its checks.

Thesis: Y. Zhang, Ch. 7 "A Method for UAV Reconnaissance and Surveillance in Complex
Environments" (J. Zhang and Y. Zhang, ICCAR 2020), eqs. (7.1)–(7.4), Figs. 7.1–7.4.

:func:`plan_recon` runs

1. validation of the inputs (area inside the DEM, θ ∈ (0, π), Z_min ≤ Z_max, margins (7.4)
   c1 > 2δ > 0, c2 > δ, lattice spacing √3·R ≥ c1, r_min small enough for δ) — each failure is a
   ``ValueError`` whose message starts with the offending field;
2. Stage 1: the optimal triangular lattice for footprint radius R (:mod:`.lattice`), then the
   lowest altitude per waypoint that sees its whole clipped cell (corners and edges included),
   with occlusion and terrain clearance c2 (:mod:`.visibility`);
3. Stage 2: k-means clusters (one per UAV) or given labels; per cluster a closed tour by the TSP
   (OR-Tools) and by the spiral order (both measured); the smooth Bézier trajectory τ of each UAV
   on its TSP tour (:mod:`.bezier`); with several UAVs also the thesis's second scenario — one
   UAV flying the merged tour (Fig. 7.4(d));
4. the checks of :mod:`.checks`, the coverage on ground truth of :mod:`.coverage` (footprint
   polygons, a 0.5 m grid and random points apart from every planning sample; see
   ``ReconConfig.check_*``) and the stage timings.

Altitudes Z_min, Z_max and waypoint z are absolute [m] in the DEM's datum; defaults (``None``)
are Z_min = 0 and Z_max = the highest terrain under D (buffered by R) + 2·R/tan(θ/2).

Units: lengths [m], angles [rad], times [s].
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from shapely.geometry import Polygon

from uvnav.recon.bezier import Trajectory, build_trajectory, check_turn_radius
from uvnav.recon.checks import (
    CoverageCheck,
    TrajectoryCheck,
    check_coverage,
    check_margins_measured,
    check_trajectory,
)
from uvnav.recon.coverage import (
    PointCoverage,
    PolygonCoverage,
    check_coverage_polygons,
    check_grid,
    check_random,
)
from uvnav.recon.lattice import LatticeSolution, check_margins, optimal_lattice
from uvnav.recon.terrain import Terrain, check_area_inside
from uvnav.recon.tour import cluster_tours, kmeans_clusters, merge_tours, tour_length
from uvnav.recon.visibility import assign_altitudes, check_theta

FloatArray = np.ndarray


@dataclass(frozen=True)
class ReconConfig:
    """Inputs of the planner.

    Attributes:
        theta: Camera cone full angle θ [rad], in (0, π).
        footprint_radius: R [m], the lattice's cell radius (triangle side √3·R).
        z_min: Lowest flight altitude [m] (absolute; None = 0).
        z_max: Highest flight altitude [m] (absolute; None = auto, see module doc).
        delta: δ [m], how far τ may pass from a waypoint.
        c1: Waypoint–waypoint margin [m] (7.4), > 2δ.
        c2: Waypoint–terrain margin [m] (7.4), > δ; also kept by τ above the terrain.
        r_min: UAV turning radius [m].
        uavs: Number of UAVs (clusters).
        seed: Seed for k-means.
        integrated: With several UAVs, also plan one UAV over the merged tour (Fig. 7.4(d)).
        n_lambda: λ samples of the lattice search.
        lattice_pairs: Lattice vectors paired with the edge-aligned lines in that search.
        tsp: OR-Tools metaheuristic, "greedy" (reproducible) or "gls".
        tsp_time_limit: Cap on each TSP solve [s].
        check_step: Spacing [m] of the independent coverage grid (None: no grid check).
        check_points: Seeded uniform random points of the independent check (0: none).
        check_polygons: Run the shapely footprint-polygon check.
    """

    theta: float = math.radians(90.0)
    footprint_radius: float = 30.0
    z_min: float | None = None
    z_max: float | None = None
    delta: float = 5.0
    c1: float = 15.0
    c2: float = 10.0
    r_min: float = 15.0
    uavs: int = 1
    seed: int = 0
    integrated: bool = True
    n_lambda: int = 24
    lattice_pairs: int = 60
    tsp: str = "greedy"
    tsp_time_limit: float = 20.0
    check_step: float | None = 0.5
    check_points: int = 200_000
    check_polygons: bool = True


@dataclass
class UavPlan:
    """One UAV's tour and trajectory with its checks."""

    indices: np.ndarray
    tsp_length: float
    spiral_length: float
    trajectory: Trajectory
    check: TrajectoryCheck


@dataclass
class ReconPlan:
    """The result of :func:`plan_recon`."""

    config: ReconConfig
    area: Polygon
    terrain: Terrain
    lattice: LatticeSolution
    waypoints: FloatArray  # (N, 3)
    labels: np.ndarray
    z_min: float
    z_max: float
    coverage: CoverageCheck
    ground: GroundCoverage
    uavs: list[UavPlan]
    integrated: UavPlan | None
    min_waypoint_separation: float
    min_waypoint_terrain: float
    timings: dict[str, float] = field(default_factory=dict)

    def summary(self) -> dict[str, Any]:
        """Flat dict of the measured figures (JSON-friendly)."""
        out: dict[str, Any] = {
            "area_m2": float(self.area.area),
            "R": self.lattice.R,
            "theta_deg": math.degrees(self.config.theta),
            "n_waypoints": self.lattice.n,
            "n_naive": self.lattice.n_naive,
            "bound_disc": self.lattice.bound_disc,
            "bound_kershner": self.lattice.bound_kershner,
            "lambda_deg": math.degrees(self.lattice.lam),
            "n_outside_area": self.lattice.n_outside,
            "z_min": self.z_min,
            "z_max": self.z_max,
            "altitude_min": float(self.waypoints[:, 2].min()),
            "altitude_max": float(self.waypoints[:, 2].max()),
            "altitude_mean": float(self.waypoints[:, 2].mean()),
            "coverage_all": self.coverage.coverage_all,
            "coverage_visible": self.coverage.coverage_visible,
            "ground_nodes": self.coverage.nodes,
            **self.ground.summary(),
            "min_waypoint_separation": self.min_waypoint_separation,
            "min_waypoint_terrain": self.min_waypoint_terrain,
            "uavs": len(self.uavs),
            "tsp_length_total": sum(u.tsp_length for u in self.uavs),
            "spiral_length_total": sum(u.spiral_length for u in self.uavs),
            "trajectory_length_total": sum(u.check.length for u in self.uavs),
            "trajectory_lengths": [u.check.length for u in self.uavs],
            "max_waypoint_distance": max(u.check.max_waypoint_distance for u in self.uavs),
            "max_curvature": max(u.check.max_curvature for u in self.uavs),
            "curvature_bound": 1.0 / self.config.r_min,
            "max_tangent_jump": max(u.check.max_tangent_jump for u in self.uavs),
            "min_clearance": min(u.check.min_clearance for u in self.uavs),
            "delta": self.config.delta,
            "planning_time_s": self.timings.get("total", float("nan")),
            "timings": dict(self.timings),
        }
        if self.integrated is not None:
            out["integrated_length"] = self.integrated.check.length
            out["integrated_tsp_length"] = self.integrated.tsp_length
            out["integrated_max_curvature"] = self.integrated.check.max_curvature
            out["integrated_max_waypoint_distance"] = self.integrated.check.max_waypoint_distance
        return out


@dataclass(frozen=True)
class GroundCoverage:
    """The independent coverage checks of :mod:`.coverage` (``None`` where not run)."""

    grid: PointCoverage | None
    grid_step: float | None
    random: PointCoverage | None
    polygons: PolygonCoverage | None

    def summary(self) -> dict[str, Any]:
        """Flat JSON-friendly figures (NaN where a check was not run)."""
        nan = float("nan")
        g, r, p = self.grid, self.random, self.polygons
        return {
            "check_grid_step": nan if self.grid_step is None else self.grid_step,
            "check_grid_points": 0 if g is None else g.points,
            "coverage_grid_all": nan if g is None else g.coverage_all,
            "coverage_grid_visible": nan if g is None else g.coverage_visible,
            "grid_unseen_visible": 0 if g is None else g.visible_at_zmax - g.seen_of_visible,
            "check_random_points": 0 if r is None else r.points,
            "coverage_random_all": nan if r is None else r.coverage_all,
            "coverage_random_visible": nan if r is None else r.coverage_visible,
            "coverage_polygon": nan if p is None else p.coverage,
            "polygon_uncovered_m2": nan if p is None else p.uncovered_area,
            "polygon_largest_gap_m": nan if p is None else p.largest_gap,
            "polygon_cells_not_seen": -1 if p is None else p.cells_not_seen,
        }


def ground_truth_coverage(
    terrain: Terrain, area: Polygon, W: FloatArray, cfg: ReconConfig, z_max: float
) -> GroundCoverage:
    """Run the independent coverage checks that ``cfg`` asks for on waypoints W (N, 3)."""
    step = cfg.check_step
    grid = None if step is None else check_grid(terrain, W, area, cfg.theta, z_max, step=step)
    rnd = None
    if cfg.check_points > 0:
        rnd = check_random(terrain, W, area, cfg.theta, z_max, n=cfg.check_points, seed=cfg.seed)
    poly = check_coverage_polygons(terrain, W, area, cfg.theta) if cfg.check_polygons else None
    return GroundCoverage(grid, step, rnd, poly)


def validate_inputs(terrain: Terrain, area: Polygon, cfg: ReconConfig) -> tuple[float, float]:
    """Check every input; return the resolved (Z_min, Z_max) [m]. Raises ``ValueError``."""
    check_theta(cfg.theta)
    if not cfg.footprint_radius > 0:
        raise ValueError(f"radius: footprint radius R must be > 0, got {cfg.footprint_radius}")
    if area.is_empty or not area.is_valid or area.area <= 0:
        raise ValueError("area: D must be a valid polygon with positive area")
    check_area_inside(terrain, area)
    check_margins(cfg.footprint_radius, cfg.delta, cfg.c1, cfg.c2)
    check_turn_radius(cfg.r_min, cfg.delta)
    if cfg.check_step is not None and not cfg.check_step > 0:
        raise ValueError(
            f"check_step: the coverage grid spacing must be > 0 m, got {cfg.check_step}"
        )
    if cfg.check_points < 0:
        raise ValueError(f"check_points: must be >= 0, got {cfg.check_points}")
    if cfg.uavs < 1:
        raise ValueError(f"uavs: need at least 1, got {cfg.uavs}")
    z_min = 0.0 if cfg.z_min is None else float(cfg.z_min)
    if cfg.z_max is None:
        region = area.buffer(cfg.footprint_radius)
        xmin, ymin, xmax, ymax = region.bounds
        xs = np.linspace(xmin, xmax, 80)
        ys = np.linspace(ymin, ymax, 80)
        X, Y = np.meshgrid(xs, ys)
        top = float(terrain.height(X, Y).max())
        z_max = top + 2.0 * cfg.footprint_radius / math.tan(cfg.theta / 2.0)
    else:
        z_max = float(cfg.z_max)
    if z_min < 0:
        raise ValueError(f"z_min: must be >= 0 (7.1), got {z_min}")
    if z_min > z_max:
        raise ValueError(f"z_min: {z_min:g} m exceeds z_max = {z_max:g} m (7.1)")
    return z_min, z_max


def plan_recon(
    terrain: Terrain,
    area: Polygon,
    cfg: ReconConfig,
    *,
    labels: np.ndarray | None = None,
) -> ReconPlan:
    """Plan waypoints and closed smooth tours for ``cfg.uavs`` UAVs over D (module doc).

    Args:
        terrain: The DEM.
        area: Target area D [m].
        cfg: Planner inputs.
        labels: Optional given clusters (N,) — only valid when N is known in advance; by default
            k-means with ``cfg.uavs`` clusters.
    """
    timings: dict[str, float] = {}
    t_all = time.perf_counter()
    z_min, z_max = validate_inputs(terrain, area, cfg)

    t = time.perf_counter()
    lat = optimal_lattice(
        area, cfg.footprint_radius, n_lambda=cfg.n_lambda, max_pairs_k=cfg.lattice_pairs
    )
    timings["lattice"] = time.perf_counter() - t

    t = time.perf_counter()
    nodes = terrain.nodes_in(area)
    z, _info = assign_altitudes(terrain, lat.xy, area, cfg.theta, z_min, z_max, cfg.c2)
    W = np.column_stack([lat.xy, z])
    timings["altitudes"] = time.perf_counter() - t

    t = time.perf_counter()
    if labels is None:
        labels = kmeans_clusters(lat.xy, cfg.uavs, seed=cfg.seed)
    else:
        labels = np.asarray(labels, dtype=np.intp)
        if labels.shape != (lat.n,):
            raise ValueError(f"labels: need one label per waypoint ({lat.n}), got {labels.shape}")
    tsp_tours = cluster_tours(
        W, labels, method="tsp", metaheuristic=cfg.tsp, time_limit_s=cfg.tsp_time_limit
    )
    spiral_tours = cluster_tours(W, labels, method="spiral")
    timings["tours"] = time.perf_counter() - t

    t = time.perf_counter()
    uavs: list[UavPlan] = []
    for tour, sp in zip(tsp_tours, spiral_tours, strict=True):
        traj = build_trajectory(
            W, tour, r_min=cfg.r_min, delta=cfg.delta, terrain_height=terrain.height, c2=cfg.c2
        )
        uavs.append(
            UavPlan(
                tour,
                tour_length(W, tour),
                tour_length(W, sp),
                traj,
                check_trajectory(traj, W[tour], terrain),
            )
        )
    integrated = None
    if cfg.integrated and len(tsp_tours) > 1:
        merged = tsp_tours[0]
        for other in tsp_tours[1:]:
            merged = merge_tours(W, merged, other)
        traj = build_trajectory(
            W, merged, r_min=cfg.r_min, delta=cfg.delta, terrain_height=terrain.height, c2=cfg.c2
        )
        integrated = UavPlan(
            merged, tour_length(W, merged), float("nan"), traj, check_trajectory(traj, W, terrain)
        )
    timings["trajectory"] = time.perf_counter() - t
    timings["total"] = time.perf_counter() - t_all

    coverage = check_coverage(terrain, nodes, W, cfg.theta, z_max)
    ground = ground_truth_coverage(terrain, area, W, cfg, z_max)
    qij, qi = check_margins_measured(terrain, W, search=2 * cfg.c2)
    timings["checks"] = time.perf_counter() - t_all - timings["total"]
    return ReconPlan(
        config=cfg,
        area=area,
        terrain=terrain,
        lattice=lat,
        waypoints=W,
        labels=labels,
        z_min=z_min,
        z_max=z_max,
        coverage=coverage,
        ground=ground,
        uavs=uavs,
        integrated=integrated,
        min_waypoint_separation=qij,
        min_waypoint_terrain=qi,
        timings=timings,
    )
