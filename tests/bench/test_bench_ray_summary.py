"""``benchmarks/summary.py``'s Ray row and ``benchmarks/bench_ray.py``'s pure helpers (no
benchmark is run)."""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path
from typing import Any

import pytest

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))

import bench_ray  # noqa: E402
import summary  # noqa: E402


def _write(folder: Path, payload: dict[str, Any]) -> None:
    (folder / "ray.json").write_text(json.dumps(payload), encoding="utf-8")


def test_ray_row(tmp_path: Path) -> None:
    assert summary.ray_row(tmp_path).result == "not run"
    full = {"episodes": 10_000}
    _write(tmp_path, {"quick": False, "ray_engine": full,
                      "target": {"measured": 0.042, "limit": 0.1, "pass": True}})  # fmt: skip
    row = summary.ray_row(tmp_path)
    assert (row.measured, row.ratio, row.result) == ("4.20 %", "0.42", "PASS")
    assert row.name in [r.name for r in summary.build_rows(tmp_path)]
    # fewer episodes than the issue's campaign: the workers' warm-up weighs more, a smoke run
    _write(tmp_path, {"quick": False, "ray_engine": {"episodes": 2_000},
                      "target": {"measured": 0.042, "limit": 0.1, "pass": True}})  # fmt: skip
    assert summary.ray_row(tmp_path).result == "PASS*"
    _write(tmp_path, {"quick": True, "target": {"measured": 0.25, "limit": 0.1, "pass": False}})
    assert summary.ray_row(tmp_path).result == "FAIL*"
    _write(tmp_path, {"quick": False, "target": {"measured": None, "limit": 0.1, "pass": None,
                                                 "note": "ray not installed"}})  # fmt: skip
    row = summary.ray_row(tmp_path)
    assert (row.measured, row.result) == ("-", "not measured")
    (tmp_path / "ray.json").write_text("{not json", encoding="utf-8")
    assert summary.ray_row(tmp_path).result == "not run"


def test_judge_compares_ray_with_the_pool() -> None:
    def run(cpu: float | None, jobs_ms: float, overhead_ms: float) -> dict[str, Any]:
        return {"episodes": 100, "cpu_s": cpu, "jobs_cpu_ms_per_episode": jobs_ms,
                "overhead_ms_per_episode": overhead_ms, "startup": {"cpu_s": 3.0}}  # fmt: skip

    inproc, pool = run(2.0, 20.0, 0.1), run(2.1, 20.2, 0.8)
    got = bench_ray.judge(inproc, pool, run(2.2, 20.4, 1.6))
    assert got["ray_added_cpu_ms"] == pytest.approx(1.0)  # (2.2 - 2.1) CPU-s over 100 episodes
    assert got["of_which_overhead_ms"] == pytest.approx(0.8)
    assert got["of_which_jobs_ms"] == pytest.approx(0.2)
    assert got["ray_added_with_startup_ms"] == pytest.approx(1.0 + 30.0)
    assert got["measured"] == pytest.approx(0.05) and got["pass"] is True
    assert bench_ray.judge(inproc, run(None, 20.0, 0.8), run(2.2, 20.4, 1.6))["pass"] is None


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="reads /proc")
def test_tree_snapshot_sees_this_process() -> None:
    snap = bench_ray.tree_snapshot()
    assert snap is not None and os.getpid() in snap
    roles = bench_ray.by_role(snap, bench_ray.tree_snapshot(), "ray")
    assert roles is not None and roles.get("driver", 0.0) >= 0.0
