"""``uvnav simulate`` on a 3D scene (thesis Ch. 3): the 3D simulator, same metrics, clear errors."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from uvnav.cli.app import app
from uvnav.sim import METRIC_NAMES

runner = CliRunner()
SCENE = "thesis-ch3-fig3-5-single-cycle"


def test_simulate_runs_a_3d_scene_to_the_goal(tmp_path: Path) -> None:
    out = tmp_path / "fig.png"
    res = runner.invoke(app, ["simulate", SCENE, "--json", "--plot", str(out)])
    assert res.exit_code == 0, res.output
    rec = json.loads(res.stdout)
    assert rec["controller"] == "zhang2020-3d-v1" and rec["status"] == "success"
    assert set(METRIC_NAMES) <= set(rec)
    assert rec["min_clearance"] > 0.0
    assert out.stat().st_size > 10_000


def test_simulate_3d_with_another_law_and_bad_names() -> None:
    res = runner.invoke(app, ["simulate", SCENE, "-c", "apf3d-v1", "--json"])
    assert res.exit_code == 0, res.output
    assert json.loads(res.stdout)["controller"] == "apf3d-v1"
    bad = runner.invoke(app, ["simulate", SCENE, "-c", "zhang2019-v1"])
    assert bad.exit_code == 2
    assert "zhang2019-v1 drives a unicycle with exact sensing; this nav3d scene" in bad.output
    assert "Traceback" not in bad.output
    bad = runner.invoke(app, ["simulate", SCENE, "-p", "alpha0=-1"])
    assert bad.exit_code == 2 and "alpha0" in bad.output and "Traceback" not in bad.output
