"""``uvnav recon plan``: files written, summary measured, one-line errors with exit status 2."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from uvnav.cli.app import app

runner = CliRunner()


def test_recon_plan_writes_plan_files(tmp_path: Path) -> None:
    out = tmp_path / "plan"
    res = runner.invoke(
        app,
        [
            "recon",
            "plan",
            "--synthetic",
            "2",
            "--area",
            "150",
            "--radius",
            "30",
            "--uavs",
            "2",
            "--out",
            str(out),
            "--json",
            "--no-figures",
        ],
    )
    assert res.exit_code == 0, res.output
    s = json.loads(res.output.strip().splitlines()[-1])
    assert s["coverage_visible"] == 1.0
    assert s["max_waypoint_distance"] <= 5.0
    with (out / "waypoints.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == s["n_waypoints"]
    gj = json.loads((out / "trajectory.geojson").read_text())
    assert {f["properties"]["uav"] for f in gj["features"]} == {0, 1, 2}
    assert json.loads((out / "plan.json").read_text())["n_waypoints"] == s["n_waypoints"]
    assert s["coverage_grid_visible"] == 1.0 and s["check_grid_step"] == 0.5


def test_recon_plan_table_quotes_the_independent_check(tmp_path: Path) -> None:
    """The summary table quotes the 0.5 m ground-truth grid, not the planning DEM nodes."""
    args = ["recon", "plan", "--synthetic", "2", "--area", "150", "--radius", "30"]
    res = runner.invoke(app, [*args, "--out", str(tmp_path), "--no-figures"],
                        env={"COLUMNS": "100"})  # fmt: skip
    assert res.exit_code == 0, res.output
    line = next(ln for ln in res.output.splitlines() if "0.5 m grid" in ln)
    assert "100.00 %" in line and "nodes" not in res.output
    assert "ground outside every footprint" in res.output


def test_recon_plan_figures(tmp_path: Path) -> None:
    out = tmp_path / "fig"
    res = runner.invoke(
        app,
        [
            "recon",
            "plan",
            "--synthetic",
            "1",
            "--area",
            "120",
            "--radius",
            "40",
            "--uavs",
            "1",
            "--out",
            str(out),
        ],
    )
    assert res.exit_code == 0, res.output
    assert (out / "fig7_4.png").stat().st_size > 10_000
    html = (out / "recon_3d.html").read_text()
    assert "plotly" in html and "waypoints" in html


def test_recon_plan_errors_are_one_line(tmp_path: Path) -> None:
    (tmp_path / "text.npy").write_text("not an array")
    np.save(tmp_path / "objects.npy", np.array([{"z": 1}], dtype=object), allow_pickle=True)
    (tmp_path / "dem.yaml").write_text("z: 1")
    cases = [
        (["--dem", str(tmp_path / "text.npy")], "text.npy: not a .npy array (no .npy header)"),
        (["--dem", str(tmp_path / "objects.npy")], "objects.npy: holds pickled objects"),
        (["--dem", str(tmp_path / "dem.yaml")], "error: " + str(tmp_path / "dem.yaml: unknown")),
        (["--theta", "180"], "--theta"),
        (["--dem", str(tmp_path / "missing.npy")], "missing.npy"),
        (["--c1", "8"], "c1"),
        (["--z-min", "90", "--z-max", "50"], "--z-min"),
        (["--r-min", "100"], "--r-min"),
        (["--area", "abc"], "--area"),
        (["--synthetic", "1", "--jacksboro"], "exclusive"),
    ]
    for extra, word in cases:
        res = runner.invoke(
            app, ["recon", "plan", "--area", "100", "--out", str(tmp_path / "x"), *extra]
        )
        assert res.exit_code == 2, (extra, res.output)
        lines = [ln for ln in res.output.splitlines() if ln.strip()]
        assert len(lines) == 1 and lines[0].startswith("error: ") and word in lines[0], (
            extra,
            res.output,
        )


def test_recon_plan_area_outside_dem(tmp_path: Path) -> None:
    import numpy as np

    dem = tmp_path / "dem.npy"
    np.save(dem, np.zeros((21, 21)))
    res = runner.invoke(
        app,
        [
            "recon",
            "plan",
            "--dem",
            str(dem),
            "--cell",
            "5",
            "--area",
            "0,0,300,300",
            "--out",
            str(tmp_path / "o"),
        ],
    )
    assert res.exit_code == 2
    assert "dem.npy: area" in res.output


def test_recon_plan_out_onto_an_existing_file_is_one_line_and_leaves_it(tmp_path: Path) -> None:
    taken = tmp_path / "notes.txt"
    taken.write_text("keep me")
    res = runner.invoke(
        app, ["recon", "plan", "--synthetic", "1", "--area", "100", "--out", str(taken)]
    )
    assert res.exit_code == 2, res.output
    assert (
        res.output.strip()
        == f"error: {taken}: --out: exists and is not a folder (the plan is several files)"
    )
    assert taken.read_text() == "keep me"
