"""World steps per second: ir-sim (optional peer) side by side with uvnav, in one run.

Scene: one unicycle / diff-drive robot driving straight along +x plus N moving non-convex polygon
obstacles wandering in an arena beside its path (N = 10 and 100), dt = 0.1 s.  The uvnav side is
``benchmarks/run_benchmarks.py``'s ``world_setup`` run by ``uvnav.sim.run_episode`` with
``straight-v1`` and ``record=False``; the ir-sim side is a YAML world generated at run time with
*the same polygons* (same seed, same ``random_nonconvex`` bodies and start poses), the robot
driven by a constant action ``[0.707, 0]`` and the obstacles on ir-sim's own ``dash`` + ``wander``
behavior (drive to a random goal in the same arena, draw a new one on arrival).  ir-sim runs
headless (``headless=True``: no figure, no rendering, no animation saving, no pauses).

Run (from the repository root)::

    MPLBACKEND=Agg .venv/bin/python benchmarks/peers/irsim_steps.py

Writes ``benchmarks/results/peers.json`` (``--out`` to change the folder) and prints a table.
Both sides: best wall time of 3 runs, interleaved (uvnav: 3000 steps, as ``run_benchmarks.py``;
ir-sim: fewer steps because it is much slower, 1000 with N = 10 and 300 with N = 100, or
``--irsim-steps``), steps/s = steps / best wall time.  Both worlds are built from the 3000-step
``world_setup`` (same arena length, same obstacle density); the ir-sim robot just drives less far.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/ -> run_benchmarks

from run_benchmarks import (  # noqa: E402
    CH2_SPEC,
    WORLD_COUNTS,
    _time_episode,
    machine_info,
    world_setup,
    write_json,
)

REPEATS = 3
UVNAV_STEPS = 3000
DT = 0.1
IRSIM_STEPS = {10: 1000, 100: 300}


# --------------------------------------------------------------------------------------------
# ir-sim world


def irsim_world_yaml(n_obstacles: int, n_steps: int, seed: int) -> str:
    """A YAML world equivalent to ``world_setup(n_obstacles, n_steps, seed)``.

    The polygons and start poses are taken from uvnav's setup itself, so both simulators carry
    exactly the same bodies.  Obstacle motion differs by construction (uvnav: ``RandomTurn``,
    speed 0.1-0.4 m/s, |turn| <= 0.3 rad/s; ir-sim: ``dash`` to a random goal in the same arena,
    ``vel_max`` = [0.4, 0.3]); both are cheap per-obstacle velocity laws.
    """
    setup = world_setup(n_obstacles, n_steps, seed)
    length = max(40.0, CH2_SPEC.v_max * n_steps * DT + 10.0)
    arena_lo, arena_hi = [-5.0, 4.0, -math.pi], [length, 16.0, math.pi]
    lines = [
        "world:",
        f"  height: {20.0}",
        f"  width: {length + 10.0:.3f}",
        f"  step_time: {DT}",
        f"  sample_time: {DT}",
        "  offset: [-5, -2]",
        # robot collides with obstacles (and stops); obstacles pass through each other, as in uvnav
        "  collision_mode: 'unobstructed_obstacles'",
        "  control_mode: 'auto'",
        "",
        "robot:",
        "  - kinematics: {name: 'diff'}",
        f"    shape: {{name: 'circle', radius: {CH2_SPEC.radius}}}",
        "    state: [0, 0, 0]",
        f"    goal: [{length + 1000.0:.1f}, 0, 0]",
        f"    vel_max: [{CH2_SPEC.v_max}, {CH2_SPEC.u_max}]",
        f"    vel_min: [-{CH2_SPEC.v_max}, -{CH2_SPEC.u_max}]",
        "",
        "obstacle:",
    ]
    for ob in setup.obstacles:
        verts = ", ".join(f"[{x:.6f}, {y:.6f}]" for x, y in ob.body.vertices)
        px, py = ob.state.position
        lines += [
            "  - kinematics: {name: 'diff'}",
            f"    shape: {{name: 'polygon', vertices: [{verts}]}}",
            f"    state: [{px:.6f}, {py:.6f}, {ob.state.heading:.6f}]",
            "    vel_max: [0.4, 0.3]",
            "    vel_min: [-0.4, -0.3]",
            "    behavior: {name: 'dash', wander: true, "
            f"range_low: {arena_lo}, range_high: {arena_hi}}}",
        ]
    return "\n".join(lines) + "\n"


def time_irsim(
    n_obstacles: int, n_steps: int, scene_steps: int, seed: int, tmp: Path
) -> dict[str, Any]:
    import irsim

    path = tmp / f"irsim_{n_obstacles}_{seed}.yaml"
    path.write_text(irsim_world_yaml(n_obstacles, scene_steps, seed))
    env = irsim.make(
        str(path), headless=True, display=False, save_ani=False, log_level="WARNING", seed=seed
    )
    try:
        n_obs = len(env.obstacle_list)
        action = np.array([[CH2_SPEC.v_max], [0.0]])
        env.step(action)  # warm-up (first-call imports, caches)
        tic = time.perf_counter()
        for _ in range(n_steps):
            env.step(action)
        wall = time.perf_counter() - tic
        robot = env.robot
        status = {
            "robot_x": float(robot.state[0, 0]),
            "robot_collision": bool(robot.collision),
            "obstacles": n_obs,
            "obstacles_moved": int(
                sum(
                    np.linalg.norm(o.state[:2, 0] - o.trajectory[0][:2, 0]) > 1e-6
                    for o in env.obstacle_list
                )
            )
            if all(o.trajectory for o in env.obstacle_list)
            else None,
        }
    finally:
        env.end(0)
    return {"wall": wall, **status}


def time_uvnav(n_obstacles: int, n_steps: int, seed: int) -> dict[str, Any]:
    wall, res = _time_episode(
        lambda: world_setup(n_obstacles, n_steps, seed=seed), "straight-v1", seed, False
    )
    return {"wall": wall, "status": res.status}


# --------------------------------------------------------------------------------------------


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=HERE.parent / "results")
    ap.add_argument("--irsim-steps", type=int, default=None, help="default: 1000 / 300 steps")
    ap.add_argument("--uvnav-steps", type=int, default=UVNAV_STEPS)
    args = ap.parse_args(argv)

    try:
        import irsim
    except ImportError:
        print("ir-sim is not installed (install the 'bench' extra: pyrvo pulls it in)")
        return 1

    info = machine_info()
    info["irsim"] = irsim.__version__
    results: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="uvnav_peers_") as tmpdir:
        tmp = Path(tmpdir)
        for n in WORLD_COUNTS:
            ir_steps = args.irsim_steps or IRSIM_STEPS.get(n, 300)
            ir_runs, uv_runs = [], []
            for r in range(REPEATS):  # interleaved so drifting machine load hits both sides
                ir_runs.append(time_irsim(n, ir_steps, args.uvnav_steps, r, tmp))
                uv_runs.append(time_uvnav(n, args.uvnav_steps, r))
            ir_best = min(x["wall"] for x in ir_runs)
            uv_best = min(x["wall"] for x in uv_runs)
            ir_sps = ir_steps / ir_best
            uv_sps = args.uvnav_steps / uv_best
            row: dict[str, Any] = {
                "irsim": {
                    "steps": ir_steps,
                    "best_wall_s": ir_best,
                    "steps_per_s": ir_sps,
                    "us_per_step": 1e6 * ir_best / ir_steps,
                    "runs": ir_runs,
                },
                "uvnav": {
                    "steps": args.uvnav_steps,
                    "best_wall_s": uv_best,
                    "steps_per_s": uv_sps,
                    "us_per_step": 1e6 * uv_best / args.uvnav_steps,
                    "runs": uv_runs,
                },
                "ratio_uvnav_over_irsim": uv_sps / ir_sps,
            }
            warnings = [
                f"uvnav run {i} ended early ({x['status']})"
                for i, x in enumerate(uv_runs)
                if x["status"] != "timeout"
            ]
            warnings += [
                f"ir-sim run {i}: robot collided"
                for i, x in enumerate(ir_runs)
                if x["robot_collision"]
            ]
            if warnings:
                row["warnings"] = warnings
            results[str(n)] = row

    payload = {
        "benchmark": "peers_world_steps",
        "description": "world steps per second, 1 robot + N moving non-convex polygons, dt 0.1 s: "
        "ir-sim EnvBase.step (headless) vs uvnav run_episode (straight-v1, record off)",
        "machine": info,
        "params": {
            "dt": DT,
            "obstacle_counts": WORLD_COUNTS,
            "repeats": REPEATS,
            "measure": "best of repeats",
            "seeds": list(range(REPEATS)),
        },
        "per_step": {
            "irsim": "behaviour velocity (dash to a wander goal) + kinematics for every obstacle, "
            "robot kinematics from the given action, STRtree rebuild over all objects, sensor "
            "step (none configured), one batched all-pairs shapely intersects query (collision "
            "status of every object; mode unobstructed_obstacles: only the robot stops), "
            "arrival/status bookkeeping",
            "uvnav": "obstacle motion (RandomTurn) for every obstacle, ObstacleField rebuild, "
            "robot unicycle step, robot clearance/collision check, sensing within 8 m and a "
            "straight-v1 decision every step",
        },
        "results": results,
    }
    path = write_json(args.out, "peers", payload)

    print(f"{'N':>5} {'ir-sim steps/s':>15} {'uvnav steps/s':>15} {'uvnav/ir-sim':>13}")
    for n, row in results.items():
        print(
            f"{n:>5} {row['irsim']['steps_per_s']:>15.0f} {row['uvnav']['steps_per_s']:>15.0f}"
            f" {row['ratio_uvnav_over_irsim']:>13.2f}"
        )
        for w in row.get("warnings", []):
            print(f"      warning: {w}")
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
