"""``uvnav recon``: plan UAV reconnaissance over terrain (thesis Ch. 7), write plans and figures.

``uvnav recon plan [--dem FILE | --synthetic SEED | --jacksboro] --area SPEC --theta DEG
--radius R --uavs K --out DIR`` writes into DIR:

* ``waypoints.csv`` / ``waypoints.geojson`` — id, x, y, z [m], cluster, visiting rank per UAV;
* ``trajectory.csv`` / ``trajectory.geojson`` — τ sampled (uav, x, y, z [m]) per UAV, and the
  integrated single-UAV tour as ``uav = 0`` when there are several UAVs;
* ``plan.json`` — every measured figure (counts, bounds, coverage, lengths, curvature, timings);
* ``fig7_4.png`` and ``recon_3d.html`` (unless ``--no-figures``).

GeoJSON coordinates are the DEM's local metric frame (x east, y north [m]), not WGS84; the file
says so in a ``crs`` note.  Bad input: one line ``error: <source>: <field>: <problem>``, exit 2.
"""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path
from typing import Annotated, Any

import numpy as np
import typer

from uvnav.cli.checks import dumps, finite
from uvnav.cli.errors import CliError, uvnav_typer

recon_app = uvnav_typer(
    help="UAV reconnaissance over terrain (thesis Ch. 7): lattice waypoints, smooth tours.",
)


def _positive(value: float | None) -> float | None:
    """Option callback: a finite number > 0 (or ``None``: not given)."""
    if value is not None and not (math.isfinite(value) and value > 0):
        raise typer.BadParameter(f"{value:g} is not a finite number > 0")
    return value


#: ReconConfig field -> the option that sets it (its errors name the option)
_OPTION_OF = {
    "theta": "--theta",
    "radius": "--radius",
    "footprint_radius": "--radius",
    "uavs": "--uavs",
    "delta": "--delta",
    "c1": "--c1",
    "c2": "--c2",
    "r_min": "--r-min",
    "z_min": "--z-min",
    "z_max": "--z-max",
    "seed": "--seed",
}


def _name_option(msg: str) -> str:
    """``"radius: must be > 0"`` -> ``"--radius: must be > 0"`` (the option the user typed)."""
    field, sep, rest = msg.partition(":")
    if sep and field.strip() in _OPTION_OF:
        opt = _OPTION_OF[field.strip()]
        if "z_max" in rest and opt == "--z-min":
            opt = "--z-min/--z-max"
        return f"{opt}:{rest}"
    return msg


def parse_area(spec: str, bounds: tuple[float, float, float, float]) -> Any:
    """``"SIDE"`` (a square centred in the DEM) or ``"X0,Y0,X1,Y1"`` (a box) [m] → polygon."""
    from shapely.geometry import box

    from uvnav.recon.terrain import square_area

    vals = _area_numbers(spec)
    if len(vals) == 1:
        cx = 0.5 * (bounds[0] + bounds[2])
        cy = 0.5 * (bounds[1] + bounds[3])
        return square_area(vals[0], center=(cx, cy))
    if len(vals) == 4 and vals[2] > vals[0] and vals[3] > vals[1]:
        return box(*vals)
    raise ValueError(f"--area: expected SIDE or X0,Y0,X1,Y1 with X1 > X0 and Y1 > Y0, got {spec!r}")


def write_plan_files(plan: Any, out: Path) -> list[Path]:
    """Write the CSV/GeoJSON/JSON plan files of the module doc; returns their paths."""
    out.mkdir(parents=True, exist_ok=True)
    W = plan.waypoints
    rank = np.full((len(W), len(plan.uavs)), -1)
    for k, u in enumerate(plan.uavs):
        rank[u.indices, k] = np.arange(len(u.indices))
    files = []
    p = out / "waypoints.csv"
    with p.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["id", "x", "y", "z", "cluster", "rank"])
        for i, (x, y, z) in enumerate(W):
            w.writerow(
                [i, f"{x:.3f}", f"{y:.3f}", f"{z:.3f}", int(plan.labels[i]), int(rank[i].max())]
            )
    files.append(p)
    crs_note = {
        "type": "name",
        "properties": {"name": "local metric frame of the DEM (x east, y north) [m]"},
    }
    feats = [
        {
            "type": "Feature",
            "geometry": {"type": "Point", "coordinates": [float(x), float(y), float(z)]},
            "properties": {"id": i, "cluster": int(plan.labels[i]), "rank": int(rank[i].max())},
        }
        for i, (x, y, z) in enumerate(W)
    ]
    p = out / "waypoints.geojson"
    p.write_text(json.dumps({"type": "FeatureCollection", "crs": crs_note, "features": feats}))
    files.append(p)
    tracks = [(k + 1, u) for k, u in enumerate(plan.uavs)]
    if plan.integrated is not None:
        tracks.append((0, plan.integrated))
    p = out / "trajectory.csv"
    lines = []
    with p.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["uav", "x", "y", "z"])
        for k, u in tracks:
            pts = u.trajectory.sample(16)
            lines.append(
                {
                    "type": "Feature",
                    "geometry": {"type": "LineString", "coordinates": np.round(pts, 3).tolist()},
                    "properties": {"uav": k, "length_m": u.check.length},
                }
            )
            for x, y, z in pts:
                w.writerow([k, f"{x:.3f}", f"{y:.3f}", f"{z:.3f}"])
    files.append(p)
    p = out / "trajectory.geojson"
    p.write_text(json.dumps({"type": "FeatureCollection", "crs": crs_note, "features": lines}))
    files.append(p)
    p = out / "plan.json"
    summary = plan.summary()
    summary["terrain"] = plan.terrain.source
    p.write_text(json.dumps(summary, indent=2, default=float))
    files.append(p)
    return files


