"""Decision time of ``zhang2019-v2`` among many bodies (issue 19: <= 200 µs CPU with 100 in range).

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/bench_zhang2019_v2.py`` (``--quick`` for a smoke
run, ``--out DIR`` writes ``DIR/zhang2019_v2.json``).

Two scenes, side by side in one run, each with 10 and 100 bodies in sensing range, 16 robot poses
cycled, time advancing by the decision period; the first decisions (imports, numba's compile or
cache load) are discarded; CPU time of the calling thread per ``act`` call:

* ``crowd``: pedestrians (discs of radius 0.3 m walking at 0.5-1.5 m/s in random directions)
  uniformly within 8 m of the robot — the crowd the law is for (the target);
* ``polygons``: the moving, rotating non-convex polygons 1-4.5 m around the robot of the decision
  benchmark (``run_benchmarks.py``: ``decision_observations``) — a far denser scene, reported for
  comparison.

Both the compiled path (numba, the ``fast`` extra) and the numpy reference are timed, and
``zhang2019-v1`` beside them.  Prints target, measured, ratio and PASS/FAIL.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

from run_benchmarks import CH2_SPEC, decision_observations, machine_info

from uvnav.controllers.base import make_controller
from uvnav.geometry.kernels3d import use_compiled
from uvnav.sensors.observation import Observation, ObstacleReading

TARGET_US = 200.0
COUNTS = (10, 100)


def crowd_observations(
    n: int, n_calls: int, *, n_poses: int = 16, seed: int = 0
) -> list[Observation]:
    """``n`` walking pedestrians within 8 m of the robot, seen exactly (discs, nearest first)."""
    rng = np.random.default_rng(seed)
    out = []
    poses = []
    for _ in range(n_poses):
        r = 0.9 + 7.1 * np.sqrt(rng.uniform(0.0, 1.0, n))
        a = rng.uniform(-math.pi, math.pi, n)
        centre = np.column_stack([r * np.cos(a), r * np.sin(a)])
        speed = rng.uniform(0.5, 1.5, n)
        course = rng.uniform(-math.pi, math.pi, n)
        vel = speed[:, None] * np.column_stack([np.cos(course), np.sin(course)])
        order = np.argsort(r)
        readings = tuple(
            ObstacleReading(
                obstacle_id=int(k),
                distance=float(r[k] - 0.3),
                nearest_point=centre[k] * (1.0 - 0.3 / r[k]),
                centre=centre[k],
                velocity=vel[k],
                angular_velocity=0.0,
                outline=np.zeros((0, 2)),
                radius=0.3,
                bounding_radius=0.3,
            )
            for k in order
        )
        poses.append((np.array([0.0, 0.0, rng.uniform(-math.pi, math.pi)]), readings))
    for i in range(n_calls):
        pose, readings = poses[i % n_poses]
        out.append(Observation(time=0.25 * i, pose=pose, speed=0.8, goal=np.array([10.0, 10.0]),
                               obstacles=readings))  # fmt: skip
    return out


def time_law(name: str, observations: list[Observation], warmup: int) -> dict[str, float]:
    """Median and p99 CPU time [µs] of ``act`` over ``observations`` after ``warmup`` calls."""
    ctrl = make_controller(name)
    ctrl.reset(CH2_SPEC, observations[0].goal, np.random.default_rng(0))
    samples = []
    for i, obs in enumerate(observations):
        tic = time.thread_time_ns()
        ctrl.act(obs)
        if i >= warmup:
            samples.append((time.thread_time_ns() - tic) / 1e3)
    arr = np.asarray(samples)
    return {"median_us": float(np.median(arr)), "p99_us": float(np.percentile(arr, 99)),
            "calls": len(arr)}  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="few calls: smoke run")
    ap.add_argument("--out", type=Path, help="write zhang2019_v2.json here")
    args = ap.parse_args(argv)
    n_calls, warmup = (120, 20) if args.quick else (2000, 100)
    scenes = {"crowd": crowd_observations, "polygons": decision_observations}
    results: dict[str, Any] = {}
    for scene, make in scenes.items():
        for n in COUNTS:
            obs = make(n, n_calls + warmup, seed=n)
            row: dict[str, Any] = {}
            for path in ("compiled", "numpy"):
                use_compiled(path == "compiled")
                row[f"zhang2019-v2 {path}"] = time_law("zhang2019-v2", obs, warmup)
            use_compiled(True)
            row["zhang2019-v1"] = time_law("zhang2019-v1", obs, warmup)
            results[f"{scene}-{n}"] = row
    measured = results["crowd-100"]["zhang2019-v2 compiled"]["median_us"]
    target = {"what": "zhang2019-v2 median decision CPU time, 100 pedestrians in range [µs]",
              "limit": TARGET_US, "measured": measured, "ratio": measured / TARGET_US,
              "pass": measured <= TARGET_US}  # fmt: skip
    print(f"{'scene':14s} {'law / path':24s} {'median µs':>10s} {'p99 µs':>10s}")
    for key, row in results.items():
        for law, t in row.items():
            print(f"{key:14s} {law:24s} {t['median_us']:10.1f} {t['p99_us']:10.1f}")
    verdict = "PASS" if target["pass"] else "FAIL"
    print(f"target: {target['what']} <= {TARGET_US:.0f}: measured {measured:.1f} "
          f"(ratio {target['ratio']:.2f}) {verdict}")  # fmt: skip
    if args.out:
        args.out.mkdir(parents=True, exist_ok=True)
        payload = {"machine": machine_info(), "quick": args.quick, "results": results,
                   "targets": {"zhang2019_v2_decision_us_median_100": target}}  # fmt: skip
        (args.out / "zhang2019_v2.json").write_text(json.dumps(payload, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
