"""Issue-9 rows of `uvnav run`: measured from real runs, one row per configuration."""

from __future__ import annotations

from uvnav.bench.reproduce_beyond import BEYOND, office_rows, replan_rows, swap_rows


def test_office_rows_measure_law_alone_and_hybrid() -> None:
    (row,) = office_rows(["apf-v1"], scenario="corridor")
    assert row["thesis"] == BEYOND
    assert "corridor" in row["quantity"] and "apf-v1" in row["quantity"]
    alone, hybrid = row["measured"].split("; ")
    assert alone.startswith("alone: success") and hybrid.startswith("hybrid: success")


def test_swap_rows_count_arrivals() -> None:
    tuned = {"switch_distance": 2.5, "forecast_horizon": 2.0, "safety_margin": 0.3}
    rows = swap_rows("antipodal:4", [("zhang2019-v1", tuned), ("straight-v1", {})])
    assert len(rows) == 2
    assert rows[0]["measured"].startswith("4/4 arrived, 0 robot-robot collisions")
    assert "switch_distance=2.5" in rows[0]["quantity"]
    # straight lines through the centre: everyone collides
    assert rows[1]["measured"].startswith("0/4 arrived")


def test_replan_row_compares_dstar_lite_with_astar_from_scratch() -> None:
    (row,) = replan_rows(size=80, n_changes=2)
    assert row["thesis"] == BEYOND and "80x80 grid" in row["quantity"]
    expansions = float(row["measured"].split("x fewer expansions")[0])
    assert expansions > 1.0  # the incremental replan expands fewer vertices than A* anew
    assert "median of 2 changes" in row["note"]
