"""Chapter-4 figures: every figure of a short recorded run is drawn and written."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt

from uvnav.bench.reproduce_ch4 import Ch4Job, run_ch4_job
from uvnav.viz.figures_ch4 import first_avoidance, plot_amaps, plot_decision, render_ch4


def test_figures_of_the_thesis_scenes(tmp_path: Path) -> None:
    res = {}
    for scene in ("thesis-ch4-fig4-8-decision", "thesis-ch4-fig4-7-approach"):
        res[(scene, "zhang2022-uuv2d-v1")] = run_ch4_job(
            Ch4Job(scene, "zhang2022-uuv2d-v1", 0), record=True
        )[1]
    traj = res[("thesis-ch4-fig4-8-decision", "zhang2022-uuv2d-v1")].trajectory
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
    paths = render_ch4(tmp_path, res)
    names = {p.name for p in paths}
    assert {"fig4-7-approach.png", "fig4-8-decision.png", "fig4-4b-amaps.png"} <= names
    assert all(p.stat().st_size > 1000 for p in paths)
