"""Chapter 5 figures draw what they are given (array, errors, trajectories)."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("torch")

from uvnav.obstacles.deforming3d import as_compound, random_star
from uvnav.sensors.sonar_array import SonarArray
from uvnav.sim.episode_uuv3d import UUV3DResult
from uvnav.sim.metrics import EpisodeMetrics
from uvnav.viz.figures_ch5 import fig_array, fig_errors, fig_trajectory3d


def test_array_figure_labels_nine_sensors() -> None:
    fig = fig_array(SonarArray())
    texts = {t.get_text() for ax in fig.axes for t in ax.texts}
    assert {f"S{i}" for i in range(1, 10)} <= texts


def test_error_figure_reports_the_error_range() -> None:
    t = np.array([[1.0, 1], [2.0, 3], [3.0, 5]])
    p = t + np.array([[0.1, 0], [-0.2, 1], [0.0, 0]])
    fig = fig_errors(p, t, t, "x")
    titles = " ".join(ax.get_title() for ax in fig.axes)
    assert "[-0.1, 0.2]" in titles and "[-1, 0]" in titles


def test_trajectory_figure() -> None:
    m = EpisodeMetrics(True, False, 0.5, 10.0, 1.1, 10.0, 1.0, 0.0, 0, 2, 1.0, 2.0)
    res = UUV3DResult(
        metrics=m,
        entered_inner_space=False,
        status="success",
        times=[0.0, 1.0],
        positions=[np.zeros(3), np.ones(3)],
        modes=["M1", "M2"],
        located=[np.full(3, np.nan), np.array([2.0, 2, 2])],
        true_nearest=[],
    )
    ob = as_compound(random_star(np.random.default_rng(0), np.full(3, 3.0), 1.0, subdivisions=1))
    fig = fig_trajectory3d(res, [ob], np.full(3, 5.0), "t")
    labels = fig.axes[0].get_legend_handles_labels()[1]
    assert {"vehicle", "avoidance (M2)", "point to evade", "B"} <= set(labels)
