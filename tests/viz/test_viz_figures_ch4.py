"""Chapter-4 figures: every figure of a recorded run is drawn and written."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt

from uvnav.experiments.ch4 import ch4_job, run_ch4_job
from uvnav.viz.figures_ch4 import (
    first_avoidance,
    plot_amaps,
    plot_approach,
    plot_decision,
    render_ch4,
)


def test_figures_of_the_thesis_scenes(tmp_path: Path) -> None:
    scene = "thesis-ch4-fig4-8-decision"
    res = run_ch4_job(ch4_job(scene, "zhang2022-uuv2d-v1", 0), record=True)[1]
    traj = res.trajectory
    assert traj is not None
    k = first_avoidance(traj)
    assert k is not None and traj.decisions[k].tangent_points is not None
    fig = plot_decision(traj, traj.goal)
    labels = fig.axes[0].get_legend_handles_labels()[1]
    assert "r_imin(t) (AMAPS)" in labels and "c(t+1) (4.13)" in labels
    plt.close(fig)
    fig = plot_amaps(traj, traj.goal)
    assert fig.axes[0].images  # the heat map
    plt.close(fig)
    fig = plot_approach(traj, traj.goal)
    assert len(fig.axes) == 4
    plt.close(fig)
    paths = render_ch4(tmp_path, {(scene, "zhang2022-uuv2d-v1"): res})
    assert {p.name for p in paths} == {"fig4-8-decision.png", "fig4-4b-amaps.png"}
    assert all(p.stat().st_size > 1000 for p in paths)
