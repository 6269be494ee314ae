"""Figures of the Chapter 3 reproduction (thesis Figs. 3.6-3.7 and more).

* :func:`trajectory_figure` — the 3D trajectory from two viewpoints (Fig. 3.6(a), (b)) with the
  obstacles drawn at a few times;
* :func:`obstacle_motion_figure` — the obstacle's v_obs(t), u_obs(t) components and norms
  (Fig. 3.7(a), (b)) with the bounds of (3.9)-(3.10);
* :func:`prediction_figure` — the law's predicted vs the true obstacle velocity;
* :func:`clearance_figure` — d_min(t), the clearance over time;
* :func:`interactive_trajectory` — the same trajectory as an interactive plotly page;
* :func:`render_ch3` — all of them for the recorded thesis-scene episodes (the renderer passed to
  :func:`uvnav.experiments.ch3.reproduce_ch3`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from uvnav.sim.episode3d import Trajectory3D


def _plt() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _obstacle_points(tr: Trajectory3D, k: int, i: int) -> np.ndarray:
    return np.asarray(tr.obstacle_outlines[i] @ tr.obstacle_rotations[k, i].T
                      + tr.obstacle_centres[k, i])  # fmt: skip


def trajectory_figure(tr: Trajectory3D, title: str = "") -> Any:
    """Fig. 3.6: trajectory (coloured by mode) from two viewpoints, obstacles at 4 times."""
    plt = _plt()
    fig = plt.figure(figsize=(11, 5))
    n = len(tr.time)
    snaps = np.linspace(0, n - 1, 4).astype(int)
    for col, (elev, azim) in enumerate(((25, -60), (70, 20))):
        ax = fig.add_subplot(1, 2, col + 1, projection="3d")
        p = tr.position
        m2 = tr.mode == "M2"
        ax.plot(p[:, 0], p[:, 1], p[:, 2], color="tab:blue", lw=1.2, label="robot (M1)")
        if m2.any():
            ax.scatter(p[m2, 0], p[m2, 1], p[m2, 2], color="tab:red", s=2, label="M2")
        ax.scatter(*p[0], color="k", marker="o", label="S")
        ax.scatter(*p[-1], color="g", marker="*", s=80, label="end")
        for i in range(tr.obstacle_centres.shape[1]):
            faces = tr.obstacle_faces[i]
            for j, k in enumerate(snaps):
                pts = _obstacle_points(tr, int(k), i)
                alpha = 0.15 + 0.2 * j / max(len(snaps) - 1, 1)
                if faces is not None:
                    ax.plot_trisurf(pts[:, 0], pts[:, 1], pts[:, 2], triangles=faces,
                                    color="tab:gray", alpha=alpha, linewidth=0)  # fmt: skip
                else:
                    ax.scatter(pts[:, 0], pts[:, 1], pts[:, 2], color="tab:gray", s=1,
                               alpha=alpha)  # fmt: skip
            c = tr.obstacle_centres[:, i]
            ax.plot(c[:, 0], c[:, 1], c[:, 2], color="tab:gray", ls="--", lw=0.8)
        ax.view_init(elev=elev, azim=azim)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
        ax.set_title(f"({'ab'[col]}) view elev {elev}, azim {azim}")
        if col == 0:
            ax.legend(loc="upper left", fontsize=7)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def obstacle_motion_figure(
    tr: Trajectory3D, obstacle: int = 0, v_max: float | None = None, u_max: float | None = None
) -> Any:
    """Fig. 3.7: components of v_obs(t) and u_obs(t) and their norms V_obs, U_obs."""
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    t = tr.time
    for ax, data, sym, bound in (
        (axes[0], tr.obstacle_velocity[:, obstacle], "v", v_max),
        (axes[1], tr.obstacle_rotation_rate[:, obstacle], "u", u_max),
    ):
        for j, comp in enumerate("xyz"):
            ax.plot(t, data[:, j], lw=1, label=f"{sym}_{comp}")
        ax.plot(t, np.linalg.norm(data, axis=1), "k", lw=1.5, label=f"{sym.upper()}_obs")
        if bound is not None:
            ax.axhline(bound, color="r", ls=":", label="robot limit (3.9)/(3.10)")
        ax.set_xlabel("time t [s]")
        ax.legend(fontsize=7)
    axes[0].set_ylabel("[m/s]")
    axes[0].set_title("(a) obstacle velocity v_obs(t)")
    axes[1].set_ylabel("[rad/s]")
    axes[1].set_title("(b) obstacle rotation u_obs(t)")
    fig.tight_layout()
    return fig


def prediction_figure(tr: Trajectory3D, obstacle: int = 0) -> Any:
    """Predicted (by the law, when it predicted) vs true velocity components of an obstacle."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4))
    t = tr.time
    for j, comp in enumerate("xyz"):
        line = ax.plot(t, tr.obstacle_velocity[:, obstacle, j], lw=1, label=f"true v_{comp}")
        ax.plot(t, tr.predicted_velocity[:, obstacle, j], ".", ms=2,
                color=line[0].get_color(), label=f"predicted v_{comp}")  # fmt: skip
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("[m/s]")
    ax.set_title(f"obstacle {obstacle}: predicted vs true velocity")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    return fig


