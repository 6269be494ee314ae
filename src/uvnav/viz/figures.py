"""Static matplotlib figures of episodes and campaigns (thesis Ch. 2, Figs. 2.7–2.10).

* :func:`plot_episode` — one episode like Figs. 2.7/2.8: (a) the robot path (red dotted) from I to T
  with the obstacles' outlines drawn at regular times in fading colour and their centre paths;
  (b) V_R(t), u_R(t) and d_min(t) (the clearance); (c) ||v_i|| and u_i of the nearest obstacle;
  (d) path length over time (as Fig. 2.10(c, d)).
* :func:`plot_comparison` — several controllers on one scene side by side plus all their path-length
  curves on one axis (Fig. 2.10).
* :func:`plot_campaign_summary` — outcome shares, min-clearance and detour-ratio distributions per
  controller from :meth:`uvnav.bench.store.ResultsStore.episodes_frame`.

Every function builds a :class:`matplotlib.figure.Figure` on an explicit Agg canvas and never
touches ``matplotlib.pyplot``: no global figure registry, no backend switch, nothing left open —
safe in worker processes, servers and tests.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.cm import ScalarMappable
from matplotlib.collections import LineCollection
from matplotlib.colors import ListedColormap, Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle

from uvnav.sim import EpisodeResult, EpisodeSetup, Trajectory

if TYPE_CHECKING:
    import pandas as pd

_ROBOT = "tab:red"
_OBSTACLE_CMAP = "Blues"
_STATUS_COLOURS = {
    "success": "tab:green",
    "collision": "tab:red",
    "timeout": "tab:orange",
    "error": "tab:gray",
    "refused": "tab:blue",
}
#: resolution of every report figure [dots per inch]
DPI = 120


def new_figure(width: float, height: float) -> Figure:
    """A matplotlib figure on the Agg canvas (no pyplot state), constrained layout, ``width`` x
    ``height`` inches."""
    fig = Figure(figsize=(width, height), dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def save_figure(fig: Figure, path: str | Path) -> Path:
    """Write ``fig`` to ``path`` (its folder created) at the report's resolution."""
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=DPI)
    return out


def _require_trajectory(result: EpisodeResult) -> Trajectory:
    if result.trajectory is None:
        raise ValueError("the episode was run with record=False: there is no trajectory to plot")
    return result.trajectory


def path_length_over_time(traj: Trajectory) -> np.ndarray:
    """Cumulative distance travelled by the robot centre at each sample [m]."""
    steps = np.hypot(*np.diff(traj.robot[:, :2], axis=0).T) if len(traj.times) > 1 else np.zeros(0)
    return np.concatenate([[0.0], np.cumsum(steps)])


def snapshot_indices(n_samples: int, snapshots: int) -> np.ndarray:
    """``snapshots`` sample indices evenly spread over ``[0, n_samples - 1]``, ends included."""
    if n_samples <= 0:
        return np.zeros(0, dtype=int)
    return np.unique(np.linspace(0, n_samples - 1, max(1, snapshots)).round().astype(int))


def _finite(a: np.ndarray) -> np.ndarray:
    out = np.asarray(a, dtype=float).copy()
    out[~np.isfinite(out)] = np.nan
    return out


def _fading_cmap() -> ListedColormap:
    """Upper 75% of the obstacle colormap: early outlines pale (yet visible), late ones dark."""
    base = colormaps[_OBSTACLE_CMAP]
    return ListedColormap(base(np.linspace(0.25, 1.0, 256)), name="uvnav-fading")


#: the most obstacle outlines panel (a) draws: in a dense crowd, fewer snapshots each
OUTLINE_BUDGET = 80