@recon_app.command("plan")
def plan_cmd(
    out: Annotated[Path, typer.Option("--out", help="Output folder.")],
    dem: Annotated[
        Path | None, typer.Option("--dem", help="DEM file: .tif (metric CRS), .npy or .npz.")
    ] = None,
    synthetic: Annotated[
        int | None,
        typer.Option(
            "--synthetic", min=0, help="Generated fractal + urban terrain with this seed."
        ),
    ] = None,
    jacksboro: Annotated[
        bool,
        typer.Option(
            "--jacksboro",
            help="The USGS Jacksboro DEM shipped with matplotlib (cropped, scaled 1/6).",
        ),
    ] = False,
    area: Annotated[
        str, typer.Option("--area", help="SIDE (square centred in the DEM) or X0,Y0,X1,Y1 [m].")
    ] = "300",
    theta: Annotated[
        float,
        typer.Option("--theta", callback=finite, help="Camera cone full angle [deg], in (0, 180)."),
    ] = 90.0,
    radius: Annotated[
        float,
        typer.Option("--radius", callback=_positive, help="Footprint radius R [m] of the lattice."),
    ] = 30.0,
    uavs: Annotated[int, typer.Option("--uavs", min=1, help="Number of UAVs (clusters).")] = 2,
    z_min: Annotated[
        float | None,
        typer.Option("--z-min", callback=finite, help="Lowest altitude [m] (default 0)."),
    ] = None,
    z_max: Annotated[
        float | None,
        typer.Option("--z-max", callback=finite, help="Highest altitude [m] (default: auto)."),
    ] = None,
    delta: Annotated[float, typer.Option("--delta", callback=_positive, help="δ [m].")] = 5.0,
    c1: Annotated[
        float, typer.Option("--c1", callback=finite, help="Waypoint-waypoint margin [m] (7.4).")
    ] = 15.0,
    c2: Annotated[
        float, typer.Option("--c2", callback=finite, help="Waypoint-terrain margin [m] (7.4).")
    ] = 10.0,
    r_min: Annotated[
        float, typer.Option("--r-min", callback=_positive, help="UAV turning radius [m].")
    ] = 15.0,
    cell: Annotated[
        float,
        typer.Option(
            "--cell",
            callback=_positive,
            help="Node spacing [m] of .npy DEMs and synthetic terrain.",
        ),
    ] = 5.0,
    seed: Annotated[
        int, typer.Option("--seed", min=0, max=2**32 - 1, help="Seed of the k-means clustering.")
    ] = 0,
    figures: Annotated[
        bool, typer.Option("--figures/--no-figures", help="Write fig7_4.png and recon_3d.html.")
    ] = True,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print one JSON object instead of the table.")
    ] = False,
) -> None:
    """Plan minimum lattice waypoints at the lowest altitude and smooth closed tours (Ch. 7)."""
    from uvnav.recon.plan import ReconConfig, plan_recon
    from uvnav.recon.terrain import (
        MAX_TERRAIN_NODES,
        fractal_terrain,
        load_dem,
        load_jacksboro,
        terrain_nodes,
    )

    if out.exists() and not out.is_dir():
        raise CliError(f"{out}: --out: exists and is not a folder (the plan is several files)")
    chosen = sum([dem is not None, synthetic is not None, jacksboro])
    if chosen > 1:
        raise CliError("recon plan: --dem, --synthetic and --jacksboro are exclusive; give one")
    source = str(dem) if dem is not None else "recon plan"
    try:
        if dem is not None:
            if not dem.is_file():
                raise CliError(f"{dem}: --dem: file not found")
            terrain = load_dem(dem, cell=cell)
        elif jacksboro:
            terrain = load_jacksboro()
        else:
            x0, y0, w, h = _area_box(area)
            pad = 2.0 * radius + 50.0
            size = (w + 2 * pad, h + 2 * pad)
            nodes = terrain_nodes(size, cell)
            if nodes > MAX_TERRAIN_NODES:
                raise CliError(
                    f"--area/--cell: a {size[0]:g} m x {size[1]:g} m terrain (the area plus "
                    f"margins) at --cell {cell:g} m is {nodes:.3g} nodes, more than the limit of "
                    f"{MAX_TERRAIN_NODES:.0e} (uvnav.recon.terrain.MAX_TERRAIN_NODES: raise it "
                    "in Python for a larger run); use a smaller --area or a larger --cell"
                )
            terrain = fractal_terrain(
                (w + 2 * pad, h + 2 * pad),
                cell=cell,
                seed=0 if synthetic is None else synthetic,
                origin=(x0 - pad, y0 - pad),
                n_blocks=int(w * h / 6000),
            )
        D = parse_area(area, terrain.bounds)
        cfg = ReconConfig(
            theta=math.radians(theta),
            footprint_radius=radius,
            z_min=z_min,
            z_max=z_max,
            delta=delta,
            c1=c1,
            c2=c2,
            r_min=r_min,
            uavs=uavs,
            seed=seed,
        )
        plan = plan_recon(terrain, D, cfg)
    except ValueError as exc:
        msg = _name_option(str(exc))
        if msg.startswith("--theta"):
            msg = f"--theta: must be in (0, 180) degrees, got {theta:g}"
        named = msg.startswith(("--", f"{source}: "))  # an option's, or the DEM reader's line
        raise CliError(msg if named else f"{source}: {msg}") from None
    files = write_plan_files(plan, out)
    if figures:
        from uvnav.viz.figures_ch7 import plot_fig7_4, recon_3d_html

        files.append(out / "fig7_4.png")
        plot_fig7_4(plan, files[-1])
        files.append(recon_3d_html(plan, out / "recon_3d.html"))
    s = plan.summary()
    if as_json:
        typer.echo(dumps(s, default=float))  # strict JSON: a missing value is null
        return
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"Ch. 7 plan over {terrain.source}")
    table.add_column("quantity")
    table.add_column("value", justify="right")
    rows = [
        ("waypoints N (naive lattice)", f"{s['n_waypoints']} ({s['n_naive']})"),
        ("bounds A/(πR²), Kershner", f"{s['bound_disc']:.1f}, {s['bound_kershner']:.1f}"),
        (
            "altitude min / mean / max [m]",
            f"{s['altitude_min']:.1f} / {s['altitude_mean']:.1f} / {s['altitude_max']:.1f}",
        ),
        (
            f"coverage, {s['check_grid_step']:g} m grid (visible at Z_max / all)",
            f"{100 * s['coverage_grid_visible']:.2f} % / {100 * s['coverage_grid_all']:.2f} %",
        ),
        (
            "ground outside every footprint [m²]",
            f"{s['polygon_uncovered_m2']:.2f}",
        ),
        (
            "TSP / spiral tour length [m]",
            f"{s['tsp_length_total']:.0f} / {s['spiral_length_total']:.0f}",
        ),
        ("trajectory length per UAV [m]", ", ".join(f"{v:.0f}" for v in s["trajectory_lengths"])),
        ("max waypoint→τ distance [m] (δ)", f"{s['max_waypoint_distance']:.2f} ({s['delta']:g})"),
        ("max curvature [1/m] (bound)", f"{s['max_curvature']:.4f} ({s['curvature_bound']:.4f})"),
        ("min clearance above terrain [m]", f"{s['min_clearance']:.1f}"),
        ("planning time [s]", f"{s['planning_time_s']:.1f}"),
    ]
    from rich.markup import escape

    for r in rows:
        table.add_row(escape(r[0]), r[1])
    console = Console()
    console.print(table)
    console.print(f"wrote {len(files)} files to {out}")


