"""One figure for one episode of any scene kind (``uvnav simulate --plot``): the chapter's own
figure of a recorded episode, titled with scene, law and seed."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np


def plot_outcome(outcome: Any, path: Path) -> Path:
    """Draw ``outcome`` (a recorded :class:`uvnav.scenarios.episodes.Outcome`) into ``path``.

    Raises:
        ValueError: the kind has no episode figure.
    """
    title = f"{outcome.scene} | {outcome.law} | seed {outcome.seed} | {outcome.status}"
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    kind = outcome.kind
    if kind == "nav2d":
        from uvnav.viz.figures import plot_episode

        return plot_episode(outcome.result, outcome.setup, path, title=title)
    if kind == "multi2d":
        from uvnav.viz.figures_beyond import plot_swap

        setup = outcome.setup  # its obstacles were advanced to the episode's end in place
        goals = np.array([robot.goal for robot in setup.robots], dtype=float)
        ends = [o.world_outline() for o in setup.obstacles]
        fig = plot_swap(outcome.result, goals, title=title, outlines=ends)
    elif kind == "nav3d":
        from uvnav.viz.figures3d import trajectory_figure

        fig = trajectory_figure(outcome.trajectory, title)
    elif kind == "uuv2d":
        from uvnav.viz.figures_ch4 import plot_run

        fig = plot_run(outcome.trajectory, outcome.trajectory.goal)
        fig.suptitle(title)
    elif kind == "uuv3d":
        from uvnav.viz.figures_ch5 import fig_trajectory3d

        setup = outcome.setup
        fig = fig_trajectory3d(outcome.result.trajectory, setup.obstacles, setup.goal, title)
    else:
        raise ValueError(f"--plot: no episode figure for {kind} scenes yet")
    fig.savefig(path, dpi=110)
    import matplotlib.pyplot as plt

    plt.close(fig)
    return path
