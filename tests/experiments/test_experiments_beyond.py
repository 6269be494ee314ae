"""Issue-9 rows of `uvnav run`: measured from real runs, one row per configuration."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from uvnav.bench.store import ResultsStore, StaleCampaignError
from uvnav.experiments import beyond as rb
from uvnav.experiments.beyond import BEYOND, office_rows, replan_rows, swap_rows


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


def _beyond(store: ResultsStore) -> list[dict[str, str]]:
    return office_rows(["apf-v1", "straight-v1"], scenario="corridor", store=store) + swap_rows(
        "antipodal:4", [("straight-v1", {})], store=store
    )


def test_the_rows_are_read_back_from_stored_episodes_and_a_run_resumes(
    tmp_path: Path, interrupt_after: Any, stored_rows: Any, set_fingerprint: Any
) -> None:
    with ResultsStore(tmp_path / "whole.sqlite") as store:
        rows = _beyond(store)
    assert rows == office_rows(["apf-v1", "straight-v1"], scenario="corridor") + swap_rows(
        "antipodal:4", [("straight-v1", {})]
    )  # a temporary store: the same figures
    expected = stored_rows(tmp_path / "whole.sqlite")
    assert {k: len(v) for k, v in expected.items()} == {rb.OFFICE_CAMPAIGN: 4, rb.MULTI_CAMPAIGN: 1}
    db = tmp_path / "uvnav.sqlite"
    seen = interrupt_after(3)
    with ResultsStore(db) as store, pytest.raises(KeyboardInterrupt):
        _beyond(store)
    assert {k: len(v) for k, v in stored_rows(db).items()} == {rb.OFFICE_CAMPAIGN: 3}
    with ResultsStore(db) as store:
        assert _beyond(store) == rows  # the resume runs the missing episodes only
    assert stored_rows(db) == expected and len(seen.after) == 2  # the 4th office run, the swap
    set_fingerprint(db, rb.MULTI_CAMPAIGN)
    with pytest.raises(StaleCampaignError, match=f"'{rb.MULTI_CAMPAIGN}'") as err:
        rb.reproduce_beyond(tmp_path)
    assert "\n" not in str(err.value) and len(seen.after) == 2  # refused before anything ran
