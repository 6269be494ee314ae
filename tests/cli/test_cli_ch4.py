"""``uvnav ch4``: scenes, simulate (JSON metrics), one-line errors."""

from __future__ import annotations

import json

from typer.testing import CliRunner

from uvnav.cli.app import app
from uvnav.sim.metrics import METRIC_NAMES

runner = CliRunner()


def test_scenes_lists_the_builtins_and_the_generator() -> None:
    out = runner.invoke(app, ["ch4", "scenes"])
    assert out.exit_code == 0, out.output
    assert "thesis-ch4-fig4-2b-trap" in out.stdout and "random-ch4:<seed>" in out.stdout


def test_simulate_prints_the_metrics_as_json() -> None:
    out = runner.invoke(app, ["ch4", "simulate", "thesis-ch4-fig4-2b-trap", "--json"])
    assert out.exit_code == 0, out.output
    data = json.loads(out.stdout)
    assert set(METRIC_NAMES) <= set(data)
    assert data["status"] == "success" and data["entered_forbidden"] is False


def test_bad_scene_and_law_are_one_line_errors() -> None:
    for args in (
        ["ch4", "simulate", "nope"],
        ["ch4", "simulate", "random-ch4:1", "--controller", "x"],
    ):
        out = runner.invoke(app, args)
        assert out.exit_code == 2
        assert out.output.count("\n") == 1 and out.output.startswith("error:")