def scene_snapshots(traj: Trajectory, snapshots: int, bodies: int) -> tuple[np.ndarray, int | None]:
    """The samples at which panel (a) draws the obstacles, and the robot's closest approach (the
    sample of least clearance; ``None`` without a finite clearance): ``snapshots`` evenly spread
    with the closest approach among them; in a dense crowd, where ``bodies`` would draw more
    than :data:`OUTLINE_BUDGET` outlines, the closest approach alone (else the first and last).

    >>> from types import SimpleNamespace
    >>> t = SimpleNamespace(times=np.arange(11.0), clearance=np.r_[5.0:0.0:-1, 0.5, 1:6.0])
    >>> scene_snapshots(t, 5, 2)
    (array([ 0,  2,  5,  8, 10]), 5)
    >>> scene_snapshots(t, 10, 40)
    (array([5]), 5)
    """
    n = len(traj.times)
    gaps = _finite(np.asarray(traj.clearance, dtype=float))
    closest = int(np.nanargmin(gaps)) if n and np.isfinite(gaps).any() else None
    if bodies * snapshots > OUTLINE_BUDGET:
        return (np.array([closest]) if closest is not None else snapshot_indices(n, 2)), closest
    idx = snapshot_indices(n, snapshots)
    return (idx if closest is None else np.union1d(idx, [closest])), closest


def _draw_scene(
    ax: Axes,
    traj: Trajectory,
    setup: EpisodeSetup,
    *,
    snapshots: int,
    status: str,
    colorbar_fig: Figure | None = None,
) -> None:
    """Panel (a): robot path, I and T, obstacle outlines over time, obstacle centre paths."""
    times = traj.times
    k = traj.obstacle_centres.shape[1] if traj.obstacle_centres.ndim == 3 else 0
    idx, closest = scene_snapshots(traj, snapshots, k)
    dense = k * snapshots > OUTLINE_BUDGET
    t_end = float(times[-1]) if len(times) else 1.0
    norm = Normalize(vmin=0.0, vmax=max(t_end, 1e-9))
    cmap = _fading_cmap()

    def shade(t: float) -> Any:
        return cmap(norm(t))

    rings: list[np.ndarray] = []
    ring_colours: list[Any] = []
    for j in range(k):
        c = traj.obstacle_centres[:, j, :]
        away = far_from_path(c, traj.robot[:, :2])
        c = np.where(away[:, None], np.nan, c)  # absent (parked) obstacles: no line to them
        ax.plot(c[:, 0], c[:, 1], color="tab:blue", lw=0.6 if dense else 0.8,
                alpha=0.3 if dense else 0.6, ls="-")  # fmt: skip
        for i in idx:
            if away[i]:
                continue
            outline = traj.obstacle_outline(j, int(i))
            rings.append(np.vstack([outline, outline[:1]]))
            ring_colours.append(shade(float(times[i])))
    if rings:
        # one collection instead of one Line2D per outline: much faster layout and drawing
        ax.add_collection(LineCollection(rings, colors=ring_colours, linewidths=1.1))
    robot = traj.robot
    ax.plot(robot[:, 0], robot[:, 1], ls=":", color=_ROBOT, lw=1.8)
    # robot positions at the snapshot times, same fading so they can be matched to the outlines
    ax.scatter(
        robot[idx, 0],
        robot[idx, 1],
        s=14,
        c=[shade(float(times[i])) for i in idx],
        edgecolors=_ROBOT,
        linewidths=0.8,
        zorder=4,
    )
    start = np.asarray(setup.start, dtype=float)
    goal = np.asarray(setup.goal, dtype=float)
    ax.plot(*start[:2], marker="o", color="k", ms=6, zorder=5)
    ax.annotate(
        "I",
        (float(start[0]), float(start[1])),
        textcoords="offset points",
        xytext=(-10, -12),
        fontweight="bold",
    )
    ax.plot(*goal, marker="*", color="k", ms=11, zorder=5)
    ax.annotate(
        "T",
        (float(goal[0]), float(goal[1])),
        textcoords="offset points",
        xytext=(6, 4),
        fontweight="bold",
    )
    if closest is not None and len(robot):  # the robot's disc at its closest approach
        centre = (float(robot[closest, 0]), float(robot[closest, 1]))
        ax.add_patch(Circle(centre, float(setup.spec.radius), fill=False, ec=_ROBOT, lw=1.6,
                            zorder=5))  # fmt: skip
    if status == "collision" and len(robot):
        ax.plot(robot[-1, 0], robot[-1, 1], marker="X", color="k", ms=10, zorder=6)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.grid(True, alpha=0.3)
    handles = [
        Line2D([], [], ls=":", color=_ROBOT, lw=1.8, label="robot path"),
        Line2D(
            [],
            [],
            color=cmap(0.8),
            lw=1.1,
            label="obstacles at closest approach" if dense else "obstacles (fading = earlier)",
        ),
        Line2D([], [], color="tab:blue", lw=0.8, alpha=0.6, label="obstacle centre paths"),
    ]
    if closest is not None:
        label = f"robot at closest approach (t = {float(times[closest]):.1f} s)"
        handles.append(Line2D([], [], color=_ROBOT, lw=1.6, label=label))
    if status == "collision":
        handles.append(Line2D([], [], marker="X", color="k", ls="", label="collision"))
    ax.legend(handles=handles, loc="lower right", fontsize="small", framealpha=0.8)
    if colorbar_fig is not None and k and not dense:
        colorbar_fig.colorbar(
            ScalarMappable(norm=norm, cmap=cmap),
            ax=ax,
            label="time of outline [s]",
            shrink=0.6,
        )


