"""Figures of thesis Ch. 7 (Fig. 7.3, Fig. 7.4(a)–(d)) and an interactive 3D view over the terrain.

:func:`plot_fig7_4` draws the four panels of the thesis's Fig. 7.4 from a
:class:`uvnav.recon.plan.ReconPlan`: (a) the waypoints on a hillshade of the DEM with D's outline,
(b) their δ-neighbourhoods and camera footprints (the ground circle of radius
``(z_i − F(x_i, y_i))·tan(θ/2)`` — the cone on flat ground at the waypoint's height), (c) the UAVs'
closed trajectories, one colour each (scenario 1), (d) one UAV's integrated trajectory
(scenario 2).  :func:`recon_3d_html` writes a self-contained plotly page (terrain surface,
waypoints, trajectories) that works offline (plotly.js is embedded).

Figures use an explicit Agg canvas (no pyplot state), like :mod:`uvnav.viz.figures`.
"""

from __future__ import annotations

import math
import textwrap
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import PatchCollection
from matplotlib.colors import LightSource
from matplotlib.figure import Figure
from matplotlib.patches import Circle

if TYPE_CHECKING:
    from uvnav.recon.plan import ReconPlan
    from uvnav.recon.terrain import Terrain

_DPI = 120
_UAV_COLOURS = ("tab:red", "tab:blue", "tab:green", "tab:purple", "tab:orange", "tab:brown")


def hillshade(terrain: Terrain) -> np.ndarray:
    """RGB hillshade (ny, nx, 3) of the DEM (matplotlib ``LightSource``, sun at 315°/45°)."""
    ls = LightSource(azdeg=315, altdeg=45)
    from matplotlib import colormaps

    return np.asarray(
        ls.shade(
            terrain.z,
            cmap=colormaps["gist_earth"],
            vert_exag=1.0,
            dx=terrain.dx,
            dy=terrain.dy,
            blend_mode="soft",
        )
    )[..., :3]


def _background(ax: Axes, plan: ReconPlan, shade: np.ndarray) -> None:
    xmin, ymin, xmax, ymax = plan.terrain.bounds
    ax.imshow(shade, origin="lower", extent=(xmin, xmax, ymin, ymax), interpolation="bilinear")
    ring = np.asarray(plan.area.exterior.coords)
    ax.plot(ring[:, 0], ring[:, 1], color="k", lw=1.2, label="D")
    pad = plan.lattice.R * 1.5
    axmin, aymin, axmax, aymax = plan.area.bounds
    ax.set_xlim(max(xmin, axmin - pad), min(xmax, axmax + pad))
    ax.set_ylim(max(ymin, aymin - pad), min(ymax, aymax + pad))
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")


def plot_fig7_4(plan: ReconPlan, path: str | Path | None = None) -> Figure:
    """Fig. 7.4-like 2 x 2 figure (module doc); saved to ``path`` when given."""
    fig = Figure(figsize=(12, 11), dpi=_DPI, layout="constrained")
    FigureCanvasAgg(fig)
    axs = fig.subplots(2, 2)
    shade = hillshade(plan.terrain)
    W = plan.waypoints
    s = plan.summary()
    ax = axs[0, 0]
    _background(ax, plan, shade)
    sc = ax.scatter(W[:, 0], W[:, 1], c=W[:, 2], s=14, cmap="viridis", zorder=3)
    fig.colorbar(sc, ax=ax, label="waypoint altitude [m]", shrink=0.8)
    ax.set_title(
        f"(a) {plan.lattice.n} waypoints (naive lattice {plan.lattice.n_naive}, "
        f"Kershner {plan.lattice.bound_kershner:.1f}), R = {plan.lattice.R:g} m"
    )
    ax = axs[0, 1]
    _background(ax, plan, shade)
    ground = plan.terrain.height(W[:, 0], W[:, 1])
    rad = np.maximum(W[:, 2] - ground, 0.0) * math.tan(plan.config.theta / 2)
    ax.add_collection(
        PatchCollection(
            [Circle((x, y), r) for (x, y), r in zip(W[:, :2], rad, strict=True)],
            facecolor="none",
            edgecolor="magenta",
            lw=0.5,
            alpha=0.7,
        )
    )
    ax.add_collection(
        PatchCollection(
            [Circle((x, y), plan.config.delta) for x, y in W[:, :2]],
            facecolor="yellow",
            edgecolor="k",
            lw=0.4,
            alpha=0.9,
        )
    )
    ax.set_title(
        f"(b) δ = {plan.config.delta:g} m balls, footprints; coverage "
        f"{100 * s['coverage_grid_visible']:.2f} % ({s['check_grid_step']:g} m grid)"
    )
    ax = axs[1, 0]
    _background(ax, plan, shade)
    for k, u in enumerate(plan.uavs):
        pts = u.trajectory.sample(16)
        ax.plot(
            pts[:, 0],
            pts[:, 1],
            color=_UAV_COLOURS[k % len(_UAV_COLOURS)],
            lw=1.2,
            label=f"UAV {k + 1}: {u.check.length:.0f} m",
        )
        ax.plot(
            *W[u.indices[0], :2],
            marker="*",
            ms=12,
            color=_UAV_COLOURS[k % len(_UAV_COLOURS)],
            mec="k",
        )
    ax.scatter(W[:, 0], W[:, 1], s=5, c="k", zorder=3)
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title(f"(c) {len(plan.uavs)} UAV(s), one cluster each (scenario 1)")
    ax = axs[1, 1]
    _background(ax, plan, shade)
    one = plan.integrated if plan.integrated is not None else plan.uavs[0]
    pts = one.trajectory.sample(16)
    ax.plot(pts[:, 0], pts[:, 1], color="tab:red", lw=1.2, label=f"{one.check.length:.0f} m")
    ax.plot(*W[one.indices[0], :2], marker="*", ms=12, color="tab:red", mec="k")
    ax.scatter(W[:, 0], W[:, 1], s=5, c="k", zorder=3)
    ax.legend(loc="upper right", fontsize=8)
    ax.set_title("(d) one UAV, integrated tour (scenario 2)")
    fig.suptitle(
        textwrap.fill(
            f"Ch. 7 plan over {plan.terrain.source}: r_min = {plan.config.r_min:g} m, "
            f"max curvature {s['max_curvature']:.4f} ≤ {s['curvature_bound']:.4f} 1/m",
            width=150,
        ),
        fontsize=10,
    )
    if path is not None:
        out = Path(path)
        out.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(out, dpi=_DPI)
    return fig


