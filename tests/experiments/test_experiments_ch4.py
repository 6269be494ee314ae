"""Chapter-4 reproduction: episodes in the results store, resume, summary and failures from them."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from uvnav.bench.store import ResultsStore
from uvnav.experiments.ch4 import (
    HARD_CAMPAIGN,
    _table,
    ch4_job,
    failures,
    run_jobs,
    stored_rows,
    summarise,
    target_approach_check,
)
from uvnav.sim.episode_uuv2d import Uuv2dTrajectory
from uvnav.sim.metrics import METRIC_NAMES


def _run(modes: list[str]) -> Uuv2dTrajectory:
    """A straight run along y = x at 1 m/s, one decision every second with ``modes``."""
    t = np.arange(0.0, 6.01, 0.5)
    poses = np.column_stack([t / math.sqrt(2), t / math.sqrt(2), np.full_like(t, math.pi / 4)])
    return Uuv2dTrajectory(
        times=t, poses=poses, clearance=10.0 - t, decision_times=np.arange(0.0, 6.0, 1.0),
        outlines=[], commands=np.zeros((6, 2)), modes=modes, decisions=[],
    )  # fmt: skip


def test_fig47_target_approach_check_and_its_row() -> None:
    held = target_approach_check(_run(["M1"] * 5 + ["M2"]))
    assert held["target_approach"] == 1.0 and held["first_avoidance_s"] == 5.0
    assert held["x_m"] == held["y_m"] == 4.0 / math.sqrt(2) and held["clearance_m"] == 6.0
    broken = target_approach_check(_run(["M1", "M1", "M2", "M1", "M1", "M1"]))
    assert broken["target_approach"] == 0.0 and broken["first_avoidance_s"] == 2.0
    never = target_approach_check(_run(["M1"] * 6))
    assert math.isnan(never["first_avoidance_s"])
    (row,) = _table([], [], held)
    assert row["thesis"] == "t = 0...4 in target approach"
    assert row["measured"].startswith("held; at (2.83, 2.83) m at t = 4 s")
    assert _table([], [], broken)[0]["measured"].startswith("NOT held")
    assert _table([], []) == []


def test_jobs_are_stored_resumed_and_summarised(tmp_path: Path) -> None:
    jobs = [
        ch4_job("random-ch4:1", "zhang2022-uuv2d-v1", 1),
        ch4_job("random-ch4:1", "apf-uuv2d-v1", 1, noise_std=0.05),
    ]
    with ResultsStore(tmp_path / "uvnav.sqlite") as store:
        rows = run_jobs(jobs[:1], store, "ch4-random")
        assert store.count("ch4-random") == 1 and set(METRIC_NAMES) <= set(rows[0])
        calls: list[tuple[int, int]] = []
        rows = run_jobs(jobs, store, "ch4-random", progress=lambda k, n: calls.append((k, n)))
        assert calls == [(1, 1)]  # only the missing job ran
        assert store.count("ch4-random") == 2 and [r["law"] for r in rows] == [
            j.controller for j in jobs
        ]
        # the store's own columns: controller = law, params = the sensing level, family
        frame = store.episodes_frame("ch4-random")
        assert list(frame["controller"]) == ["zhang2022-uuv2d-v1", "apf-uuv2d-v1"]
        assert set(frame["family"]) == {"random-ch4"}
        assert '"noise_std":0.05' in frame["params"].iloc[1]
        again = stored_rows(store, "ch4-random")
    assert [(r["scene"], r["law"], r["seed"]) for r in again] == [
        (j.label, j.controller, j.seed) for j in jobs
    ]
    assert again[1]["key"] == "random-ch4:1|apf-uuv2d-v1|1|0.05|0"
    assert again[1]["noise_std"] == 0.05 and again[0]["n_obstacles"] >= 1
    assert again[0]["status"] == rows[0]["status"]
    assert again[0]["path_length"] == rows[0]["path_length"]
    summary = summarise(rows)
    assert {(s["family"], s["law"]) for s in summary} == {
        ("random-ch4", "zhang2022-uuv2d-v1"),
        ("random-ch4", "apf-uuv2d-v1"),
    }
    for s in summary:
        assert s["episodes"] == 1
        assert abs(s["success_rate"] + s["collision_rate"] + s["timeout_rate"] - 1.0) < 1e-12
    assert all(f["status"] != "success" for f in failures(rows, law=None))


def test_a_missing_campaign_has_no_rows(tmp_path: Path) -> None:
    with ResultsStore(tmp_path / "uvnav.sqlite") as store:
        assert stored_rows(store, HARD_CAMPAIGN) == []


def test_a_store_written_by_the_chapter_s_former_job_type_is_resumed(tmp_path: Path) -> None:
    """Rows as the former ``Ch4Job``/``store_row`` wrote them: scenario = the scene label,
    params = the sensing level; the same episodes are skipped, not run again."""
    old_params = {"noise_std": 0.05, "dropout": 0.0}
    with ResultsStore(tmp_path / "uvnav.sqlite") as store:
        cid = store.campaign("ch4-noise", {"chapter": 4})
        store.add_episode(
            cid,
            scenario="random-ch4:3",
            controller="apf-uuv2d-v1",
            seed=3,
            status="timeout",
            params=old_params,
            metrics={m: None for m in METRIC_NAMES} | {"success": False, "collision": False},
            family="random-ch4",
            effective_params={**old_params, "n_obstacles": 4, "entered_forbidden": False},
            wall_time=1.5,
        )
        calls: list[tuple[int, int]] = []
        job = ch4_job("random-ch4:3", "apf-uuv2d-v1", 3, noise_std=0.05)
        rows = run_jobs([job], store, "ch4-noise", progress=lambda k, n: calls.append((k, n)))
        assert calls == [] and store.count("ch4-noise") == 1
    assert rows[0]["status"] == "timeout" and rows[0]["n_obstacles"] == 4
    assert rows[0]["key"] == "random-ch4:3|apf-uuv2d-v1|3|0.05|0"
