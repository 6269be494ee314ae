"""The batched Nav2D env (issue 20, item 3): env steps per CPU-second under a random policy.

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/bench_vector_env.py [--quick] [--out DIR]``.

``gymnasium.make_vec("uvnav/Nav2D-v0", num_envs=256, vectorization_mode="vector_entry_point")``
(:class:`uvnav.envs.nav2d_vec.Nav2DVectorEnv`, K packed worlds of :mod:`uvnav.sim.packed`) on a
``random-ch2`` scene with 10 obstacles, a random policy (uniform actions from a seeded
generator), autoreset on: env steps per CPU second of this process over 200 vector steps (40 with
``--quick``), median of 5 runs.  Target: >= 100,000 env steps/s (the issue's, on 2 cores; this
measures one).  The packed world step itself is timed beside ir-sim and the one loop by
``benchmarks/peers/irsim_steps.py``.

Prints target, measured, ratio, PASS/FAIL; ``--out DIR`` writes ``DIR/vector_env.json``.
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

from run_benchmarks import machine_info

from uvnav.scenarios.generators import generate

REPEATS = 5
#: env steps per CPU-second
TARGET_VEC = 100_000.0


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
    ap.add_argument("--out", type=Path, help="write vector_env.json here")
    args = ap.parse_args()
    vec_steps = 40 if args.quick else 200
    out: dict[str, Any] = {"machine": machine_info(), "quick": args.quick}
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
    out["targets"] = [verdict("vector env, K = 256", f">= {TARGET_VEC:,.0f}/s", f"{rate:,.0f}/s",
                              rate / TARGET_VEC, rate >= TARGET_VEC)]  # fmt: skip
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "vector_env.json").write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