def _shade_modes(ax: Axes, traj: Trajectory) -> list[Any]:
    """Shade where the controller's mode is not its first mode; returns legend handles."""
    modes = list(traj.modes)
    if len(set(modes)) < 2:
        return []
    base = next((m for m in modes if m), modes[0])
    t = traj.times
    colours = ["0.85", "#f5deb3", "#d8bfd8", "#c1e1c1"]
    palette = {m: colours[i % len(colours)] for i, m in enumerate(sorted(set(modes) - {base}))}
    start = 0
    for i in range(1, len(modes) + 1):
        if i == len(modes) or modes[i] != modes[start]:
            m = modes[start]
            if m in palette:
                t1 = t[i] if i < len(t) else t[-1]
                ax.axvspan(t[start], t1, color=palette[m], alpha=0.6, lw=0)
            start = i
    from matplotlib.patches import Patch

    return [Patch(color=c, alpha=0.6, label=_mode_label(m)) for m, c in palette.items()]


#: what the 2D laws' mode names mean (every law names avoidance ``M2``: the thesis's sliding
#: mode, ORCA's velocity away from the preferred one)
MODE_MEANINGS = {"M1": "to the goal (M1)", "M2": "avoiding (M2)"}


def _mode_label(mode: str) -> str:
    """A mode's legend label: its meaning where it has one, else ``mode NAME``."""
    return MODE_MEANINGS.get(mode, f"mode {mode or '(none)'}")


def _draw_signals(ax: Axes, traj: Trajectory, setup: EpisodeSetup) -> None:
    """Panel (b): the two commands (V_R(t), u_R(t) for the unicycle, v_x(t), v_y(t) for the
    holonomic robot) and the clearance d_min(t) (twin axis)."""
    t = traj.times
    handles = _shade_modes(ax, traj)
    first, second = traj.command_names
    (hv,) = ax.plot(t, traj.commands[:, 0], color="tab:blue", drawstyle="steps-post", label=first)
    (hu,) = ax.plot(
        t, traj.commands[:, 1], color="tab:orange", drawstyle="steps-post", lw=0.9, label=second
    )
    spec = setup.spec
    unicycle = second.startswith("u_R")
    limits = (spec.v_max, spec.u_max, -spec.u_max) if unicycle else (spec.v_max, -spec.v_max)
    for y in limits:
        ax.axhline(y, color="0.5", ls="--", lw=0.6)
    ax.set_ylabel(f"{first}, {second}")
    ax.grid(True, alpha=0.3)
    ax2 = ax.twinx()
    (hd,) = ax2.plot(t, _finite(traj.clearance), color="tab:green", lw=1.4, label="d_min [m]")
    ax2.axhline(0.0, color="tab:green", ls=":", lw=0.8)
    ax2.set_ylabel("d_min = clearance [m]", color="tab:green")
    ax.legend(
        handles=[hv, hu, hd, *handles], loc="upper right", fontsize="small", ncols=2, framealpha=0.8
    )
    what = "speed, turn rate" if unicycle else "velocity"
    ax.set_title(f"(b) robot {what} and clearance", fontsize="medium", loc="left")


