"""D* Lite incremental replanning vs A* from scratch after a local map change (issue 9).

Run: ``.venv/bin/python benchmarks/bench_planners.py --out benchmarks/results`` (``--quick``: a
200x200 grid and 3 changes, indicative only).  Writes ``<out>/planners.json``.

Scene: a 500x500 8-connected grid (cell 0.1 m), 20 % of the cells occupied at random (seeded),
start near one corner, goal near the other.  D* Lite plans once; then, ``n_changes`` times, the
robot advances ``advance`` cells along its current path and a 3x3 obstacle appears on the path
``ahead`` cells in front of it (a newly sensed static obstacle, the hybrid controller's case).
Each time we measure, side by side on the same map: D* Lite's ``move_start`` + ``set_cells`` +
``compute`` (the replan), and A* (octile) from the robot's cell on the updated map from
scratch; both costs must agree.  Reported: CPU times [ms] (this thread's; wall times beside them,
``*_wall_ms``), vertex expansions, and the ratio of
A*'s time to D* Lite's (median over the changes).  Target: ratio >= 10.
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import statistics
import sys
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np

from uvnav.planners import DStarLite, astar

TARGET_RATIO = 10.0


def _clock() -> tuple[int, int]:
    """(wall, this thread's CPU) now [ns]: targets are judged on CPU time, wall is reported."""
    return time.perf_counter_ns(), time.thread_time_ns()


def _ms_since(tic: tuple[int, int]) -> tuple[float, float]:
    """(CPU, wall) milliseconds since ``tic``."""
    wall, cpu = _clock()
    return (cpu - tic[1]) / 1e6, (wall - tic[0]) / 1e6


def run(
    size: int, n_changes: int, seed: int = 0, advance: int = 25, ahead: int = 8
) -> dict[str, Any]:
    rng = np.random.default_rng(seed)
    occ = rng.random((size, size)) < 0.2
    start, goal = (5, 5), (size - 6, size - 20)
    occ[start] = occ[goal] = False
    res = 0.1
    tic = _clock()
    planner = DStarLite(occ, start, goal, resolution=res)
    planner.compute()
    initial_ms, initial_wall_ms = _ms_since(tic)
    initial_expanded = planner.expanded
    tic = _clock()
    first_astar = astar(occ, start, goal, resolution=res)
    initial_astar_ms, initial_astar_wall_ms = _ms_since(tic)
    changes = []
    path = planner.path()
    for _ in range(n_changes):
        if len(path.cells) <= advance + ahead + 2:
            break
        robot = (int(path.cells[advance][0]), int(path.cells[advance][1]))
        r, c = (int(v) for v in path.cells[advance + ahead])
        blob = [(r + dr, c + dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1)]
        before = planner.expanded
        tic = _clock()
        planner.move_start(robot)
        planner.set_cells(blob)
        cost = planner.compute()
        d_ms, d_wall = _ms_since(tic)
        d_exp = planner.expanded - before
        tic = _clock()
        ref = astar(planner.occupancy(), robot, goal, resolution=res)
        a_ms, a_wall = _ms_since(tic)
        if not math.isclose(cost, ref.cost, rel_tol=1e-9):
            raise AssertionError(f"D* Lite cost {cost} != A* cost {ref.cost}")
        changes.append(
            {
                "dstar_lite_ms": d_ms,
                "dstar_lite_wall_ms": d_wall,
                "dstar_lite_expanded": d_exp,
                "astar_ms": a_ms,
                "astar_wall_ms": a_wall,
                "astar_expanded": ref.expanded,
                "cost_m": cost,
                "ratio_time": a_ms / max(d_ms, 1e-6),
                "ratio_time_wall": a_wall / max(d_wall, 1e-6),
                "ratio_expanded": ref.expanded / max(d_exp, 1),
            }
        )
        path = planner.path()
    ratio = statistics.median(ch["ratio_time"] for ch in changes)
    return {
        "grid": [size, size],
        "resolution_m": res,
        "occupied_fraction": float(occ.mean()),
        "initial": {
            "dstar_lite_ms": initial_ms,
            "dstar_lite_wall_ms": initial_wall_ms,
            "dstar_lite_expanded": initial_expanded,
            "astar_ms": initial_astar_ms,
            "astar_wall_ms": initial_astar_wall_ms,
            "astar_expanded": first_astar.expanded,
        },
        "changes": changes,
        "median_ratio_time": ratio,
        "median_ratio_time_wall": statistics.median(ch["ratio_time_wall"] for ch in changes),
        "median_ratio_expanded": statistics.median(ch["ratio_expanded"] for ch in changes),
        "target": {
            "what": "A* from scratch CPU time / D* Lite replan CPU time",
            "limit": TARGET_RATIO,
            "direction": ">=",
        },
        "pass": ratio >= TARGET_RATIO,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("benchmarks/results"))
    ap.add_argument("--quick", action="store_true")
    args = ap.parse_args(argv)
    payload = run(200, 3) if args.quick else run(500, 8)
    payload["quick"] = args.quick
    payload["machine"] = {
        "python": sys.version.split()[0],
        "platform": platform.platform(),
        "numpy": np.__version__,
        "timestamp": datetime.now(UTC).isoformat(timespec="seconds"),
    }
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "planners.json").write_text(json.dumps(payload, indent=2))
    print(
        f"D* Lite replan vs A* from scratch on {payload['grid']}: median time ratio "
        f"{payload['median_ratio_time']:.1f}x (target >= {TARGET_RATIO:g}x), "
        f"expansions ratio {payload['median_ratio_expanded']:.1f}x"
    )
    return 0 if payload["pass"] else 1


if __name__ == "__main__":
    raise SystemExit(main())
