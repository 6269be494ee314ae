"""The figure of a bag replayed through a law (``uvnav replay``): the robot's path with the goal,
and each command component over time, the law's beside the robot's."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from uvnav.viz.figures import new_figure, save_figure


def plot_replay(result: Any, path: Path, title: str = "") -> Path:
    """Draw ``result`` (a :class:`uvnav.bags.replay.Replay`) into the image file ``path``."""
    fig = new_figure(11.0, 4.5)
    grid = fig.add_gridspec(2, 2, width_ratios=(1.0, 1.3))
    ax = fig.add_subplot(grid[:, 0])
    poses = np.asarray(result.poses, dtype=float)
    ax.plot(poses[:, 0], poses[:, 1], color="tab:blue", lw=1.5, label="robot (odometry)")
    ax.plot(*poses[0, :2], "o", color="tab:blue", ms=5)
    ax.plot(*result.goal[:2], "*", color="tab:green", ms=12, label="goal")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(loc="best", fontsize=8)
    for row, name in enumerate(result.command_names):
        axc = fig.add_subplot(grid[row, 1])
        axc.step(result.times, result.robot_commands[:, row], where="post", color="0.4", lw=1.2,
                 label="robot did")  # fmt: skip
        axc.step(result.times, result.law_commands[:, row], where="post", color="tab:red",
                 lw=1.2, label=f"{result.law} would")  # fmt: skip
        axc.set_ylabel(name)
        if row == 0:
            axc.legend(loc="best", fontsize=8)
        else:
            axc.set_xlabel("time from the first scan [s]")
    if title:
        fig.suptitle(title)
    return save_figure(fig, path)
