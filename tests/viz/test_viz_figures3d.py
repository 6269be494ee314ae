"""Chapter 3 figures from a real (short) recorded 3D episode."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from uvnav.controllers.base import make_law
from uvnav.dynamics.vehicle3d import Vehicle3DSpec
from uvnav.geometry.mesh3d import box_mesh
from uvnav.obstacles.bodies3d import MeshBody
from uvnav.obstacles.motion3d import ConstantMotion3D, Obstacle3D, ObstacleState3D
from uvnav.sim.episode3d import Episode3DSetup, Sensing3DConfig
from uvnav.sim.run import run_episode
from uvnav.viz.figures3d import interactive_trajectory, render_ch3


def test_render_ch3_writes_every_figure(tmp_path: Path) -> None:
    ob = Obstacle3D(MeshBody.from_mesh(*box_mesh(np.array([0.5, 0.5, 0.5]))),
                    ConstantMotion3D(np.array([0.0, 0.1, 0.0]), np.array([0.0, 0.0, 0.2])),
                    ObstacleState3D(np.array([3.0, 0.3, 0.0])))  # fmt: skip
    setup = Episode3DSetup(spec=Vehicle3DSpec(1.0, 1.0, 0.1), start=np.zeros(3),
                           heading=np.array([1.0, 0, 0]), goal=np.array([6.0, 0, 0]),
                           obstacles=[ob], t_max=12.0,
                           sensing=Sensing3DConfig(velocities="known"))  # fmt: skip
    res = run_episode(
        setup,
        make_law("zhang2020-3d-v1", vehicle="vehicle3d", oracle=True),
        np.random.default_rng(0),
    )
    tr = res.trajectory  # fmt: skip
    assert res.status == "success" and tr is not None
    assert np.isfinite(tr.predicted_velocity).any()  # the law's predictions were recorded
    files = render_ch3(tmp_path / "db.sqlite", tmp_path, [("scene", "zhang2020-3d-v1", tr)])
    kinds = sorted(f.name.split("--")[-1] for f in files)
    assert kinds == ["clearance.png", "obstacle-motion.png", "prediction.png",
                     "trajectory.png", "zhang2020-3d-v1.html"]  # fmt: skip
    assert all(f.stat().st_size > 1000 for f in files)
    assert "plotly" in interactive_trajectory(tr, "t")[:5000].lower()
    # the report's views share one plotly.js next to index.html instead of embedding a copy each
    (page,) = [f for f in files if f.suffix == ".html"]
    text = page.read_text(encoding="utf-8")
    assert 'src="../plotly.min.js"' in text and len(text) < 1_000_000
    assert (tmp_path / "plotly.min.js").stat().st_size > 1_000_000
