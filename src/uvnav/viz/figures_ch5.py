"""Chapter 5 figures: the sonar array (Fig. 5.2), training curves, error histograms and
target-vs-output regressions (Figs. 5.5-5.8), the learning curve, 3D trajectories (Fig. 5.3) and
an animated GIF of a whole 3D run (:func:`save_animation3d`: vehicle, deforming obstacles at each
decision time, the located point to evade).

Thesis Chapter 5 (Y. Zhang and J. Zhang, ICCAE 2022).  Pure plotting of what the library measured
(matplotlib, Agg backend); nothing here computes a result.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.figure import Figure

from uvnav.experiments.ch5_bpnn import VARIANT_LABELS, split_model_key
from uvnav.geometry.angles import FloatArray
from uvnav.learning.bpnn import TrainedBPNN
from uvnav.obstacles.deforming3d import CompoundBody
from uvnav.sensors.sonar_array import SonarArray
from uvnav.sim.episode_uuv3d import LocatedTrace
from uvnav.sim.setup import EpisodeResult


def fig_array(array: SonarArray, *, beam_length: float = 2.0) -> Figure:
    """The nine sensors on the front cap and their beam axes and cone rims (front and side)."""
    fig = plt.figure(figsize=(10, 4.5))
    s, n = array.placement(np.zeros(3), np.array([1.0, 0.0, 0.0]))
    th = np.linspace(0, 2 * np.pi, 40)
    for k, (view, title) in enumerate((((0, 0), "front view (a)"), ((0, -90), "side view (b)"))):
        ax: Any = fig.add_subplot(1, 2, k + 1, projection="3d")
        u, v = np.mgrid[-np.pi / 2 : np.pi / 2 : 20j, 0 : np.pi : 20j]
        r = array.hull_radius
        ax.plot_wireframe(
            r * np.cos(u) * np.sin(v),
            r * np.sin(u) * np.sin(v),
            r * np.cos(v),
            color="0.8",
            linewidth=0.4,
        )
        for i in range(9):
            ax.scatter(*s[i], color="C3", s=20)
            ax.text(*(s[i] + 0.08 * n[i]), f"S{i + 1}", fontsize=8)
            e1 = np.cross(n[i], [0.0, 0.0, 1.0] if abs(n[i][2]) < 0.9 else [1.0, 0.0, 0.0])
            e1 /= np.linalg.norm(e1)
            e2 = np.cross(n[i], e1)
            rad = beam_length * np.tan(array.half_angle)
            rim = (
                s[i]
                + beam_length * n[i]
                + rad * (np.outer(np.cos(th), e1) + np.outer(np.sin(th), e2))
            )
            ax.plot(*rim.T, color=f"C{i % 10}", linewidth=0.6)
            ax.plot(*np.stack([s[i], s[i] + beam_length * n[i]]).T, color=f"C{i % 10}", lw=0.8)
        ax.view_init(elev=view[0], azim=view[1] + (180 if k == 0 else 0))
        ax.set_title(title)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_zlabel("z [m]")
    fig.suptitle("Nine-sonar array on the front cap (thesis Fig. 5.2)")
    return fig


def fig_training(model: TrainedBPNN, title: str = "") -> Figure:
    """Training and validation MSE (scaled units) per epoch, with the kept (best) epoch."""
    fig, ax = plt.subplots(figsize=(6, 4))
    ep = np.arange(1, len(model.history["train"]) + 1)
    ax.semilogy(ep, model.history["train"], label="training")
    ax.semilogy(ep, model.history["val"], label="validation")
    ax.axvline(model.best_epoch, color="k", ls="--", lw=0.8, label=f"best epoch {model.best_epoch}")
    ax.set_xlabel("epoch")
    ax.set_ylabel("MSE (scaled outputs)")
    ax.set_title(title or f"BPNN training ({model.stop_reason})")
    ax.legend()
    return fig


def fig_errors(
    predicted: FloatArray, targets: FloatArray, baseline: FloatArray | None, title: str
) -> Figure:
    """Error histograms (a) and target-vs-output regressions (b), distance and sensor index, like
    thesis Figs. 5.5-5.8; the min/argmin baseline in grey."""
    fig, axes = plt.subplots(2, 2, figsize=(10, 8))
    names = ("minimum distance [m]", "sensor number")
    for j in range(2):
        err = targets[:, j] - predicted[:, j]
        ax = axes[0, j]
        ax.hist(err, bins=20, color="C0", alpha=0.8, label="network")
        if baseline is not None:
            ax.hist(
                targets[:, j] - baseline[:, j], bins=20, color="0.5", alpha=0.5, label="min/argmin"
            )
        ax.set_title(
            f"(a) error = target - output, {names[j]}\nrange [{err.min():.3g}, {err.max():.3g}]"
        )
        ax.legend()
        ax = axes[1, j]
        ax.scatter(targets[:, j], predicted[:, j], s=8, label="network")
        if baseline is not None:
            ax.scatter(targets[:, j], baseline[:, j], s=6, color="0.6", label="min/argmin")
        lo, hi = float(targets[:, j].min()), float(targets[:, j].max())
        ax.plot([lo, hi], [lo, hi], "k--", lw=0.8)
        r = np.corrcoef(targets[:, j], predicted[:, j])[0, 1] if len(targets) > 1 else np.nan
        ax.set_title(f"(b) output vs target, {names[j]} (R = {r:.4f})")
        ax.set_xlabel("target")
        ax.set_ylabel("output")
        ax.legend()
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def fig_learning_curve(rows: Sequence[dict[str, Any]]) -> Figure:
    """Median MAE on the independent test set vs sample count, network (plain thesis-style and
    residual) and baseline, for the true-geometry targets (the literal experiment's rows, trained
    on min/argmin of the inputs, are another task and stay in the table)."""
    rows = [r for r in rows if r.get("targets", "geometry") == "geometry"]
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for j, out in enumerate(("distance", "index")):
        for variant, style in zip(VARIANT_LABELS, ("o-", "^-", "D-", "v-"), strict=True):
            vr = [r for r in rows if r.get("variant", "plain") == variant]
            sizes_v = sorted({int(r["samples"]) for r in vr})
            if not sizes_v:
                continue
            med_v = [
                np.median(
                    [r["independent"]["network"][out]["mae"] for r in vr if int(r["samples"]) == n]
                )
                for n in sizes_v
            ]
            axes[j].loglog(sizes_v, med_v, style, label=f"network ({variant})")
        sizes = sorted({int(r["samples"]) for r in rows})
        for who, style in (("baseline", "s--"),):
            med = [
                np.median(
                    [r["independent"][who][out]["mae"] for r in rows if int(r["samples"]) == n]
                )
                for n in sizes
            ]
            axes[j].loglog(sizes, med, style, label=who if who == "network" else "min/argmin")
        axes[j].set_xlabel("training samples")
        axes[j].set_ylabel(f"{out} MAE (independent test)")
        axes[j].legend()
    fig.suptitle("Learning curve of the BPNN")
    fig.tight_layout()
    return fig


def fig_trajectory3d(
    trace: LocatedTrace, obstacles: Sequence[CompoundBody], goal: FloatArray, title: str
) -> Figure:
    """Vehicle path (coloured by mode), located points, and the obstacles' meshes at t = 0."""
    fig = plt.figure(figsize=(7, 6))
    ax: Any = fig.add_subplot(projection="3d")
    for ob in obstacles:
        for part in ob.parts:
            v = part.vertices(0.0)
            ax.plot_trisurf(
                v[:, 0], v[:, 1], v[:, 2], triangles=part.faces, color="C1", alpha=0.25, linewidth=0
            )
    pos = np.asarray(trace.positions)
    if len(pos):
        ax.plot(*pos.T, color="C0", lw=1.5, label="vehicle")
        m2 = np.array([m == "M2" for m in trace.modes])
        if m2.any():
            ax.scatter(*pos[m2].T, color="C3", s=4, label="avoidance (M2)")
        loc = np.asarray(trace.located)
        ok = np.all(np.isfinite(loc), axis=1) if len(loc) else np.zeros(0, bool)
        if ok.any():
            ax.scatter(*loc[ok].T, color="k", s=3, label="point to evade")
        ax.scatter(*pos[0], color="g", s=30, label="A")
    ax.scatter(*goal, color="m", s=40, marker="*", label="B")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_zlabel("z [m]")
    ax.set_title(title)
    ax.legend(loc="upper left", fontsize=8)
    return fig


