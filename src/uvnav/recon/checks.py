"""Checks run on every reconnaissance plan (thesis Ch. 7 §7.2: coverage, δ, (7.4), turning radius).

Thesis: Y. Zhang, Ch. 7 (J. Zhang and Y. Zhang, ICCAR 2020).  The chapter claims full coverage
of D at the lowest altitude, a trajectory through every waypoint's δ-neighbourhood, safety margins
(7.4) and a smooth curve within the UAV's kinematic limits; these functions *measure* each claim
on a plan, independently of how the plan was built:

* coverage: fraction of D's DEM nodes seen by at least one waypoint camera at its altitude, over
  (a) all nodes and (b) the nodes visible from some waypoint at Z_max ("visible at all") — a
  coarse figure; the ground-truth checks (finer grid, random points, footprint polygons) are in
  :mod:`.coverage`;
* max distance waypoint → trajectory (dense samples of τ, an upper bound of the true distance);
* max horizontal curvature of τ (analytic Bézier derivatives at dense samples) vs 1/r_min;
* max tangent-angle jump at the Bézier joints [rad];
* min vertical clearance of τ above the terrain (an upper bound of its 3D distance; near a
  waypoint (7.4) guarantees c2 − δ, between waypoints the altitude bump aims at c2), min
  waypoint–terrain distance and min waypoint–waypoint distance (7.4);
* lengths (total and per UAV).

Units: lengths [m], angles [rad], curvature [1/m].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from uvnav.recon.bezier import Trajectory, bezier_eval
from uvnav.recon.terrain import Terrain
from uvnav.recon.visibility import seen_by_any, terrain_distance

FloatArray = np.ndarray


@dataclass(frozen=True)
class TrajectoryCheck:
    """Measured properties of one closed trajectory (units in field names' docs)."""

    length: float  # [m]
    max_waypoint_distance: float  # [m]
    max_curvature: float  # horizontal [1/m]
    curvature_bound: float  # 1/r_min [1/m]
    max_tangent_jump: float  # [rad]
    min_clearance: float  # vertical, above terrain [m]
    n_pieces: int


def check_trajectory(
    traj: Trajectory, waypoints: FloatArray, terrain: Terrain | None = None, *, per_piece: int = 48
) -> TrajectoryCheck:
    """Measure length, δ, curvature, tangent jumps and clearance of ``traj``.

    ``waypoints`` (n, 3) are the waypoints this trajectory must visit (in any order).
    """
    B = traj.beziers
    t = np.linspace(0.0, 1.0, per_piece + 1)
    pos, d1, d2 = bezier_eval(B, t)
    seg = np.linalg.norm(np.diff(pos, axis=1), axis=2).sum()
    xp, yp = d1[..., 0], d1[..., 1]
    xpp, ypp = d2[..., 0], d2[..., 1]
    speed2 = xp * xp + yp * yp
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa = np.abs(xp * ypp - yp * xpp) / speed2**1.5
    kappa = np.where(speed2 > 1e-12, kappa, 0.0)
    end_d = d1[:, -1, :]
    start_d = np.roll(d1[:, 0, :], -1, axis=0)
    cosang = np.sum(end_d * start_d, axis=1) / np.maximum(
        np.linalg.norm(end_d, axis=1) * np.linalg.norm(start_d, axis=1), 1e-300
    )
    jump = float(np.max(np.arccos(np.clip(cosang, -1.0, 1.0)))) if len(B) else 0.0
    pts = pos.reshape(-1, 3)
    W = np.asarray(waypoints, dtype=float)
    from scipy.spatial import cKDTree

    dmin = cKDTree(pts).query(W)[0] if len(W) else np.zeros(0)
    clear = float(np.min(pts[:, 2] - terrain.height(pts[:, 0], pts[:, 1]))) if terrain else math.inf
    return TrajectoryCheck(
        length=float(seg),
        max_waypoint_distance=float(dmin.max()) if len(W) else 0.0,
        max_curvature=float(np.max(kappa)) if kappa.size else 0.0,
        curvature_bound=1.0 / traj.r_min,
        max_tangent_jump=jump,
        min_clearance=clear,
        n_pieces=len(B),
    )


@dataclass(frozen=True)
class CoverageCheck:
    """Coverage of D's DEM nodes by the waypoint cameras."""

    nodes: int
    visible_at_zmax: int
    seen: int
    seen_of_visible: int

    @property
    def coverage_all(self) -> float:
        """Seen / all nodes of D."""
        return self.seen / self.nodes if self.nodes else 1.0

    @property
    def coverage_visible(self) -> float:
        """Seen / nodes visible from some waypoint at Z_max (the target: 1.0)."""
        return self.seen_of_visible / self.visible_at_zmax if self.visible_at_zmax else 1.0


def check_coverage(
    terrain: Terrain, nodes: FloatArray, waypoints: FloatArray, theta: float, z_max: float
) -> CoverageCheck:
    """Recompute coverage from the waypoints (n, 3) independently of the planner."""
    W = np.asarray(waypoints, dtype=float)
    seen = seen_by_any(terrain, W, nodes, theta)
    vis = seen_by_any(terrain, np.column_stack([W[:, :2], np.full(len(W), z_max)]), nodes, theta)
    return CoverageCheck(len(nodes), int(vis.sum()), int(seen.sum()), int((seen & vis).sum()))


def check_margins_measured(
    terrain: Terrain, waypoints: FloatArray, *, search: float
) -> tuple[float, float]:
    """(min waypoint–waypoint distance, min waypoint–terrain distance) [m] for (7.4)."""
    W = np.asarray(waypoints, dtype=float)
    if len(W) > 1:
        from scipy.spatial import cKDTree

        dd = cKDTree(W).query(W, k=2)[0][:, 1]
        qij = float(dd.min())
    else:
        qij = math.inf
    qi = float(terrain_distance(terrain, W, search).min()) if len(W) else math.inf
    return qij, qi
