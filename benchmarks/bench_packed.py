"""Packed worlds (issue 20 items 1 and 3): the compiled world step and the batched Nav2D env.

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/bench_packed.py [--quick] [--out DIR]``.

* ``world step``: one robot (constant command 0.707 m/s straight ahead) among N = 10 and 100
  moving non-convex polygons (``run_benchmarks.world_setup``: random-turn motion with arena
  steering and spin, the scene of ``world_steps`` and of the ir-sim comparison), advanced by
  :class:`uvnav.sim.packed.PackedWorlds` one decision (= one 0.1 s step) per call: obstacle
  motion, robot motion, exact clearance, arrival and collision tests.  Beside it, in the same
  run, the same scene through the one loop (``run_episode`` with ``straight-v1``, record off:
  the sensing and decision every step are extra work there).  CPU time (``process_time``),
  median of 5 repetitions of 3000 steps (600 with ``--quick``).  Targets: <= 3 us (10) and
  <= 15 us (100) per step.
* ``vector env``: ``gymnasium.make_vec("uvnav/Nav2D-v0", num_envs=256,
  vectorization_mode="vector_entry_point")`` on a ``random-ch2`` scene with 10 obstacles, a
  random policy (uniform actions from a seeded generator), autoreset on; env steps per CPU
  second of this process over 200 vector steps (40 with ``--quick``), median of 5.  Target:
  >= 100,000 env steps/s (the issue's, on 2 cores; this measures one).

Prints target, measured, ratio, PASS/FAIL; ``--out DIR`` writes ``DIR/packed.json``.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

from run_benchmarks import machine_info, world_setup

from uvnav.controllers import make_controller
from uvnav.scenarios.generators import generate
from uvnav.sim import run_episode
from uvnav.sim.packed import STATUS_NAMES, PackedWorlds

REPEATS = 5
#: us per step at 10 and 100 obstacles; env steps per CPU-second
TARGET_STEP_US = {10: 3.0, 100: 15.0}
TARGET_VEC = 100_000.0


def packed_step_us(n_obstacles: int, steps: int, seed: int) -> tuple[float, str]:
    """CPU us per packed step of ``world_setup(n_obstacles)``, and the final status."""
    worlds = PackedWorlds(1)
    worlds.load(0, world_setup(n_obstacles, steps, seed))
    worlds.command[0] = (0.707, 0.0)
    worlds.step()  # compiles (or loads the cache) before the clock starts
    cpu = time.process_time()
    for _ in range(steps - 1):
        worlds.step()
    cpu = time.process_time() - cpu
    return 1e6 * cpu / (steps - 1), STATUS_NAMES[int(worlds.status[0])]


def loop_step_us(n_obstacles: int, steps: int, seed: int) -> tuple[float, str]:
    """CPU us per step of the same scene through ``run_episode`` (straight-v1, record off)."""
    setup = world_setup(n_obstacles, steps, seed)
    cpu = time.process_time()
    res = run_episode(
        setup, make_controller("straight-v1"), np.random.default_rng(seed), record=False
    )
    return 1e6 * (time.process_time() - cpu) / steps, res.status


def vector_steps_per_s(num_envs: int, steps: int, seed: int) -> tuple[float, int]:
    """Env steps per CPU-second of the batched Nav2D env under a random policy, and the number
    of episodes that ended."""
    import gymnasium as gym

    import uvnav.envs  # noqa: F401 - registers the envs

    scene = generate("random-ch2", 3, n_obstacles=10)
    env = gym.make_vec("uvnav/Nav2D-v0", num_envs=num_envs,
                       vectorization_mode="vector_entry_point", scenario=scene)  # fmt: skip
    rng = np.random.default_rng(seed)
    env.reset(seed=seed)
    env.step(rng.uniform(-1, 1, (num_envs, 2)).astype(np.float32))  # compiled before timing
    ended = 0
    cpu = time.process_time()
    for _ in range(steps):
        _, _, term, trunc, _ = env.step(rng.uniform(-1, 1, (num_envs, 2)).astype(np.float32))
        ended += int(term.sum() + trunc.sum())
    cpu = time.process_time() - cpu
    env.close()
    return num_envs * steps / cpu, ended


def verdict(name: str, target: str, measured: str, ratio: float, ok: bool) -> dict[str, Any]:
    line = f"{name:<28} target {target:<14} measured {measured:<14} ratio {ratio:6.2f}"
    print(f"{line} {'PASS' if ok else 'FAIL'}")
    return {"name": name, "target": target, "measured": measured, "ratio": ratio, "pass": ok}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="shorter runs: a smoke test")
    ap.add_argument("--out", type=Path, help="write packed.json here")
    args = ap.parse_args()
    steps = 600 if args.quick else 3000
    vec_steps = 40 if args.quick else 200
    out: dict[str, Any] = {"machine": machine_info(), "quick": args.quick, "world_step": {}}
    rows = []
    for n in (10, 100):
        packed, loop = [], []
        for rep in range(REPEATS):  # alternating, so both sides see the same load
            us, status = packed_step_us(n, steps, rep)
            packed.append(us)
            lus, lstatus = loop_step_us(n, steps, rep)
            loop.append(lus)
            if status != "timeout" or lstatus != "timeout":
                raise SystemExit(f"world step {n}: the run ended early ({status}, {lstatus})")
        med, lmed = statistics.median(packed), statistics.median(loop)
        out["world_step"][str(n)] = {
            "packed_us": packed, "loop_us": loop, "packed_median_us": med,
            "loop_median_us": lmed, "speedup": lmed / med, "target_us": TARGET_STEP_US[n],
        }  # fmt: skip
        print(f"world step, {n} obstacles: packed {med:.2f} us, one loop {lmed:.1f} us "
              f"({lmed / med:.0f}x)")  # fmt: skip
        t = TARGET_STEP_US[n]
        rows.append(verdict(f"world step, {n} obstacles", f"<= {t:g} us", f"{med:.2f} us",
                            med / t, med <= t))  # fmt: skip
    rates, ended = [], 0
    for rep in range(REPEATS):
        rate, e = vector_steps_per_s(256, vec_steps, rep)
        rates.append(rate)
        ended += e
    rate = statistics.median(rates)
    out["vector_env"] = {"num_envs": 256, "steps": vec_steps, "env_steps_per_s": rates,
                         "median": rate, "episodes_ended": ended, "target": TARGET_VEC}  # fmt: skip
    print(f"vector env, K = 256, 10 obstacles: {rate:,.0f} env steps/CPU-s "
          f"({ended} episodes ended)")  # fmt: skip
    rows.append(verdict("vector env, K = 256", f">= {TARGET_VEC:,.0f}/s", f"{rate:,.0f}/s",
                        rate / TARGET_VEC, rate >= TARGET_VEC))  # fmt: skip
    out["targets"] = rows
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "packed.json").write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