def _round(shape: np.ndarray) -> bool:
    """Whether a body-frame outline is a disc's (every vertex at one distance from the centre,
    many vertices): its rotation moves no part of its boundary."""
    r = np.hypot(shape[:, 0], shape[:, 1]) if len(shape) else np.zeros(0)
    return len(r) >= 16 and bool(np.ptp(r) <= 1e-9 * max(float(r.max()), 1.0))


def _draw_nearest(ax: Axes, traj: Trajectory) -> None:
    """Panel (c): ||v_i|| and u_i of the nearest obstacle over time (u_i of a rotating body
    only: a disc's rotation, a walking person's heading rate, moves none of its boundary)."""
    t = traj.times
    near = np.asarray(traj.nearest_id, dtype=int)
    n = len(t)
    speed = np.full(n, np.nan)
    omega = np.full(n, np.nan)
    ok = near >= 0
    if ok.any() and traj.obstacle_velocities.ndim == 3:
        rows = np.nonzero(ok)[0]
        v = traj.obstacle_velocities[rows, near[ok], :]
        speed[rows] = np.hypot(v[:, 0], v[:, 1])
        omega[rows] = traj.obstacle_omegas[rows, near[ok]]
        discs = np.array([_round(np.asarray(s)) for s in traj.obstacle_shapes], dtype=bool)
        if len(discs) == traj.obstacle_omegas.shape[1]:
            omega[rows[discs[near[ok]]]] = np.nan
    ax.plot(t, speed, color="tab:purple", label="||v_i|| [m/s]")
    rotating = bool(np.isfinite(omega).any())
    ax.plot(t, omega, color="tab:brown", lw=0.9, label="u_i [rad/s]" if rotating else None)
    ax.axhline(0.0, color="0.5", lw=0.5)
    ax.set_ylabel("||v_i|| [m/s], u_i [rad/s]" if rotating else "||v_i|| [m/s]")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper right", fontsize="small", framealpha=0.8)
    ax.set_title("(c) nearest obstacle", fontsize="medium", loc="left")


def _draw_path_length(
    ax: Axes, traj: Trajectory, *, label: str | None = None, color: str | None = None
) -> None:
    """Path length over time, labelled with its final value [m] (thesis Fig. 2.10(c, d))."""
    length = path_length_over_time(traj)
    final = f"{length[-1]:.2f} m" if len(length) else "n/a"
    ax.plot(traj.times, length, color=color, label=f"{label}: {final}" if label else final)
    ax.legend(loc="upper left", fontsize="small")


def _summary_line(result: EpisodeResult) -> str:
    m = result.metrics
    clear = "n/a" if m.min_clearance is None else f"{m.min_clearance:.3f} m"
    return f"status: {result.status}, path length {m.path_length:.2f} m, min clearance {clear}"


