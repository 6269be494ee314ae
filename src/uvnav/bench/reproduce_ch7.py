"""Thesis Chapter 7 reproduction for ``uvnav run``: the 300 m x 300 m and 600 m x 600 m experiments.

Thesis: Y. Zhang, Ch. 7 §7.3.1 (Fig. 7.3: a 300 x 300 m² terrain) and §7.4 (Fig. 7.4: a
600 x 600 m² terrain, two UAVs on two clusters, then one UAV on the integrated tour).  The chapter
reports no numbers — only that D "is covered completely", that the waypoint count "is the minimum
one" and that the altitude "is the lowest possible" — so the table's *thesis* column quotes those
claims and the *measured* column gives what uvnav measures on the same experiment sizes:

* Stage 1 counts: N of the optimised lattice vs the naive lattice and the bounds A/(πR²) and
  A/(1.5·√3·R²) (Kershner) for R ∈ {20, 30, 50} m on both sizes (pure geometry);
* full plans (quick: synthetic 300 m with R = 30 m, Jacksboro 600 m with R = 50 m; ``full``: both
  terrains x both sizes x R ∈ {20, 30, 50} m): coverage of the nodes visible at Z_max, tour
  lengths (TSP vs spiral, two UAVs vs one integrated), δ, curvature vs 1/r_min, planning time.

Every plan's summary is written to ``out_dir/<name>.json``; a caller that can draw (the CLI,
layer 8) passes ``render_plan(plan, out_dir / name) -> list[Path]`` for figures — this module
(layer 6) never imports :mod:`uvnav.viz`.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from uvnav.recon.lattice import optimal_lattice
from uvnav.recon.plan import ReconConfig, ReconPlan, plan_recon
from uvnav.recon.terrain import Terrain, fractal_terrain, load_jacksboro, square_area

SIZES = (300.0, 600.0)
RADII = (20.0, 30.0, 50.0)
QUICK_PLANS = (("synthetic", 300.0, 30.0), ("jacksboro", 600.0, 50.0))
THETA = math.radians(90.0)


@dataclass
class Ch7Summary:
    """Rows for the "thesis reported vs uvnav measured" table, plan summaries and figure files."""

    table: list[dict[str, str]] = field(default_factory=list)
    plans: dict[str, dict[str, Any]] = field(default_factory=dict)
    lattice: list[dict[str, float]] = field(default_factory=list)
    figures: list[Path] = field(default_factory=list)
    wall_time: float = 0.0


def experiment_terrain(kind: str, side: float) -> tuple[Terrain, Any]:
    """The terrain and centred square D of one experiment (``synthetic`` or ``jacksboro``)."""
    if kind == "synthetic":
        pad = 150.0
        t = fractal_terrain(
            (side + 2 * pad, side + 2 * pad),
            cell=5.0,
            seed=7,
            origin=(-pad, -pad),
            relief=40.0,
            n_blocks=int(side * side / 6000),
        )
    elif kind == "jacksboro":
        t = load_jacksboro()
    else:
        raise ValueError(f"terrain: unknown kind {kind!r}")
    xmin, ymin, xmax, ymax = t.bounds
    return t, square_area(side, center=(0.5 * (xmin + xmax), 0.5 * (ymin + ymax)))


def lattice_rows(
    sizes: tuple[float, ...] = SIZES, radii: tuple[float, ...] = RADII
) -> list[dict[str, float]]:
    """Stage 1 counts for every size and R (pure geometry, no terrain)."""
    rows = []
    for side in sizes:
        for R in radii:
            t = time.perf_counter()
            sol = optimal_lattice(square_area(side), R)
            rows.append(
                {
                    "side": side,
                    "R": R,
                    "n": sol.n,
                    "n_naive": sol.n_naive,
                    "bound_disc": sol.bound_disc,
                    "bound_kershner": sol.bound_kershner,
                    "lambda_deg": math.degrees(sol.lam),
                    "seconds": time.perf_counter() - t,
                }
            )
    return rows


def reproduce_ch7(
    out_dir: Path,
    *,
    full: bool = False,
    render_plan: Callable[[ReconPlan, Path], list[Path]] | None = None,
    sizes: tuple[float, ...] = SIZES,
    radii: tuple[float, ...] = RADII,
    plans: list[tuple[str, float, float]] | None = None,
) -> Ch7Summary:
    """Run the Ch. 7 experiments (module doc); write JSON summaries; return the table rows.

    Args:
        out_dir: Folder of the JSON summaries (and figures, if ``render_plan``).
        full: All terrains x sizes x radii instead of the quick pair.
        render_plan: Draws one plan's figures at a path prefix; ``None`` draws nothing.
        sizes: Square sides [m] of the Stage 1 count rows.
        radii: Footprint radii R [m] of the Stage 1 count rows.
        plans: Override the (terrain kind, side [m], R [m]) of the full plans.
    """
    tic = time.perf_counter()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    summary = Ch7Summary()
    summary.lattice = lattice_rows(sizes, radii)
    for r in summary.lattice:
        summary.table.append(
            {
                "quantity": f"Ch7 waypoints N, {r['side']:.0f} m square, R = {r['R']:.0f} m",
                "thesis": '"the minimum one" (no count given)',
                "measured": f"{r['n']}",
                "note": (
                    f"naive lattice {r['n_naive']}; bounds A/(πR²) {r['bound_disc']:.1f}, "
                    f"Kershner {r['bound_kershner']:.1f}; λ = {r['lambda_deg']:.1f}°"
                ),
            }
        )
    if plans is None:
        plans = (
            [(k, s, R) for k in ("synthetic", "jacksboro") for s in SIZES for R in RADII]
            if full
            else list(QUICK_PLANS)
        )
    for kind, side, R in plans:
        terrain, area = experiment_terrain(kind, side)
        cfg = ReconConfig(theta=THETA, footprint_radius=R, uavs=2, r_min=min(15.0, 0.5 * R))
        plan = plan_recon(terrain, area, cfg)
        s = plan.summary()
        name = f"ch7-{kind}-{side:.0f}m-R{R:.0f}"
        s["terrain"] = terrain.source
        (out_dir / f"{name}.json").write_text(json.dumps(s, indent=2, default=float))
        summary.plans[name] = s
        if render_plan is not None:
            summary.figures += render_plan(plan, out_dir / name)
        label = f"Ch7 {kind} {side:.0f} m, R = {R:.0f} m"
        summary.table += [
            {
                "quantity": f"{label}: coverage of ground visible at Z_max",
                "thesis": '"covered completely"',
                "measured": f"{100 * s['coverage_visible']:.2f} %",
                "note": (
                    f"{100 * s['coverage_all']:.2f} % of all {s['ground_nodes']} DEM nodes in D"
                ),
            },
            {
                "quantity": f"{label}: tour length, 2 UAVs / 1 UAV integrated [m]",
                "thesis": "not reported",
                "measured": (
                    f"{s['trajectory_length_total']:.0f} / "
                    f"{s.get('integrated_length', float('nan')):.0f}"
                ),
                "note": (
                    f"TSP polygon {s['tsp_length_total']:.0f} m vs spiral "
                    f"{s['spiral_length_total']:.0f} m; "
                    f"max curvature {s['max_curvature']:.4f} ≤ {s['curvature_bound']:.4f} 1/m; "
                    f"max waypoint→τ {s['max_waypoint_distance']:.2f} ≤ δ = {s['delta']:g} m"
                ),
            },
            {
                "quantity": f"{label}: waypoint altitude min / mean / max [m]",
                "thesis": '"the lowest altitude"',
                "measured": (
                    f"{s['altitude_min']:.1f} / {s['altitude_mean']:.1f} / {s['altitude_max']:.1f}"
                ),
                "note": (
                    f"N = {s['n_waypoints']}; Z_max = {s['z_max']:.1f} m "
                    "(planning times in the JSON)"
                ),
            },
        ]
    summary.wall_time = time.perf_counter() - tic
    (out_dir / "ch7-summary.json").write_text(
        json.dumps({"lattice": summary.lattice, "plans": summary.plans}, indent=2, default=float)
    )
    return summary
