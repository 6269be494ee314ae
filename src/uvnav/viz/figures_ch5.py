"""Chapter 5 figures: the sonar array (Fig. 5.2), training curves, error histograms and
target-vs-output regressions (Figs. 5.5-5.8), the learning curve, and 3D trajectories (Fig. 5.3).

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

from uvnav.geometry.angles import FloatArray
from uvnav.learning.bpnn import TrainedBPNN
from uvnav.obstacles.deforming3d import CompoundBody
from uvnav.sensors.sonar_array import SonarArray
from uvnav.sim.episode_uuv3d import UUV3DResult


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
    residual) and baseline."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for j, out in enumerate(("distance", "index")):
        for variant, style in (("plain", "o-"), ("residual", "^-")):
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
    result: UUV3DResult, obstacles: Sequence[CompoundBody], goal: FloatArray, title: str
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
    pos = np.asarray(result.positions)
    if len(pos):
        ax.plot(*pos.T, color="C0", lw=1.5, label="vehicle")
        m2 = np.array([m == "M2" for m in result.modes])
        if m2.any():
            ax.scatter(*pos[m2].T, color="C3", s=4, label="avoidance (M2)")
        loc = np.asarray(result.located)
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


def render_ch5(summary: Any, report_dir: Path) -> list[Path]:
    """All Chapter 5 figures of a :class:`~uvnav.bench.reproduce_ch5.Ch5Summary` as PNG files in
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
        if not key.startswith("n") or key not in summary.datasets:
            continue
        ds = summary.datasets[key]
        grp = model.split["test"]
        label = f"{key[1:].rstrip('r')} samples, {'residual' if key.endswith('r') else 'plain'}"
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
        setup = build_uuv3d(load_ch5_scenario(scene))
        save(
            fig_trajectory3d(res, setup.obstacles, setup.goal, f"{scene}, {loc}, noise {noise} m"),
            f"ch5_traj_{scene}_{loc}_{noise}.png",
        )
    return files
