"""Figures of thesis Chapter 4 (Figs. 4.4, 4.7, 4.8, 4.9) from recorded Ch. 4 episodes.

* :func:`plot_approach` — Fig. 4.7: the obstacle's outline and the UUV at t = 0 ... 4 s.
* :func:`plot_decision` — Fig. 4.8: one avoidance decision in full: sonar returns, AMAPS r_imin,
  the forecast circle (4.11), both tangent points p+/p- and the chosen waypoint (4.13).
* :func:`plot_run` — Fig. 4.9: the whole trajectory (blue), r_imin(t) (green stars), the
  avoidance waypoints (blue stars), obstacle outlines over time (faded).
* :func:`plot_amaps` — Fig. 4.4(b): the AMAPS count map as a heat map with r_imin marks.
* :func:`save_animation` — the run as an animated GIF (matplotlib + Pillow), for the report.
* :func:`render_ch4` — all of them for the thesis scenes (the renderer ``uvnav run`` injects into
  :func:`uvnav.experiments.ch4.reproduce_ch4`).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from uvnav.sim.episode_uuv2d import Uuv2dTrajectory
from uvnav.sim.setup import EpisodeResult


def _closed(o: np.ndarray) -> np.ndarray:
    return np.vstack([o, o[:1]])


def _frame(ax: Axes, traj: Uuv2dTrajectory, goal: np.ndarray | None = None) -> None:
    start = traj.poses[0, :2]
    ax.plot(*start, "ko", ms=6)
    ax.annotate(
        "I", (float(start[0]), float(start[1])), textcoords="offset points", xytext=(5, -12)
    )
    if goal is not None:
        ax.plot(*goal, "k^", ms=7)
        ax.annotate(
            "E", (float(goal[0]), float(goal[1])), textcoords="offset points", xytext=(5, 5)
        )
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.grid(alpha=0.3)


def _index_at(traj: Uuv2dTrajectory, t: float) -> int:
    k = int(np.searchsorted(traj.decision_times, t - 1e-9))
    return min(k, len(traj.decision_times) - 1)


def plot_approach(
    traj: Uuv2dTrajectory, goal: np.ndarray, times: tuple[float, ...] = (0.0, 1.4, 2.8, 4.0)
) -> Figure:
    """Fig. 4.7: one panel per time: the obstacle outline, the path so far, the vehicle."""
    fig, axes = plt.subplots(2, 2, figsize=(9, 9))
    for ax, t in zip(axes.ravel(), times, strict=False):
        k = _index_at(traj, t)
        for o in traj.outlines[k]:
            ax.fill(*_closed(o).T, color="0.45", alpha=0.6)
        upto = traj.times <= traj.decision_times[k] + 1e-9
        ax.plot(*traj.poses[upto, :2].T, "b-")
        ax.plot(*traj.poses[upto][-1, :2], "bo")
        d = traj.decisions[k]
        if d is not None:
            ax.set_title(f"t = {traj.decision_times[k]:.1f} s, d_min = {d.d_min:.2f} m, {d.mode}")
        _frame(ax, traj, goal)
    fig.tight_layout()
    return fig


def first_avoidance(traj: Uuv2dTrajectory) -> int | None:
    """Index of the first decision in the avoiding strategy (with tangent points), if any."""
    for k, d in enumerate(traj.decisions):
        if d is not None and d.mode == "M2" and d.tangent_points is not None:
            return k
    return None


def plot_decision(traj: Uuv2dTrajectory, goal: np.ndarray, k: int | None = None) -> Figure:
    """Fig. 4.8: decision ``k`` (default: the first avoidance decision) in full."""
    if k is None:
        k = first_avoidance(traj)
    fig, ax = plt.subplots(figsize=(7, 7))
    if k is None:
        ax.set_title("no avoidance decision in this run")
        _frame(ax, traj, goal)
        return fig
    d = traj.decisions[k]
    pose = traj.poses[np.searchsorted(traj.times, traj.decision_times[k] - 1e-9)]
    for o in traj.outlines[k]:
        ax.fill(*_closed(o).T, color="0.55", alpha=0.6)
    ax.plot(*pose[:2], "bo", ms=7, label="UUV c(t)")
    ax.plot([pose[0], goal[0]], [pose[1], goal[1]], "k:", lw=1, label="line to E")
    if d.r_min is not None:
        ax.plot(*d.r_min, "g*", ms=14, label="r_imin(t) (AMAPS)")
        circle = plt.Circle(tuple(d.r_min), d.radius, fill=False, color="g", ls="--")
        ax.add_patch(circle)
    if d.tangent_points is not None:
        for p, name in zip(d.tangent_points, ("p+", "p-"), strict=True):
            ax.plot([pose[0], p[0]], [pose[1], p[1]], "c-", lw=1)
            ax.plot(*p, "cs", ms=6)
            ax.annotate(name, p, textcoords="offset points", xytext=(5, 5))
    if d.waypoint is not None:
        ax.plot(*d.waypoint, "b*", ms=14, label="c(t+1) (4.13)")
    ax.set_title(
        f"t = {d.time:.1f} s: tag {'+' if d.tag > 0 else '-'}, count = {d.count}, "
        f"forecast radius {d.radius:.2f} m"
    )
    lo = pose[:2] - 3.0
    hi = pose[:2] + 3.0
    _frame(ax, traj, goal)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.legend(loc="upper left", fontsize=8)
    return fig


def plot_run(traj: Uuv2dTrajectory, goal: np.ndarray, *, every: int = 10) -> Figure:
    """Fig. 4.9: the trajectory, r_imin(t) and the avoidance waypoints over the whole run."""
    fig, ax = plt.subplots(figsize=(7, 7))
    for k in range(0, len(traj.outlines), every):
        for o in traj.outlines[k]:
            ax.plot(*_closed(o).T, color="0.6", lw=0.6, alpha=0.5)
    for o in traj.outlines[-1]:
        ax.fill(*_closed(o).T, color="0.45", alpha=0.6)
    ax.plot(*traj.poses[:, :2].T, "b-", label="trajectory")
    rmin = np.array([d.r_min for d in traj.decisions if d is not None and d.r_min is not None])
    if len(rmin):
        ax.plot(*rmin.T, "g*", ms=5, label="r_imin(t)")
    way = np.array(
        [
            d.waypoint
            for d in traj.decisions
            if d is not None and d.mode == "M2" and d.waypoint is not None
        ]
    )
    if len(way):
        ax.plot(*way.T, "b*", ms=5, label="waypoints (avoiding)")
    _frame(ax, traj, goal)
    ax.legend(loc="upper left", fontsize=8)
    return fig


def plot_amaps(traj: Uuv2dTrajectory, goal: np.ndarray | None = None) -> Figure:
    """Fig. 4.4(b): the AMAPS counts (darker: covered more often) and the r_imin marks."""
    fig, ax = plt.subplots(figsize=(7, 6))
    grid = traj.grid
    if grid is None:
        ax.set_title("this law keeps no AMAPS grid")
        return fig
    counts = grid.counts
    h = grid.config.cell
    extent = (grid.x0, grid.x0 + grid.nx * h, grid.y0, grid.y0 + grid.ny * h)
    img = ax.imshow(
        np.ma.masked_less_equal(counts, 1e-3),
        origin="lower",
        extent=extent,
        cmap="Greys",
        interpolation="nearest",
    )
    fig.colorbar(img, ax=ax, label="coverage count")
    rmin = np.array([d.r_min for d in traj.decisions if d is not None and d.r_min is not None])
    if len(rmin):
        ax.plot(*rmin.T, "g*", ms=4, label="r_imin(t)")
    ax.plot(*traj.poses[:, :2].T, "b-", lw=1, label="trajectory")
    _frame(ax, traj, goal)
    ax.legend(loc="upper left", fontsize=8)
    ax.set_title(f"AMAPS, {h * 100:.0f} cm squares, after {grid.updates} sweeps")
    return fig


def save_animation(
    traj: Uuv2dTrajectory, goal: np.ndarray, path: Path, *, every: int = 2, fps: int = 10
) -> Path | None:
    """The run as an animated GIF; ``None`` when Pillow is not installed."""
    try:
        from matplotlib.animation import FuncAnimation, PillowWriter
    except ImportError:  # pragma: no cover
        return None
    fig, ax = plt.subplots(figsize=(6, 6))
    _frame(ax, traj, goal)
    allp = traj.poses[:, :2]
    pad = 1.5
    ax.set_xlim(min(allp[:, 0].min(), goal[0]) - pad, max(allp[:, 0].max(), goal[0]) + pad)
    ax.set_ylim(min(allp[:, 1].min(), goal[1]) - pad, max(allp[:, 1].max(), goal[1]) + pad)
    patches = [ax.fill(*_closed(o).T, color="0.45", alpha=0.6)[0] for o in traj.outlines[0]]
    (line,) = ax.plot([], [], "b-")
    (dot,) = ax.plot([], [], "bo")
    frames = list(range(0, len(traj.decision_times), every))

    def draw(k: int) -> list[Any]:
        for patch, o in zip(patches, traj.outlines[k], strict=True):
            patch.set_xy(_closed(o))
        upto = traj.times <= traj.decision_times[k] + 1e-9
        line.set_data(*traj.poses[upto, :2].T)
        dot.set_data([traj.poses[upto][-1, 0]], [traj.poses[upto][-1, 1]])
        ax.set_title(f"t = {traj.decision_times[k]:.1f} s ({traj.modes[k]})")
        return [*patches, line, dot]

    anim = FuncAnimation(fig, draw, frames=frames, blit=False)
    try:
        anim.save(str(path), writer=PillowWriter(fps=fps))
    except (ImportError, RuntimeError, ValueError):  # Pillow missing or unusable
        plt.close(fig)
        return None
    plt.close(fig)
    return path


def render_ch4(
    out_dir: Path,
    scene_results: Mapping[tuple[str, str], EpisodeResult[Uuv2dTrajectory]],
    summary: Any = None,
) -> list[Path]:
    """Figures for the Chapter-4 thesis scenes (the thesis's law), written under ``out_dir``."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    law = "zhang2022-uuv2d-v1"

    def save(fig: Figure, name: str) -> None:
        path = out_dir / name
        fig.savefig(path, dpi=90, bbox_inches="tight")
        plt.close(fig)
        written.append(path)

    for (scene, name), res in sorted(scene_results.items()):
        traj = res.trajectory
        if name != law or traj is None or len(traj.decision_times) == 0:
            continue
        goal = traj.goal
        if scene.endswith("fig4-7-approach"):
            save(plot_approach(traj, goal), "fig4-7-approach.png")
        elif scene.endswith("fig4-8-decision"):
            save(plot_decision(traj, goal), "fig4-8-decision.png")
            save(plot_amaps(traj, goal), "fig4-4b-amaps.png")
        elif scene.endswith("fig4-9-whole-run"):
            save(plot_run(traj, goal), "fig4-9-whole-run.png")
            gif = save_animation(traj, goal, out_dir / "fig4-9-whole-run.gif")
            if gif is not None:
                written.append(gif)
        else:
            save(plot_run(traj, goal), f"{scene}.png")
    return written