def _sphere(centre: FloatArray, radius: float, n: int = 10) -> tuple[Any, Any, Any]:
    u, v = np.mgrid[0 : 2 * np.pi : complex(0, n), 0 : np.pi : complex(0, n // 2 + 1)]
    return (
        centre[0] + radius * np.cos(u) * np.sin(v),
        centre[1] + radius * np.sin(u) * np.sin(v),
        centre[2] + radius * np.cos(v),
    )


def animation_frames(n_decisions: int, max_frames: int) -> list[int]:
    """Decision indices shown by :func:`save_animation3d`: evenly spread, first and last kept,
    at most ``max_frames`` (>= 2) of them."""
    if n_decisions <= 0:
        return []
    k = min(n_decisions, max(2, int(max_frames)))
    return sorted({round(float(x)) for x in np.linspace(0, n_decisions - 1, k)})


def save_animation3d(
    trace: LocatedTrace,
    obstacles: Sequence[CompoundBody],
    goal: FloatArray,
    path: Path,
    *,
    radius: float = 0.5,
    title: str = "",
    max_frames: int = 24,
    fps: int = 4,
    close_up: float = 5.0,
    dpi: int = 70,
) -> Path | None:
    """A recorded 3D run as an animated GIF (matplotlib + Pillow): left, the whole scene (path so
    far, obstacles at that time, A and B); right, a close-up box of half-side ``close_up`` [m]
    around the vehicle (hull sphere of ``radius`` [m]) where the surfaces' deformation and the
    located point to evade (black cross, joined to the vehicle) are visible.  The obstacles are
    redrawn at each frame's decision time.  ``None`` when Pillow is not installed or the run was
    not recorded.
    """
    try:
        from matplotlib.animation import FuncAnimation, PillowWriter
    except ImportError:  # pragma: no cover
        return None
    pos = np.asarray(trace.positions, dtype=float)
    frames = animation_frames(len(trace.times), max_frames)
    if len(frames) < 2:
        return None
    loc = np.asarray(trace.located, dtype=float)
    goal = np.asarray(goal, dtype=float)
    pts = [pos, goal[None]]
    for ob in obstacles:
        pts += [p.vertices(0.0) for p in ob.parts]
    allp = np.concatenate(pts)
    lo, hi = allp.min(axis=0) - 1.0, allp.max(axis=0) + 1.0
    fig = plt.figure(figsize=(10, 4.8))
    ax_all: Any = fig.add_subplot(1, 2, 1, projection="3d")
    ax_zoom: Any = fig.add_subplot(1, 2, 2, projection="3d")
    fig.subplots_adjust(left=0.0, right=1.0, bottom=0.0, top=0.88, wspace=0.0)
    ax_all.set_xlim(lo[0], hi[0])
    ax_all.set_ylim(lo[1], hi[1])
    ax_all.set_zlim(lo[2], hi[2])
    ax_all.set_box_aspect(tuple(hi - lo), zoom=1.05)
    size = "x".join(f"{x:.0f}" for x in hi - lo)
    ax_all.set_title(f"whole scene ({size} m box)", fontsize=9)
    ax_zoom.set_box_aspect((1, 1, 1), zoom=1.2)
    ax_zoom.set_title(f"close-up ({2 * close_up:.0f} m box); x: located point", fontsize=9)
    # static and updated artists; axes off: tick text would dominate the drawing time
    lines: list[Any] = []
    marks: list[Any] = []
    links: list[Any] = []
    moving: list[Any] = []
    for ax in (ax_all, ax_zoom):
        ax.set_axis_off()
        ax.scatter(*pos[0], color="g", s=25)
        ax.scatter(*goal, color="m", s=60, marker="*")
        lines.append(ax.plot([], [], [], color="C0", lw=1.4)[0])
        marks.append(ax.plot([], [], [], "kx", ms=7)[0])
        links.append(ax.plot([], [], [], "k:", lw=1)[0])
    alphas = (0.35, 0.5)

    def draw(i: int) -> list[Any]:
        k = frames[i]
        t = float(trace.times[k])
        c = pos[k]
        while moving:
            moving.pop().remove()
        ax_zoom.set_xlim(c[0] - close_up, c[0] + close_up)
        ax_zoom.set_ylim(c[1] - close_up, c[1] + close_up)
        ax_zoom.set_zlim(c[2] - close_up, c[2] + close_up)
        seen = k < len(loc) and bool(np.all(np.isfinite(loc[k])))
        for j, ax in enumerate((ax_all, ax_zoom)):
            for ob in obstacles:
                for part in ob.parts:
                    v = part.vertices(t)
                    moving.append(
                        ax.plot_trisurf(
                            *v.T, triangles=part.faces, color="C1", alpha=alphas[j], linewidth=0
                        )
                    )
            moving.append(ax.plot_surface(*_sphere(c, radius), color="C0", linewidth=0))
            lines[j].set_data_3d(*pos[: k + 1].T)
            pts = np.stack([c, loc[k]]) if seen else np.zeros((0, 3))
            marks[j].set_data_3d(*pts[1:].T)
            links[j].set_data_3d(*pts.T)
        mode = trace.modes[k] if k < len(trace.modes) else ""
        fig.suptitle(f"{title}  t = {t:.1f} s  ({mode})", fontsize=10)
        return []

    anim = FuncAnimation(fig, draw, frames=len(frames), blit=False)
    try:
        anim.save(str(path), writer=PillowWriter(fps=fps), dpi=dpi)
    except (ImportError, RuntimeError, ValueError):  # Pillow missing or unusable
        plt.close(fig)
        return None
    plt.close(fig)
    return Path(path)


def render_ch5(summary: Any, report_dir: Path) -> list[Path]:
    """All Chapter 5 figures of a :class:`~uvnav.experiments.ch5.Ch5Summary` as PNG files in
    ``report_dir/ch5``."""
    from uvnav.scenarios.ch5 import build_uuv3d, load_ch5_scenario

    out = Path(report_dir) / "ch5"
    out.mkdir(parents=True, exist_ok=True)
    files: list[Path] = []

    def save(fig: Figure, name: str) -> None:
        p = out / name
        fig.savefig(p, dpi=110)
        plt.close(fig)
        files.append(p)

    save(fig_array(SonarArray()), "ch5_array.png")
    for key, model in summary.models.items():
        if key not in summary.datasets:
            continue
        ds = summary.datasets[key]
        grp = model.split["test"]
        n_variant = split_model_key(key)
        if n_variant is None:
            continue
        label = f"{n_variant[0]} samples, {VARIANT_LABELS[n_variant[1]]}"
        save(fig_training(model, f"BPNN training, {label}"), f"ch5_training_{key}.png")
        save(
            fig_errors(
                model.predict(ds.inputs[grp], ds.baseline()[grp]),
                ds.targets()[grp],
                ds.baseline()[grp],
                f"{label}: test group",
            ),
            f"ch5_errors_{key}_test_group.png",
        )
        test = summary.datasets.get("independent_test")
        if test is not None:
            save(
                fig_errors(
                    model.predict(test.inputs, test.baseline()),
                    test.targets(),
                    test.baseline(),
                    f"{label}: independent test set",
                ),
                f"ch5_errors_{key}_independent.png",
            )
    if summary.learning:
        save(fig_learning_curve(summary.learning), "ch5_learning_curve.png")
    for (scene, loc, noise), res in dict(summary.models.get("episodes", {})).items():
        if res.trajectory is None:
            continue
        setup = build_uuv3d(load_ch5_scenario(scene))
        save(
            fig_trajectory3d(
                res.trajectory, setup.obstacles, setup.goal, f"{scene}, {loc}, noise {noise} m"
            ),
            f"ch5_traj_{scene}_{loc}_{noise}.png",
        )
    gif = _animate_one(dict(summary.models.get("episodes", {})), out)
    if gif is not None:
        files.append(gif)
    return files


#: frames of the report's animation (each redraws the bodies in two 3D views: ~0.3 s a frame)
ANIMATION_FRAMES = 24

#: the run animated in the report: Scene 3 (two obstacles) first, with the BPNN locator
ANIMATION_PREFERENCE: tuple[tuple[str, str], ...] = (
    ("thesis-ch5-scene3", "network"),
    ("thesis-ch5-scene1", "network"),
    ("thesis-ch5-scene3", "geometric"),
    ("thesis-ch5-scene1", "geometric"),
)


def _animate_one(
    episodes: dict[tuple[str, str, float], EpisodeResult[LocatedTrace]], out: Path
) -> Path | None:
    """Animate the preferred recorded noise-free thesis run (:data:`ANIMATION_PREFERENCE`)."""
    from uvnav.scenarios.ch5 import build_uuv3d, load_ch5_scenario

    for scene, loc in ANIMATION_PREFERENCE:
        res = episodes.get((scene, loc, 0.0))
        trace = res.trajectory if res is not None else None
        if trace is None or len(trace.times) < 2:
            continue
        setup = build_uuv3d(load_ch5_scenario(scene))
        return save_animation3d(
            trace,
            setup.obstacles,
            setup.goal,
            out / f"ch5_anim_{scene}_{loc}.gif",
            radius=setup.spec.radius,
            title=f"{scene}, {loc} locator",
            max_frames=ANIMATION_FRAMES,
        )
    return None
