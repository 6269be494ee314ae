"""Chapter-4 reproduction: rows per episode, resume, summary and failures computed from them."""

from __future__ import annotations

from pathlib import Path

from uvnav.bench.reproduce_ch4 import (
    Ch4Job,
    failures,
    read_rows,
    run_jobs,
    summarise,
)
from uvnav.sim.metrics import METRIC_NAMES


def test_jobs_are_stored_resumed_and_summarised(tmp_path: Path) -> None:
    out = tmp_path / "ch4" / "episodes.jsonl"
    jobs = [
        Ch4Job("random-ch4:1", "zhang2022-uuv2d-v1", 1),
        Ch4Job("random-ch4:1", "apf-uuv2d-v1", 1),
    ]
    rows = run_jobs(jobs[:1], out)
    assert len(read_rows(out)) == 1 and set(METRIC_NAMES) <= set(rows[0])
    calls = []
    rows = run_jobs(jobs, out, progress=lambda k, n: calls.append((k, n)))
    assert calls == [(1, 1)]  # only the missing job ran
    assert len(read_rows(out)) == 2 and [r["law"] for r in rows] == [j.law for j in jobs]
    summary = summarise(rows)
    assert {s["law"] for s in summary} == {"zhang2022-uuv2d-v1", "apf-uuv2d-v1"}
    for s in summary:
        assert s["episodes"] == 1
        assert abs(s["success_rate"] + s["collision_rate"] + s["timeout_rate"] - 1.0) < 1e-12
    fails = failures(rows)
    assert all(f["status"] != "success" for f in fails)