def plot_episode(
    result: EpisodeResult,
    setup: EpisodeSetup,
    path: str | Path,
    *,
    title: str | None = None,
    snapshots: int = 10,
) -> Path:
    """Write a four-panel figure of one recorded episode (thesis Figs. 2.7/2.8 style) as PNG.

    Args:
        result: a result of ``run_episode(..., record=True)`` (or one rebuilt from the store).
        setup: the episode's setup (start, goal and vehicle limits are read from it).
        path: output file (``.png``; parent directories are created).
        title: figure title; the status and key metrics are added below it.
        snapshots: number of times at which obstacle outlines are drawn (fewer in a dense
            crowd, :func:`scene_snapshots`; the closest approach is always drawn).

    Returns:
        ``path``.

    Raises:
        ValueError: the result has no trajectory.
    """
    traj = _require_trajectory(result)
    fig = new_figure(13.0, 8.0)
    gs = fig.add_gridspec(3, 2, width_ratios=[1.15, 1.0])
    ax_a = fig.add_subplot(gs[:, 0])
    ax_b = fig.add_subplot(gs[0, 1])
    ax_c = fig.add_subplot(gs[1, 1], sharex=ax_b)
    ax_d = fig.add_subplot(gs[2, 1], sharex=ax_b)
    _draw_scene(ax_a, traj, setup, snapshots=snapshots, status=result.status, colorbar_fig=fig)
    ax_a.set_title("(a) paths of the robot and the obstacles", fontsize="medium", loc="left")
    _draw_signals(ax_b, traj, setup)
    _draw_nearest(ax_c, traj)
    _draw_path_length(ax_d, traj, color=_ROBOT)
    ax_d.set_title("(d) length of the robot's path", fontsize="medium", loc="left")
    ax_d.set_xlabel("t [s]")
    ax_d.set_ylabel("path length [m]")
    ax_d.grid(True, alpha=0.3)
    fig.suptitle(f"{title}\n{_summary_line(result)}" if title else _summary_line(result))
    return save_figure(fig, path)


def plot_comparison(
    results: Mapping[str, tuple[EpisodeResult, EpisodeSetup]],
    path: str | Path,
    *,
    title: str | None = None,
    snapshots: int = 10,
) -> Path:
    """Several controllers on one scene side by side, their path lengths on one axis (Fig. 2.10).

    Args:
        results: label (e.g. controller name) → (recorded result, setup), in display order.
        path: output PNG file.
        title: figure title.
        snapshots: outlines per obstacle in each path panel.

    Returns:
        ``path``.
    """
    if not results:
        raise ValueError("nothing to compare")
    items = list(results.items())
    n = len(items)
    fig = new_figure(max(6.0, 5.2 * n), 9.0)
    gs = fig.add_gridspec(2, n, height_ratios=[1.6, 1.0])
    colours = [f"C{i}" for i in range(n)]
    lo, hi = _common_limits([(_require_trajectory(r), st) for r, st in results.values()])
    for i, (label, (res, setup)) in enumerate(items):
        ax = fig.add_subplot(gs[0, i])
        _draw_scene(ax, _require_trajectory(res), setup, snapshots=snapshots, status=res.status)
        # same window for every law, so the paths compare at a glance
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_aspect("equal", adjustable="box")
        ax.set_title(
            f"({chr(ord('a') + i)}) {label}\n{_summary_line(res)}", fontsize="medium", loc="left"
        )
    ax_len = fig.add_subplot(gs[1, :])
    straight = []
    for (label, (res, setup)), colour in zip(items, colours, strict=True):
        _draw_path_length(ax_len, _require_trajectory(res), label=label, color=colour)
        straight.append(float(np.hypot(*(np.asarray(setup.goal) - np.asarray(setup.start)[:2]))))
    if straight and np.allclose(straight, straight[0]):
        ax_len.axhline(
            straight[0],
            color="k",
            ls="--",
            lw=0.8,
            label=f"straight-line distance I–T ({straight[0]:.2f} m)",
        )
    ax_len.set_xlabel("t [s]")
    ax_len.set_ylabel("path length [m]")
    ax_len.set_title(
        f"({chr(ord('a') + n)}) length of the robot's path", fontsize="medium", loc="left"
    )
    ax_len.grid(True, alpha=0.3)
    ax_len.legend(loc="upper left", fontsize="small")  # again: includes the straight line
    if title:
        fig.suptitle(title)
    return save_figure(fig, path)


def far_from_path(points: np.ndarray, path: np.ndarray, limit: float = 50.0) -> np.ndarray:
    """(n,) True for points more than ``limit`` [m] outside the robot path's bounding box.

    Replayed pedestrians are parked far away while absent from the recording
    (:mod:`uvnav.scenarios.pedestrians`); figures leave those positions out.
    """
    lo, hi = path.min(axis=0) - limit, path.max(axis=0) + limit
    return np.asarray(np.any((points < lo) | (points > hi), axis=1))


