"""Interactive trajectory views for the HTML report (plotly, no server).

:func:`trajectory_animation` turns a recorded :class:`~uvnav.sim.Trajectory` into a plotly figure
with one frame per sampled instant: the robot's disc and the path it has driven so far, its sensing
range, every obstacle's outline at that instant, start and goal — with play / pause buttons and a
time slider.  :func:`animation_sections` collects one such view per recorded episode of a results
database, as HTML ``<div>`` fragments that load ``plotly.min.js`` from the report folder
(:func:`write_plotly_js` puts it there), so the report works from ``file://`` with no network.
In the report each view's frames live in a side file ``anim/anim-<id>.js``
(:func:`write_animation_file`) that the page loads only when the reader asks for that view, so the
page itself carries no frames.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    import plotly.graph_objects as go

    from uvnav.sim import Trajectory

#: The script file the report's animations load, next to ``index.html``.
PLOTLY_JS = "plotly.min.js"


def _require_plotly() -> Any:
    try:
        import plotly.graph_objects as go
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "interactive report views need plotly: pip install 'uvnav[report]'"
        ) from exc
    return go


def _circle(x: float, y: float, r: float, n: int = 32) -> tuple[list[float], list[float]]:
    a = np.linspace(0.0, 2.0 * math.pi, n)
    return np.round(x + r * np.cos(a), 3).tolist(), np.round(y + r * np.sin(a), 3).tolist()


def trajectory_animation(
    traj: Trajectory,
    *,
    goal: tuple[float, float],
    robot_radius: float,
    sensing_range: float | None = None,
    title: str = "",
    max_frames: int = 80,
) -> go.Figure:
    """Animated plotly figure of one recorded episode (the whole path is drawn; the robot's disc,
    its sensing range and the obstacles move).

    Args:
        traj: the recorded trajectory.
        goal: target position [m].
        robot_radius: radius of the robot's disc [m].
        sensing_range: radius of the sensing disc drawn around the robot [m] (None: not drawn).
        title: figure title.
        max_frames: at most this many frames (samples are thinned evenly; the last is kept).
    """
    go_ = _require_plotly()
    n = len(traj.times)
    idx = np.unique(np.linspace(0, n - 1, min(n, max_frames)).round().astype(int))
    k = traj.obstacle_centres.shape[1]
    path = traj.robot[:, :2]

    def traces(i: int) -> list[Any]:
        x, y = float(path[i, 0]), float(path[i, 1])
        out = []
        for j in range(k):
            o = traj.obstacle_outline(j, i)
            out.append(
                go_.Scatter(
                    x=np.r_[o[:, 0], o[:1, 0]].tolist(),
                    y=np.r_[o[:, 1], o[:1, 1]].tolist(),
                    fill="toself",
                    mode="lines",
                    line={"color": "#1f4e79"},
                    fillcolor="rgba(31,78,121,0.35)",
                    name=f"obstacle {j}",
                    showlegend=j == 0,
                    legendgroup="obstacles",
                    hoverinfo="skip",
                )
            )
        cx, cy = _circle(x, y, robot_radius)
        out.append(
            go_.Scatter(
                x=cx,
                y=cy,
                fill="toself",
                mode="lines",
                line={"color": "#d62728"},
                fillcolor="rgba(214,39,40,0.8)",
                name="robot",
            )
        )
        if sensing_range is not None and math.isfinite(sensing_range):
            sx, sy = _circle(x, y, sensing_range, 64)
            out.append(
                go_.Scatter(
                    x=sx,
                    y=sy,
                    mode="lines",
                    line={"color": "#2ca02c", "dash": "dash", "width": 1},
                    name="sensing range",
                    hoverinfo="skip",
                )
            )
        return out

    fixed = [
        go_.Scatter(
            x=np.round(path[:, 0], 3).tolist(),
            y=np.round(path[:, 1], 3).tolist(),
            mode="lines",
            line={"color": "#d62728", "dash": "dot"},
            name="robot path",
        ),
        go_.Scatter(
            x=[float(path[0, 0])],
            y=[float(path[0, 1])],
            mode="markers+text",
            text=["I"],
            textposition="bottom left",
            marker={"color": "black", "size": 9},
            name="start I",
        ),
        go_.Scatter(
            x=[goal[0]],
            y=[goal[1]],
            mode="markers+text",
            text=["T"],
            textposition="top right",
            marker={"color": "black", "size": 12, "symbol": "star"},
            name="target T",
        ),
    ]
    frames = [
        go_.Frame(
            data=traces(int(i)), name=f"{traj.times[i]:.1f}", traces=list(range(len(traces(0))))
        )
        for i in idx
    ]
    from uvnav.viz.figures import far_from_path

    centres = traj.obstacle_centres.reshape(-1, 2)
    pts = [path, centres[~far_from_path(centres, path)], np.asarray([goal])]
    allp = np.concatenate([p for p in pts if len(p)])
    pad = 1.5 + (
        sensing_range if sensing_range is not None and math.isfinite(sensing_range) else 0.0
    )
    lo, hi = allp.min(axis=0) - pad, allp.max(axis=0) + pad
    slider_steps = [
        {
            "method": "animate",
            "label": f.name,
            "args": [
                [f.name],
                {
                    "mode": "immediate",
                    "frame": {"duration": 0, "redraw": True},
                    "transition": {"duration": 0},
                },
            ],
        }
        for f in frames
    ]
    fig = go_.Figure(data=traces(int(idx[0])) + fixed, frames=frames)
    fig.update_layout(
        title=title,
        xaxis={"range": [float(lo[0]), float(hi[0])], "title": "x [m]"},
        yaxis={"range": [float(lo[1]), float(hi[1])], "title": "y [m]", "scaleanchor": "x"},
        height=560,
        margin={"l": 50, "r": 20, "t": 50, "b": 40},
        updatemenus=[
            {
                "type": "buttons",
                "direction": "left",
                "x": 0.0,
                "y": -0.12,
                "xanchor": "left",
                "buttons": [
                    {
                        "label": "Play",
                        "method": "animate",
                        "args": [
                            None,
                            {
                                "frame": {"duration": 80, "redraw": True},
                                "fromcurrent": True,
                                "transition": {"duration": 0},
                            },
                        ],
                    },
                    {
                        "label": "Pause",
                        "method": "animate",
                        "args": [
                            [None],
                            {
                                "mode": "immediate",
                                "frame": {"duration": 0},
                                "transition": {"duration": 0},
                            },
                        ],
                    },
                ],
            }
        ],
        sliders=[
            {
                "active": 0,
                "x": 0.15,
                "len": 0.85,
                "y": -0.05,
                "currentvalue": {"prefix": "t = ", "suffix": " s"},
                "steps": slider_steps,
            }
        ],
    )
    return fig


def write_plotly_js(out_dir: Path) -> Path:
    """Write the bundled plotly.js next to the report (the animations load it from there)."""
    from plotly.offline import get_plotlyjs

    path = Path(out_dir) / PLOTLY_JS
    if not path.is_file():
        path.write_text(get_plotlyjs(), encoding="utf-8")
    return path


#: Folder, next to ``index.html``, of the animations' frame files (loaded on demand).
ANIMATIONS_DIR = "anim"
#: The global object each frame file registers its figure in (``window.uvnavAnimations[id]``).
ANIMATIONS_GLOBAL = "uvnavAnimations"


def write_animation_file(fig: go.Figure, out_dir: Path, div_id: str) -> Path:
    """Write one figure (data, layout, frames) as ``out_dir/anim/<div_id>.js``, a script that
    registers it in ``window.uvnavAnimations``: the report loads it only when asked (a
    ``<script>`` element works from ``file://``, where fetching JSON does not)."""
    folder = Path(out_dir) / ANIMATIONS_DIR
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{div_id}.js"
    g = ANIMATIONS_GLOBAL
    path.write_text(
        f"(window.{g} = window.{g} || {{}})[{json.dumps(div_id)}] = {fig.to_json()};\n",
        encoding="utf-8",
    )
    return path


def animation_sections(
    db_path: Path, *, limit: int = 12, out_dir: Path | None = None
) -> list[dict[str, str]]:
    """One animated view per recorded episode of ``db_path`` (at most ``limit``).

    Args:
        db_path: the results database (only read).
        limit: at most this many views.
        out_dir: the report folder: each view's frames go to a side file
            (:func:`write_animation_file`) loaded on demand; ``None``: inline ``<div>`` fragments.

    Returns:
        ``[{"title", "id", "src", "html"}]`` (``src``: the side file relative to ``out_dir``,
        ``html`` empty; without ``out_dir``: ``src`` empty and ``html`` the fragment); empty when
        nothing was recorded.
    """
    from contextlib import closing

    from uvnav.bench.store import ResultsStore, connect_readonly

    with closing(connect_readonly(db_path)) as conn:  # a report never writes its input
        rows = conn.execute(
            "SELECT e.id, e.scenario, e.controller, e.seed, e.status FROM episodes e "
            "JOIN trajectories t ON t.episode_id = e.id ORDER BY e.scenario, e.controller, e.seed "
            "LIMIT ?",
            (int(limit),),
        ).fetchall()
    if not rows:
        return []
    from uvnav.scenarios import ScenarioError, load_scenario

    sections = []
    with ResultsStore(db_path, readonly=True) as store:
        for ep_id, scenario, controller, seed, status in rows:
            traj = store.load_trajectory(int(ep_id))
            if traj is None or len(traj.times) == 0:
                continue
            try:
                sc = load_scenario(scenario)
                goal = (float(sc.robot.goal[0]), float(sc.robot.goal[1]))
                radius = float(sc.robot.radius)
                sensing: float | None = float(sc.sensing.range)
            except (ScenarioError, OSError):
                goal, radius, sensing = (
                    (float(traj.robot[-1, 0]), float(traj.robot[-1, 1])),
                    0.1,
                    None,
                )
            title = f"{scenario} — {controller} (seed {seed}, {status})"
            fig = trajectory_animation(
                traj, goal=goal, robot_radius=radius, sensing_range=sensing, title=title
            )
            div_id = f"anim-{ep_id}"
            if out_dir is not None:
                src = write_animation_file(fig, out_dir, div_id)
                rel = src.relative_to(Path(out_dir)).as_posix()
                sections.append({"title": title, "id": div_id, "src": rel, "html": ""})
                continue
            html = fig.to_html(
                full_html=False, include_plotlyjs=False, div_id=div_id, auto_play=False
            )
            sections.append({"title": title, "id": div_id, "src": "", "html": html})
    return sections