def recon_3d_figure(plan: ReconPlan, *, max_grid: int = 160) -> Any:
    """Plotly 3D figure: terrain surface, waypoints, every trajectory."""
    try:
        import plotly.graph_objects as go
    except ImportError as exc:  # pragma: no cover - depends on the extra
        raise ImportError("the 3D view needs plotly: pip install 'uvnav[report]'") from exc
    t = plan.terrain
    sy = max(1, math.ceil(t.z.shape[0] / max_grid))
    sx = max(1, math.ceil(t.z.shape[1] / max_grid))
    fig = go.Figure()
    fig.add_trace(
        go.Surface(
            x=t.xs[::sx],
            y=t.ys[::sy],
            z=t.z[::sy, ::sx],
            colorscale="Earth",
            showscale=False,
            opacity=0.95,
            name="terrain",
        )
    )
    W = plan.waypoints
    fig.add_trace(
        go.Scatter3d(
            x=W[:, 0],
            y=W[:, 1],
            z=W[:, 2],
            mode="markers",
            marker={"size": 3, "color": "black"},
            name="waypoints",
        )
    )
    for k, u in enumerate(plan.uavs):
        p = u.trajectory.sample(12)
        fig.add_trace(
            go.Scatter3d(
                x=p[:, 0],
                y=p[:, 1],
                z=p[:, 2],
                mode="lines",
                line={"width": 4, "color": _UAV_COLOURS[k % len(_UAV_COLOURS)].replace("tab:", "")},
                name=f"UAV {k + 1}",
            )
        )
    if plan.integrated is not None:
        p = plan.integrated.trajectory.sample(12)
        fig.add_trace(
            go.Scatter3d(
                x=p[:, 0],
                y=p[:, 1],
                z=p[:, 2],
                mode="lines",
                line={"width": 3, "color": "orange"},
                name="integrated (one UAV)",
                visible="legendonly",
            )
        )
    fig.update_layout(
        title=f"Ch. 7 reconnaissance plan — {plan.lattice.n} waypoints, {len(plan.uavs)} UAV(s)",
        scene={
            "aspectmode": "data",
            "xaxis_title": "x [m]",
            "yaxis_title": "y [m]",
            "zaxis_title": "z [m]",
        },
        margin={"l": 0, "r": 0, "t": 40, "b": 0},
    )
    return fig


def recon_3d_html(plan: ReconPlan, path: str | Path) -> Path:
    """Write the 3D view as one self-contained HTML file (plotly.js embedded, works offline)."""
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    recon_3d_figure(plan).write_html(out, include_plotlyjs=True, full_html=True)
    return out


def render_plan(plan: ReconPlan, prefix: str | Path) -> list[Path]:
    """Fig. 7.4 PNG and the 3D HTML of one plan at ``<prefix>-fig7_4.png`` / ``<prefix>-3d.html``.

    The shape :func:`uvnav.experiments.ch7.reproduce_ch7` takes as ``render_plan``.
    """
    p = Path(prefix)
    png = p.parent / f"{p.name}-fig7_4.png"
    plot_fig7_4(plan, png)
    return [png, recon_3d_html(plan, p.parent / f"{p.name}-3d.html")]
