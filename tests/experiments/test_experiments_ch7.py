"""``uvnav run``'s Ch. 7 part: rows measured from real plans, JSON written, figures drawn."""

from __future__ import annotations

import json
from pathlib import Path

from uvnav.experiments import ch7 as r7


def test_reproduce_ch7_rows_come_from_plans(tmp_path: Path) -> None:
    # a small version of the quick job: one plan, one size, two radii
    drawn: list[str] = []

    def render(plan: object, prefix: Path) -> list[Path]:
        drawn.append(prefix.name)
        return [prefix]

    out = r7.reproduce_ch7(
        tmp_path,
        render_plan=render,
        sizes=(150.0,),
        radii=(30.0, 50.0),
        plans=[("synthetic", 150.0, 30.0)],
        coverage_kinds=("flat",),
    )
    assert drawn == ["ch7-synthetic-150m-R30"]
    plan = json.loads((tmp_path / "ch7-synthetic-150m-R30.json").read_text())
    assert plan["coverage_visible"] == 1.0
    assert plan["max_curvature"] <= plan["curvature_bound"]
    rows = {r["quantity"]: r for r in out.table}
    label = "Ch7 synthetic 150 m, R = 30 m: coverage of ground visible at Z_max"
    cov = rows[label + " (independent 0.5 m grid)"]
    assert cov["measured"] == f"{100 * plan['coverage_grid_visible']:.2f} %" == "100.00 %"
    # the ground-truth rows: flat 150 m for both radii, the cell rule complete, the DEM-node
    # rule not, and the guarantee costs altitude
    assert [(c["kind"], c["R"]) for c in out.coverage] == [("flat", 30.0), ("flat", 50.0)]
    for c in out.coverage:
        assert c["after_grid"] == 1.0 > c["before_grid"]
        assert c["after_polygon_uncovered_m2"] == 0.0
        assert c["after_altitude_mean"] > c["before_altitude_mean"]
        q = f"Ch7 coverage on ground truth, flat 150 m, R = {c['R']:.0f} m"
        assert rows[q + " (independent 0.5 m grid, ground visible at Z_max)"]["measured"] == (
            "100.00 %"
        )
    n_rows = [r for r in out.table if r["quantity"].startswith("Ch7 waypoints N, 150 m square")]
    assert len(n_rows) == 2
    for lat in out.lattice:
        assert lat["n"] <= lat["n_naive"]
        assert lat["n"] >= lat["bound_disc"]
