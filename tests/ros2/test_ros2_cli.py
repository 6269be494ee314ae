"""``uvnav ros2``: the law's parameters as ROS 2 parameters, a parameter file read back by
``run``, and one-line errors with status 2 (a missing ``cyclonedds`` names the extra)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest
import yaml
from typer.testing import CliRunner

from uvnav.cli.app import app

runner = CliRunner()


def test_params_lists_name_type_description_and_default() -> None:
    r = runner.invoke(app, ["ros2", "params", "zhang2019-holonomic-v2"])
    assert r.exit_code == 0, r.output
    lines = r.stdout.splitlines()
    at = lines.index("Parameter name: speed_levels")
    assert lines[at + 1] == "  Type: double array"
    assert lines[at + 2].startswith("  Description: fractions of V_max")
    assert lines[at + 3] == "  Default: [1.0, 0.6, 0.3]"
    assert "Parameter name: n_headings\n  Type: integer\n" in r.stdout
    assert "Parameter name: track_estimates\n  Type: boolean\n" in r.stdout


def test_params_yaml_is_a_ros2_parameter_file_of_the_defaults() -> None:
    r = runner.invoke(app, ["ros2", "params", "zhang2019-v2", "--yaml"])
    assert r.exit_code == 0, r.output
    data = yaml.safe_load(r.stdout)
    params = data["uvnav"]["ros__parameters"]
    assert params["horizon"] == 4.0 and params["speed_levels"] == [1.0, 0.6, 0.3]


def test_a_law_without_parameters_says_so() -> None:
    r = runner.invoke(app, ["ros2", "params", "straight-holonomic-v1"])
    assert r.exit_code == 0 and r.stdout.strip() == "straight-holonomic-v1 takes no parameters"


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--rate", "0"], "error: --rate: must be positive (got 0)"),
        (["--scan-timeout", "-1"], "error: --scan-timeout: must be positive (got -1)"),
        (["--rate", "nan"], "nan is not a finite number"),
        (["-p", "horizon=-1"], "horizon"),
        (["-p", "nope=1"], "error: unknown parameter(s) nope"),
        (["--domain", "300"], "--domain"),
    ],
)
def test_bad_run_options_are_one_line_errors(args: list[str], message: str) -> None:
    r = runner.invoke(app, ["ros2", "run", "zhang2019-v2", *args])
    assert r.exit_code == 2, r.output
    assert message in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_a_law_of_another_vehicle_is_refused() -> None:
    r = runner.invoke(app, ["ros2", "run", "zhang2020-3d-v1"])
    assert r.exit_code == 2
    assert r.stderr.strip() == (
        "error: law 'zhang2020-3d-v1' drives the vehicle3d vehicle; "
        "the ROS 2 node drives unicycle and holonomic laws"
    )


def test_a_bad_parameter_file_names_the_file(tmp_path: Path) -> None:
    bad = tmp_path / "p.yaml"
    bad.write_text("uvnav:\n  parameters:\n    horizon: 2.0\n")
    r = runner.invoke(app, ["ros2", "run", "zhang2019-v2", "--params-file", str(bad)])
    assert r.exit_code == 2
    assert r.stderr.strip() == (
        f"error: {bad}: uvnav: expected a mapping with a 'ros__parameters' mapping"
    )


def test_missing_cyclonedds_is_one_line_naming_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    for name in [m for m in sys.modules if m == "cyclonedds" or m.startswith("cyclonedds.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "cyclonedds", None)
    r = runner.invoke(app, ["ros2", "run", "zhang2019-v2"])
    assert r.exit_code == 2
    line = r.stderr.strip()
    assert line.startswith("error: uvnav ros2 needs the 'ros2' extra (pip install 'uvnav[ros2]')")
    assert len(line.splitlines()) == 1


def test_run_reads_a_parameter_file_and_stops_after_its_duration(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    pytest.importorskip("cyclonedds")
    from ros2_world import LOOPBACK

    monkeypatch.setenv("CYCLONEDDS_URI", LOOPBACK)
    params = runner.invoke(app, ["ros2", "params", "zhang2019-holonomic-v2", "--yaml"]).stdout
    path = tmp_path / "params.yaml"
    path.write_text(params.replace("horizon: 4.0", "horizon: 2.5"))
    domain = str(1 + (os.getpid() + 100) % 200)
    args = ["--params-file", str(path), "-p", "n_headings=8", "--duration", "0.3"]
    r = runner.invoke(app, ["ros2", "run", "zhang2019-holonomic-v2", *args, "--domain", domain])
    assert r.exit_code == 0, r.output
    assert "uvnav ros2: waiting for a goal" in r.stderr
    assert r.stderr.strip().endswith("uvnav ros2: stopped (zero Twist sent)")
    path.write_text(params.replace("horizon: 4.0", "horizon: -2.5"))  # the file is read
    r = runner.invoke(app, ["ros2", "run", "zhang2019-holonomic-v2", "--params-file", str(path)])
    assert r.exit_code == 2 and "horizon" in r.stderr, r.output
