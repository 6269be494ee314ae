"""The campaign summary's social columns (:func:`uvnav.bench.summary.controller_summary`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from uvnav.bench.store import ResultsStore
from uvnav.bench.summary import (
    FAILURE_COLUMNS,
    SUMMARY_COLUMNS,
    controller_summary,
    failure_rows,
    paired_difference_interval,
)


def _metrics(status: str, **social: Any) -> dict[str, Any]:
    return {
        "success": status == "success", "collision": status == "collision",
        "min_clearance": 0.1, "path_length": 5.0, "control_effort": 0.0,
        "limit_violations": 0, "mode_switches": 0, "decision_us_median": 1.0,
        "decision_us_p99": 2.0, **social,
    }  # fmt: skip


def test_social_columns(tmp_path: Path) -> None:
    episodes: list[tuple[str, dict[str, Any]]] = [
        ("success", {"min_separation": 0.3, "too_close_frequency": 0.0, "intrusion_time": 1.0,
                     "intrusion_ratio": 0.1, "path_irregularity": 0.2, "personal_space_time": 1.5,
                     "min_time_to_collision": 2.0, "heading_irregularity": 0.3, "jerk": 4.0}),
        ("collision", {"min_separation": -0.05, "too_close_frequency": 0.5, "intrusion_time": 2.0,
                       "intrusion_ratio": 0.4, "path_irregularity": 0.4,
                       "personal_space_time": 0.5, "min_time_to_collision": 0.0,
                       "collision_by": "pedestrian"}),
        ("collision", {"min_separation": 0.2, "too_close_frequency": 0.1, "intrusion_time": 0.0,
                       "path_irregularity": 0.6, "collision_by": "robot"}),
        ("collision", {"min_separation": -0.01, "too_close_frequency": 0.2, "intrusion_time": 3.0,
                       "path_irregularity": None, "collision_by": "pedestrian"}),
        # a scene without pedestrians
        ("success", {"path_irregularity": 0.3, "heading_irregularity": 0.1, "jerk": 2.0}),
    ]  # fmt: skip
    with ResultsStore(tmp_path / "r.sqlite") as store:
        cid = store.campaign("c")
        for seed, (status, social) in enumerate(episodes):
            store.add_episode(
                cid, scenario="s", controller="law", seed=seed, status=status,
                metrics=_metrics(status, **social),
            )  # fmt: skip
        store.add_episode(cid, scenario="s", controller="other", seed=0, status="success",
                          metrics=_metrics("success"))  # fmt: skip
        rows = {r["controller"]: r for r in controller_summary(store, "c")}
    assert all(tuple(r) == SUMMARY_COLUMNS for r in rows.values())
    law = rows["law"]
    assert law["min_separation"] == -0.05
    assert law["too_close_frequency"] == pytest.approx(0.8 / 4)
    assert law["intrusion_time"] == pytest.approx(6.0 / 4)
    assert law["intrusion_ratio"] == pytest.approx(0.5 / 2)  # the episodes that have it
    assert law["path_irregularity"] == pytest.approx(1.5 / 4)
    assert law["pedestrian_collision_share"] == pytest.approx(2 / 3)
    # comfort: means over the episodes that have a value (no time to collision: never on course)
    assert law["personal_space_time"] == pytest.approx(2.0 / 2)
    assert law["min_time_to_collision"] == pytest.approx(2.0 / 2)
    assert law["heading_irregularity"] == pytest.approx(0.4 / 2)
    assert law["jerk"] == pytest.approx(6.0 / 2)
    other = rows["other"]  # no pedestrian, no turn recorded, no collision
    for col in ("min_separation", "too_close_frequency", "intrusion_time", "intrusion_ratio",
                "path_irregularity", "pedestrian_collision_share", "personal_space_time",
                "min_time_to_collision", "heading_irregularity", "jerk"):  # fmt: skip
        assert other[col] is None


def test_failure_rows_give_seed_and_cause(tmp_path: Path) -> None:
    """Every episode that did not succeed, sorted by its key, with who closed the gap or why."""
    with ResultsStore(tmp_path / "r.sqlite") as store:
        cid = store.campaign("c")
        add = store.add_episode
        add(cid, scenario="s/0003", controller="law", seed=3, status="collision",
            metrics=_metrics("collision", collision_by="robot"))  # fmt: skip
        add(cid, scenario="s/0001", controller="law", seed=1, status="success",
            metrics=_metrics("success"))  # fmt: skip
        add(cid, scenario="s/0002", controller="law", seed=2, status="collision",
            metrics=_metrics("collision", collision_by="pedestrian"))  # fmt: skip
        add(cid, scenario="s/0004", controller="law", seed=4, status="timeout",
            metrics=_metrics("timeout"))  # fmt: skip
        add(cid, scenario="s/0005", controller="law", seed=5, status="refused",
            error="speed bound 2 m/s >= V_max 1 m/s\nmore")  # fmt: skip
        rows = failure_rows(store, "c")
        assert failure_rows(store, "nothing") == []
    assert all(tuple(r) == FAILURE_COLUMNS for r in rows)
    assert [(r["seed"], r["cause"]) for r in rows] == [
        (2, "pedestrian-driven"),
        (3, "robot-driven"),
        (4, "timeout"),
        (5, "refused: speed bound 2 m/s >= V_max 1 m/s"),
    ]
    assert rows[0]["min_clearance"] == 0.1 and rows[-1]["min_clearance"] is None


def _paired_counts(a: np.ndarray, b: np.ndarray) -> tuple[int, int, int, int]:
    return (int(np.sum(a & ~b)), int(np.sum(~a & b)), int(np.sum(a & b)), int(np.sum(~a & ~b)))


@pytest.mark.parametrize(("p_a", "p_b", "rho"), [(0.85, 0.83, 0.3), (0.97, 0.90, 0.0)])
def test_paired_difference_interval_covers_the_true_difference(
    p_a: float, p_b: float, rho: float
) -> None:
    """Newcombe's paired interval covers the true difference about 95 % of the time: 1,000
    seeded draws of 390 correlated pairs (a shared uniform for a share ``rho`` of the cases)."""
    rng = np.random.default_rng(0)
    covered = 0
    for _ in range(1000):
        shared = rng.random(390) < rho
        u = rng.random(390)
        a = np.where(shared, u, rng.random(390)) < p_a
        b = np.where(shared, u, rng.random(390)) < p_b
        diff, lo, hi = paired_difference_interval(*_paired_counts(a, b))
        assert lo <= diff <= hi
        covered += lo <= p_a - p_b <= hi
    assert 0.93 <= covered / 1000 <= 0.975


@given(st.lists(st.tuples(st.booleans(), st.booleans()), min_size=1, max_size=60))
def test_paired_difference_interval_swaps_with_its_sides(pairs: list[tuple[bool, bool]]) -> None:
    """Swapping A and B negates the difference and mirrors the interval, inside [-1, 1]."""
    a = np.array([p[0] for p in pairs])
    b = np.array([p[1] for p in pairs])
    diff, lo, hi = paired_difference_interval(*_paired_counts(a, b))
    back, lo_b, hi_b = paired_difference_interval(*_paired_counts(b, a))
    assert -1.0 <= lo <= diff <= hi <= 1.0
    assert back == pytest.approx(-diff)
    assert lo_b == pytest.approx(-hi) and hi_b == pytest.approx(-lo)
