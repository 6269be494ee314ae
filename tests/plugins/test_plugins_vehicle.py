"""A vehicle added by a third party: one file (``point_robot/point_robot.py``: the vehicle and a
law for it), installed through entry points only — no uvnav module edited — runs through
``uvnav simulate``, ``uvnav bench`` and the Gymnasium env.

The plug-in is installed as a package manager would: a ``.dist-info`` folder with its
``entry_points.txt`` on the path of fresh processes (so each one loads the entry points as a
user's would).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

PLUGIN = Path(__file__).with_name("point_robot")
ENTRY_POINTS = """\
[uvnav.vehicles]
point = point_robot:PointRobot

[uvnav.controllers]
point-straight-v1 = point_robot:POINT_STRAIGHT
"""


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """The environment of a process that has the plug-in installed."""
    site = tmp_path_factory.mktemp("site")
    info = site / "point_robot-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: point-robot\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text(ENTRY_POINTS)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(site), str(PLUGIN), env.get("PYTHONPATH", "")])
    return env


def _run(env: dict[str, str], *args: str, cwd: Path | None = None) -> str:
    out = subprocess.run(
        [sys.executable, *args], env=env, capture_output=True, text=True, timeout=300, cwd=cwd
    )
    assert out.returncode == 0, out.stderr
    return out.stdout


def test_simulate_runs_the_plugin_vehicle_with_its_law(installed: dict[str, str]) -> None:
    listed = _run(installed, "-m", "uvnav.cli", "controllers", "list", "--vehicle", "point")
    assert "point-straight-v1" in listed
    args = ("simulate", "open-field", "-c", "point-straight-v1", "--json")
    got = json.loads(_run(installed, "-m", "uvnav.cli", *args))
    assert got["status"] == "success" and got["limit_violations"] == 0
    # straight at the box's corner speed: the path is the straight line to the goal's disc
    assert got["detour_ratio"] == pytest.approx(1.0, abs=0.02)


def test_bench_runs_a_campaign_of_the_plugin_vehicle(
    installed: dict[str, str], tmp_path: Path
) -> None:
    campaign = tmp_path / "point.yaml"
    campaign.write_text(
        "name: point\nscenarios:\n  - builtin: open-field\n    seeds: [0, 1]\n"
        "  - generator: random-ch2\n    seeds: [0, 3]\n"
        "controllers:\n  - name: point-straight-v1\n  - name: straight-v1\n"
    )
    db = tmp_path / "point.sqlite"
    args = ("bench", str(campaign), "--db", str(db), "--workers", "1", "--json")
    out = json.loads(_run(installed, "-m", "uvnav.cli", *args))
    text = json.dumps(out)
    assert "point-straight-v1" in text and "straight-v1" in text
    rows = _run(
        installed, "-c",
        "import sqlite3, sys; c = sqlite3.connect(sys.argv[1]); "
        "print(c.execute(\"select count(*), sum(status = 'error') from episodes "
        "where controller = 'point-straight-v1'\").fetchone())", str(db),
    )  # fmt: skip
    assert rows.strip() == "(4, 0)"  # open-field and three random scenes, none an error


def test_the_gymnasium_env_drives_the_plugin_vehicle(installed: dict[str, str]) -> None:
    script = """
import json
import numpy as np
from gymnasium.utils.env_checker import check_env
from uvnav.envs import Nav2DEnv, as_policy
env = Nav2DEnv("open-field", vehicle="point", raw_commands=True)
check_env(env, skip_render_check=True)
obs, info = env.reset(seed=0)
policy = as_policy("point-straight-v1", env=env)
done, steps = False, 0
while not done:
    obs, reward, term, trunc, info = env.step(policy(obs, info))
    done, steps = term or trunc, steps + 1
print(json.dumps({"status": info["status"], "steps": steps,
                  "vehicle": type(env.world.body).__name__,
                  "box": [env.action_space.low.tolist(), env.action_space.high.tolist()]}))
"""
    got = json.loads(_run(installed, "-c", script).strip().splitlines()[-1])
    assert got["vehicle"] == "PointRobot" and got["status"] == "success"
    assert got["box"] == [[-0.707, -0.707], [0.707, 0.707]]  # the scene's V_max, per component