def _common_limits(
    runs: Sequence[tuple[Trajectory, EpisodeSetup]], margin: float = 0.5
) -> tuple[np.ndarray, np.ndarray]:
    """Bounding box [m] of robot paths, I, T and obstacle centre paths of several episodes."""
    pts = []
    for traj, setup in runs:
        pts.append(traj.robot[:, :2])
        pts.append(np.asarray(setup.start, dtype=float)[None, :2])
        pts.append(np.asarray(setup.goal, dtype=float)[None, :])
        if traj.obstacle_centres.ndim == 3 and traj.obstacle_centres.shape[1]:
            reach = max(
                (float(np.max(np.hypot(*np.asarray(s).T))) for s in traj.obstacle_shapes),
                default=0.0,
            )
            c = traj.obstacle_centres.reshape(-1, 2)
            c = c[~far_from_path(c, traj.robot[:, :2])]
            pts += [c - reach, c + reach]
    allp = np.concatenate(pts, axis=0)
    return allp.min(axis=0) - margin, allp.max(axis=0) + margin


def _box(
    ax: Axes,
    groups: Sequence[tuple[str, np.ndarray]],
    *,
    ylabel: str,
    title: str,
    ref: float | None = None,
    ref_label: str = "",
) -> None:
    data = [(name, v[np.isfinite(v)]) for name, v in groups]
    data = [(name, v) for name, v in data if len(v)]
    if not data:
        ax.text(0.5, 0.5, "no data", ha="center", va="center", transform=ax.transAxes)
    else:
        ax.boxplot(
            [v for _, v in data],
            tick_labels=[name for name, _ in data],
            showmeans=True,
            showfliers=False,
        )
        rng = np.random.default_rng(0)  # fixed jitter: figures are reproducible
        for i, (_, v) in enumerate(data, start=1):
            ax.scatter(i + rng.uniform(-0.12, 0.12, len(v)), v, s=6, alpha=0.35, color="0.3")
        ax.tick_params(axis="x", labelrotation=20 if len(data) <= 8 else 90)
    if ref is not None:
        ax.axhline(ref, color="tab:red", ls="--", lw=0.8, label=ref_label)
        ax.legend(loc="upper right", fontsize="small")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize="medium", loc="left")
    ax.grid(True, axis="y", alpha=0.3)


def _outcome_bars(ax: Axes, df: pd.DataFrame, family: Any, groups: list[tuple[str, str]]) -> None:
    """One bar per (family, controller): the share of each status, the success rate at right."""
    statuses = [s for s in _STATUS_COLOURS if (df["status"] == s).any()]
    statuses += sorted(set(df["status"].astype(str)) - set(statuses))
    labels = [f"{f} · {c}" if f else c for f, c in groups]
    left = np.zeros(len(groups))
    for s in statuses:
        shares = np.array(
            [
                float(((family == f) & (df["controller"] == c) & (df["status"] == s)).sum())
                / max(1, int(((family == f) & (df["controller"] == c)).sum()))
                for f, c in groups
            ]
        )
        ax.barh(labels, shares, left=left, color=_STATUS_COLOURS.get(s), label=s)
        left += shares
    for y, (f, c) in enumerate(groups):
        status = df.loc[(family == f) & (df["controller"] == c), "status"]
        ran = status[status != "refused"]
        text = f"{(ran == 'success').mean():.1%} of {len(ran)}" if len(ran) else "refused"
        ax.text(1.01, y, text, va="center", fontsize="small")
    ax.set_xlim(0, 1.25)
    ax.invert_yaxis()
    ax.set_xlabel("share of episodes")
    ax.set_title("outcomes (success of those run, at right)", fontsize="medium", loc="left")
    ax.legend(
        loc="upper center", bbox_to_anchor=(0.5, -0.12), ncols=len(statuses), fontsize="small"
    )


