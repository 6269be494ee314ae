"""Fig. 7.4-style figure and the 3D HTML view of a small real plan."""

from __future__ import annotations

from pathlib import Path

import pytest

from uvnav.recon.plan import ReconConfig, plan_recon
from uvnav.recon.terrain import fractal_terrain, square_area
from uvnav.viz.figures_ch7 import hillshade, plot_fig7_4, render_plan


@pytest.fixture(scope="module")
def plan():  # type: ignore[no-untyped-def]
    t = fractal_terrain((220.0, 220.0), cell=5.0, seed=5, origin=(-60.0, -60.0), n_blocks=3)
    return plan_recon(t, square_area(100.0), ReconConfig(footprint_radius=30.0, uavs=2, n_lambda=6))


def test_fig7_4_has_four_panels(plan) -> None:  # type: ignore[no-untyped-def]
    fig = plot_fig7_4(plan)
    axes = [ax for ax in fig.axes if ax.get_title()]
    assert [ax.get_title()[:3] for ax in axes] == ["(a)", "(b)", "(c)", "(d)"]
    assert hillshade(plan.terrain).shape == (*plan.terrain.shape, 3)


def test_render_plan_writes_png_and_html(plan, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    files = render_plan(plan, tmp_path / "p")
    assert [f.name for f in files] == ["p-fig7_4.png", "p-3d.html"]
    assert files[0].stat().st_size > 10_000
    html = files[1].read_text()
    assert "UAV 1" in html and "UAV 2" in html and "terrain" in html
