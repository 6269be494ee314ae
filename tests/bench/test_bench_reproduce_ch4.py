"""Chapter-4 reproduction: episodes in the results store, resume, summary and failures from them."""

from __future__ import annotations

from pathlib import Path

from uvnav.bench.reproduce_ch4 import (
    HARD_CAMPAIGN,
    Ch4Job,
    failures,
    run_jobs,
    stored_rows,
    summarise,
)
from uvnav.bench.store import ResultsStore
from uvnav.sim.metrics import METRIC_NAMES


def test_jobs_are_stored_resumed_and_summarised(tmp_path: Path) -> None:
    jobs = [
        Ch4Job("random-ch4:1", "zhang2022-uuv2d-v1", 1),
        Ch4Job("random-ch4:1", "apf-uuv2d-v1", 1, noise_std=0.05),
    ]
    with ResultsStore(tmp_path / "uvnav.sqlite") as store:
        rows = run_jobs(jobs[:1], store, "ch4-random")
        assert store.count("ch4-random") == 1 and set(METRIC_NAMES) <= set(rows[0])
        calls: list[tuple[int, int]] = []
        rows = run_jobs(jobs, store, "ch4-random", progress=lambda k, n: calls.append((k, n)))
        assert calls == [(1, 1)]  # only the missing job ran
        assert store.count("ch4-random") == 2 and [r["law"] for r in rows] == [j.law for j in jobs]
        # the store's own columns: controller = law, params = the sensing level, family
        frame = store.episodes_frame("ch4-random")
        assert list(frame["controller"]) == ["zhang2022-uuv2d-v1", "apf-uuv2d-v1"]
        assert set(frame["family"]) == {"random-ch4"}
        assert '"noise_std":0.05' in frame["params"].iloc[1]
        again = stored_rows(store, "ch4-random")
    assert [r["key"] for r in again] == [j.key for j in jobs]
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