def clearance_figure(tr: Trajectory3D) -> Any:
    """d_min(t): clearance between the robot's sphere and the nearest obstacle."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.plot(tr.time, tr.clearance, lw=1.2)
    ax.axhline(0.0, color="r", ls=":")
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("clearance [m]")
    ax.set_title(f"d_min(t), minimum {np.min(tr.clearance):.2f} m")
    fig.tight_layout()
    return fig


def interactive_trajectory(tr: Trajectory3D, title: str = "", plotly_js: bool | str = True) -> str:
    """HTML (plotly) of the trajectory and the obstacles' paths.

    Args:
        tr: the recorded episode.
        title: page title.
        plotly_js: ``True`` embeds plotly.js (a standalone page, about 3.5 MB); a relative path
            loads it from there instead (the report shares one copy).

    Raises:
        ImportError: plotly missing (install the ``report`` extra).
    """
    try:
        import plotly.graph_objects as go
    except ImportError as exc:  # pragma: no cover
        raise ImportError("interactive figures need plotly: pip install 'uvnav[report]'") from exc
    p = tr.position
    data = [go.Scatter3d(x=p[:, 0], y=p[:, 1], z=p[:, 2], mode="lines", name="robot")]
    for i in range(tr.obstacle_centres.shape[1]):
        c = tr.obstacle_centres[:, i]
        data.append(go.Scatter3d(x=c[:, 0], y=c[:, 1], z=c[:, 2], mode="lines",
                                 name=f"obstacle {i} centre", line={"dash": "dash"}))  # fmt: skip
        faces = tr.obstacle_faces[i]
        if faces is not None:
            pts = _obstacle_points(tr, len(tr.time) // 2, i)
            data.append(go.Mesh3d(x=pts[:, 0], y=pts[:, 1], z=pts[:, 2], i=faces[:, 0],
                                  j=faces[:, 1], k=faces[:, 2], opacity=0.4,
                                  name=f"obstacle {i} (mid-episode)"))  # fmt: skip
    fig = go.Figure(data=data)
    fig.update_layout(title=title, scene={"aspectmode": "data"})
    return str(fig.to_html(include_plotlyjs=plotly_js, full_html=True))


def render_ch3(db_path: Path, report_dir: Path, recorded: list[tuple[str, str, Any]]) -> list[Path]:
    """Write the Chapter 3 figures of every recorded thesis-scene episode into
    ``report_dir/ch3`` (PNG; and one interactive HTML per scene for the thesis's law)."""
    plt = _plt()
    out = Path(report_dir) / "ch3"
    out.mkdir(parents=True, exist_ok=True)
    files: list[Path] = []
    for scene, ctrl, tr in recorded:
        if tr is None:
            continue
        stem = f"{scene}--{ctrl}"
        figs = {"trajectory": trajectory_figure(tr, f"{scene}: {ctrl}"),
                "clearance": clearance_figure(tr)}  # fmt: skip
        if ctrl.startswith("zhang2020"):
            figs["obstacle-motion"] = obstacle_motion_figure(tr)
            figs["prediction"] = prediction_figure(tr)
            try:
                from uvnav.viz.interactive import PLOTLY_JS, write_plotly_js

                write_plotly_js(Path(report_dir))  # one shared copy next to index.html
                html = out / f"{stem}.html"
                page = interactive_trajectory(tr, f"{scene}: {ctrl}", plotly_js=f"../{PLOTLY_JS}")
                html.write_text(page, encoding="utf-8")
                files.append(html)
            except ImportError:
                pass
        for kind, fig in figs.items():
            path = out / f"{stem}--{kind}.png"
            fig.savefig(path, dpi=110)
            plt.close(fig)
            files.append(path)
    return files
