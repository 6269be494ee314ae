"""Issue-9 figures are drawn from real plans and runs and saved."""

from __future__ import annotations

import numpy as np
import pytest

from uvnav.planners import DStarLite, astar, occupancy_grid, visibility_path
from uvnav.scenarios.multi import build_multi, load_multi_scenario
from uvnav.sim.run import run_episode
from uvnav.viz.figures_beyond import plot_grid_paths, plot_swap, plot_trajectories


def test_grid_paths_figure(tmp_path) -> None:
    box = np.array([[3.0, 1.0], [5.0, 1.0], [5.0, 6.0], [3.0, 6.0]])
    grid = occupancy_grid((0, 0, 8, 8), 0.1, [box], inflate=0.2)
    s, g = grid.to_cell((1.0, 4.0)), grid.to_cell((7.0, 4.0))
    a = astar(grid.occupied, s, g, resolution=0.1)
    d = DStarLite(grid.occupied, s, g, resolution=0.1)
    d.compute()
    before = grid.occupied.copy()
    d.set_cells([(r, c) for r in range(60, 80) for c in range(20, 23)])
    d.compute()
    changed = d.occupancy() & ~before
    vis = visibility_path((1.0, 4.0), (7.0, 4.0), [box], inflate=0.2)
    out = tmp_path / "paths.png"
    fig = plot_grid_paths(
        grid,
        {
            "A*": grid.to_world(a.cells),
            "D* Lite after change": grid.to_world(d.path().cells),
            "visibility graph": vis.points,
        },
        start=np.array([1.0, 4.0]),
        goal=np.array([7.0, 4.0]),
        changed=changed,
        path=out,
    )
    assert out.stat().st_size > 10_000
    labels = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert any(lbl.startswith("visibility graph") for lbl in labels)


def test_swap_and_trajectory_figures(tmp_path) -> None:
    sc = load_multi_scenario("antipodal:4")
    res = run_episode(build_multi(sc, 0, controller="straight-v1"), None, np.random.default_rng(0))
    goals = np.array([r.goal for r in sc.robots])
    fig = plot_swap(res, goals, path=tmp_path / "swap.png")
    assert "0/4 arrived" in fig.axes[0].get_title()
    legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    assert legend[:2] == ["start", "goal"] and "collided" in legend  # straight-v1 robots meet
    assert (tmp_path / "swap.png").exists()
    plot_trajectories(
        [np.array([[0, 0], [1, 0], [1, 1]], dtype=float)],
        {"robot": res.poses[:, 0, :]},
        path=tmp_path / "t.png",
    )
    assert (tmp_path / "t.png").exists()
    unrecorded = run_episode(
        build_multi(sc, 0, controller="straight-v1"), None, np.random.default_rng(0), record=False
    )
    with pytest.raises(ValueError, match="not recorded"):
        plot_swap(unrecorded, goals)


def test_beyond_figures_are_written(tmp_path) -> None:
    from uvnav.viz.figures_beyond import beyond_figures

    files = beyond_figures(
        tmp_path,
        office_law="savkin-wang2013-v1",
        swap="antipodal:4",
        swap_laws=(("straight-v1", {}),),
    )
    assert [f.name for f in files] == [
        "beyond-paths.png",
        "beyond-office.png",
        "beyond-swap-straight-v1.png",
    ]
    assert all(f.stat().st_size > 5_000 for f in files)
