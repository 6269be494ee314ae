"""``uvnav run``'s Ch. 7 part: rows measured from real plans, JSON written, figures drawn."""

from __future__ import annotations

import json
from pathlib import Path

from uvnav.bench import reproduce_ch7 as r7


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
    )
    assert drawn == ["ch7-synthetic-150m-R30"]
    plan = json.loads((tmp_path / "ch7-synthetic-150m-R30.json").read_text())
    assert plan["coverage_visible"] == 1.0
    assert plan["max_curvature"] <= plan["curvature_bound"]
    rows = {r["quantity"]: r for r in out.table}
    cov = rows["Ch7 synthetic 150 m, R = 30 m: coverage of ground visible at Z_max"]
    assert cov["measured"] == "100.00 %"
    n_rows = [r for r in out.table if r["quantity"].startswith("Ch7 waypoints N, 150 m square")]
    assert len(n_rows) == 2
    for lat in out.lattice:
        assert lat["n"] <= lat["n_naive"]
        assert lat["n"] >= lat["bound_disc"]