def _success_matrix(ax: Axes, df: pd.DataFrame, family: Any) -> None:
    """Success rate [%] of each family (row) x controller (column) over the episodes that ran;
    blank where none ran ("ref." where every episode was refused)."""
    families = sorted({str(f) for f in family})
    laws = sorted(df["controller"].astype(str).unique())
    ok = (df["status"] == "success").to_numpy()
    ran = (df["status"] != "refused").to_numpy()
    rates = np.full((len(families), len(laws)), np.nan)
    for (i, f), (j, c) in itertools.product(enumerate(families), enumerate(laws)):
        sel = ((family == f) & (df["controller"] == c)).to_numpy()
        if (sel & ran).any():
            rates[i, j] = 100.0 * float(ok[sel & ran].mean())
        elif sel.any():
            ax.text(j, i, "ref.", ha="center", va="center", fontsize="x-small", color="0.4")
    image = ax.imshow(rates, cmap="RdYlGn", vmin=0.0, vmax=100.0, aspect="auto")
    for (i, j), rate in np.ndenumerate(rates):
        if np.isfinite(rate):
            ax.text(j, i, f"{rate:.0f}", ha="center", va="center", fontsize="x-small")
    ax.set_xticks(range(len(laws)), laws, rotation=90, fontsize="small")
    ax.set_yticks(range(len(families)), families, fontsize="small")
    ax.figure.colorbar(image, ax=ax, label="success [%]", fraction=0.04)
    ax.set_title("success [%] of the episodes run (blank: none)", fontsize="medium", loc="left")


#: above this many (family, controller) pairs the outcome panel is a success-rate matrix
_MAX_OUTCOME_BARS = 24


def plot_campaign_summary(df: pd.DataFrame, path: str | Path, *, title: str | None = None) -> Path:
    """Outcome shares per (family, controller), and min-clearance / detour-ratio distributions.

    With more than :data:`_MAX_OUTCOME_BARS` pairs the outcomes are a families x controllers
    matrix of success rates (a pair not run is blank), and the figure widens with the number
    of controllers, so that every label stays readable.

    Args:
        df: episodes as from :meth:`uvnav.bench.store.ResultsStore.episodes_frame` (columns
            ``controller``, ``status``, ``min_clearance``, ``detour_ratio``, optionally
            ``family``).
        path: output PNG file.
        title: figure title.

    Returns:
        ``path``.
    """
    n_laws = int(df["controller"].nunique()) if not df.empty else 1
    fig = new_figure(max(15.0, 6.0 + 0.75 * n_laws), 5.5 if n_laws <= 8 else 7.5)
    ax_s, ax_c, ax_d = fig.subplots(1, 3, width_ratios=[1.3, 1.0, 1.0])
    if df.empty:
        for ax in (ax_s, ax_c, ax_d):
            ax.text(0.5, 0.5, "no episodes", ha="center", va="center", transform=ax.transAxes)
        return save_figure(fig, path)
    family = df["family"] if "family" in df.columns else df["controller"].map(lambda _: "")
    groups = sorted({(str(f), str(c)) for f, c in zip(family, df["controller"], strict=True)})
    if len(groups) > _MAX_OUTCOME_BARS:
        _success_matrix(ax_s, df, family)
    else:
        _outcome_bars(ax_s, df, family, groups)
    controllers = sorted(df["controller"].astype(str).unique())

    def column(name: str, mask: Any = None) -> list[tuple[str, np.ndarray]]:
        out = []
        for c in controllers:
            sel = df["controller"] == c
            if mask is not None:
                sel = sel & mask
            out.append((c, df.loc[sel, name].to_numpy(dtype=float, na_value=np.nan)))
        return out

    _box(
        ax_c,
        column("min_clearance"),
        ylabel="min clearance [m]",
        title="min clearance per episode",
        ref=0.0,
        ref_label="contact",
    )
    _box(
        ax_d,
        column("detour_ratio", df["status"] == "success"),
        ylabel="detour ratio [-]",
        title="detour ratio (successful episodes)",
        ref=1.0,
        ref_label="straight line",
    )
    if title:
        fig.suptitle(title)
    return save_figure(fig, path)
