"""`uvnav multi run`: metrics as JSON, one-line errors with exit status 2."""

from __future__ import annotations

import json

from typer.testing import CliRunner

from uvnav.cli.app import app
from uvnav.sim.metrics import METRIC_NAMES
from uvnav.sim.multi import GROUP_METRIC_NAMES

runner = CliRunner()


def test_json_output_has_group_and_robot_metrics() -> None:
    res = runner.invoke(app, ["multi", "run", "antipodal:4", "-c", "straight-v1", "--json"])
    assert res.exit_code == 0, res.output
    data = json.loads(res.stdout)
    assert set(data["group"]) == set(GROUP_METRIC_NAMES)
    assert len(data["robots"]) == 4
    assert set(METRIC_NAMES) <= set(data["robots"][0])
    # four straight lines through the centre: they all collide there
    assert data["group"]["arrived"] == 0 and data["group"]["robot_collisions"] >= 2


def test_text_output_and_params() -> None:
    res = runner.invoke(
        app,
        [
            "multi",
            "run",
            "antipodal:4",
            "-p",
            "switch_distance=2.5",
            "-p",
            "forecast_horizon=2.0",
            "-p",
            "safety_margin=0.3",
        ],
    )
    assert res.exit_code == 0, res.output
    assert res.stdout.startswith("antipodal-4: 4/4 arrived, 0 robot-robot collisions")


def test_bad_input_is_one_line_exit_2() -> None:
    for args in (
        ["antipodal:x"],
        ["crossing:3"],
        ["antipodal:4", "-c", "nope-v1"],
        ["antipodal:4", "-p", "bogus=1"],
    ):
        res = runner.invoke(app, ["multi", "run", *args])
        assert res.exit_code == 2, (args, res.output)
        assert res.output.count("\n") == 1 and res.output.startswith("error:")