def _area_box(spec: str) -> tuple[float, float, float, float]:
    """(x0, y0, width, height) [m] of the area spec for sizing generated terrain."""
    vals = _area_numbers(spec)
    if len(vals) == 1:
        if vals[0] <= 0:
            raise ValueError(f"--area: side must be positive, got {vals[0]:g}")
        return 0.0, 0.0, vals[0], vals[0]
    if len(vals) == 4 and vals[2] > vals[0] and vals[3] > vals[1]:
        return vals[0], vals[1], vals[2] - vals[0], vals[3] - vals[1]
    raise ValueError(f"--area: expected SIDE or X0,Y0,X1,Y1 with X1 > X0 and Y1 > Y0, got {spec!r}")


def _area_numbers(spec: str) -> list[float]:
    """The finite numbers of an ``--area`` spec (one side, or a box X0,Y0,X1,Y1) [m]."""
    try:
        vals = [float(p.strip()) for p in spec.split(",")]
    except ValueError:
        raise ValueError(f"--area: expected SIDE or X0,Y0,X1,Y1 in metres, got {spec!r}") from None
    if not all(math.isfinite(v) for v in vals):
        raise ValueError(f"--area: expected finite numbers in metres, got {spec!r}")
    if len(vals) == 1 and vals[0] <= 0:
        raise ValueError(f"--area: side must be positive, got {vals[0]:g}")
    return vals
