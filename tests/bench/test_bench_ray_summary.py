"""``benchmarks/bench_ray.py``'s pure helpers (no benchmark is run; its row in the summary table:
``test_bench_results_summary.py``)."""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any

import pytest

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))

import bench_ray  # noqa: E402


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


def test_pooled_runs_are_summed_and_judged_per_episode_of_the_sum() -> None:
    def run(cpu: float, jobs: float, wall: float) -> dict[str, Any]:
        return {"episodes": 100, "statuses": {"success": 99, "collision": 1}, "wall_s": wall,
                "session_wall_s": 0.5, "cpu_s": cpu, "jobs_cpu_s": jobs,
                "cpu_s_by_process": {"driver": 0.1, "ray workers": cpu - 0.1},
                "startup": {"cpu_s": 3.0}}  # fmt: skip

    both = bench_ray.pooled(run(2.2, 2.0, 1.5), run(2.6, 2.2, 2.5))
    assert both["episodes"] == 200 and both["runs"] == 2
    assert both["statuses"] == {"collision": 2, "success": 198}
    assert both["cpu_s"] == pytest.approx(4.8) and both["episodes_per_s"] == pytest.approx(50.0)
    assert both["jobs_cpu_ms_per_episode"] == pytest.approx(21.0)
    assert both["overhead_ms_per_episode"] == pytest.approx(3.0)
    assert both["cpu_s_by_process"] == pytest.approx({"driver": 0.2, "ray workers": 4.6})
    inproc = {"cpu_s": 2.0, "jobs_cpu_ms_per_episode": 20.0}
    pool = bench_ray.pooled(run(2.1, 2.0, 1.0), run(2.1, 2.0, 1.0))
    got = bench_ray.judge(inproc, pool, both)
    assert got["ray_added_cpu_ms"] == pytest.approx(3.0)  # (4.8 - 4.2) CPU-s over 200
    assert got["ray_added_with_startup_ms"] == pytest.approx(3.0 + 30.0)  # 3 s a run of 100


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="reads /proc")
def test_tree_snapshot_sees_this_process() -> None:
    snap = bench_ray.tree_snapshot()
    assert snap is not None and os.getpid() in snap
    roles = bench_ray.by_role(snap, bench_ray.tree_snapshot(), "ray")
    assert roles is not None and roles.get("driver", 0.0) >= 0.0
