"""Chapter 5 figures draw what they are given (array, errors, trajectories)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("torch")

from uvnav.obstacles.deforming3d import as_compound, random_star
from uvnav.sensors.sonar_array import SonarArray
from uvnav.sim.episode_uuv3d import LocatedTrace
from uvnav.viz.figures_ch5 import (
    animation_frames,
    fig_array,
    fig_errors,
    fig_trajectory3d,
    save_animation3d,
)


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
    res = LocatedTrace(
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


def test_animation_frames_are_spread_and_keep_both_ends() -> None:
    assert animation_frames(0, 10) == []
    assert animation_frames(5, 24) == [0, 1, 2, 3, 4]
    f = animation_frames(100, 6)
    assert f[0] == 0 and f[-1] == 99 and len(f) == 6 and f == sorted(set(f))


def test_animation_is_a_gif_with_one_frame_per_chosen_decision(tmp_path: Path) -> None:
    Image = pytest.importorskip("PIL.Image")
    n = 12
    times = [0.5 * k for k in range(n)]
    pos = [np.array([0.5 * k, 0.0, 0.0]) for k in range(n)]
    located = [np.full(3, np.nan)] * 4 + [np.array([4.0, 0.5, 0.0])] * (n - 4)
    res = LocatedTrace(times, pos, ["M1"] * 4 + ["M2"] * (n - 4), located, [])
    ob = as_compound(
        random_star(
            np.random.default_rng(0),
            np.array([5.0, 1.0, 0.0]),
            1.0,
            subdivisions=1,
            max_frequency=0.5,
        )
    )
    out = save_animation3d(res, [ob], np.array([8.0, 0.0, 0.0]), tmp_path / "a.gif", max_frames=3)
    assert out == tmp_path / "a.gif" and out.stat().st_size > 0
    with Image.open(out) as im:
        assert im.n_frames == 3
        frames = []
        for k in range(im.n_frames):
            im.seek(k)
            frames.append(np.asarray(im.convert("RGB")))
    assert not np.array_equal(frames[0], frames[-1])  # the vehicle moved (and the body deformed)
    short = LocatedTrace([0.0], [np.zeros(3)], ["M1"], located[:1], [])
    assert save_animation3d(short, [ob], np.ones(3), tmp_path / "b.gif") is None
