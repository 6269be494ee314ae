"""``uvnav simulate`` prints the social metrics (:mod:`uvnav.sim.social`) of 2D scenes only."""

from __future__ import annotations

import json

from typer.testing import CliRunner

from uvnav.cli.app import app
from uvnav.sim.metrics import SOCIAL_METRIC_NAMES

runner = CliRunner()


def test_simulate_crowd_scene_shows_social_metrics() -> None:
    res = runner.invoke(app, ["simulate", "crowdnav-circle:1", "--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)
    assert data["kind"] == "nav2d"
    assert data["min_separation"] is not None and data["intrusion_time"] is not None
    if data["status"] == "collision":
        assert data["collision_by"] in ("robot", "pedestrian", "obstacle")
    table = runner.invoke(app, ["simulate", "crowdnav-circle:1"])
    assert table.exit_code == 0, table.output
    for name in SOCIAL_METRIC_NAMES:
        assert name in table.stdout
    assert "rad/m" in table.stdout


def test_simulate_other_kinds_hide_social_metrics() -> None:
    res = runner.invoke(app, ["simulate", "random-ch4:1", "--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)
    assert all(data[name] is None for name in SOCIAL_METRIC_NAMES)  # null in JSON
    table = runner.invoke(app, ["simulate", "random-ch4:1"])
    assert table.exit_code == 0, table.output
    assert not any(name in table.stdout for name in SOCIAL_METRIC_NAMES)
