"""The Nav2D env under a random policy: the batched env (issue 20, item 3) and a single
``uvnav/Nav2D-v0``, env steps per CPU-second.

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/bench_vector_env.py [--quick] [--out DIR]
[--against DIR]``.

* Batched: ``gymnasium.make_vec("uvnav/Nav2D-v0", num_envs=256,
  vectorization_mode="vector_entry_point")`` (:class:`uvnav.envs.nav2d_vec.Nav2DVectorEnv`, K
  packed worlds of :mod:`uvnav.sim.packed`) over 200 vector steps (40 with ``--quick``), median
  of 5 runs.  Target: >= 100,000 env steps/s (the issue's, on 2 cores; this measures one).  The
  packed world step itself is timed beside ir-sim and the one loop by
  ``benchmarks/peers/irsim_steps.py``.
* Single: ``gymnasium.make("uvnav/Nav2D-v0")`` (:class:`uvnav.envs.nav2d.Nav2DEnv`, the default
  settings: collisions judged along each step, 32 lidar beams, ``info["uvnav"]`` with the
  observation a uvnav law would get) over 2,000 steps (300 with ``--quick``), reset when an
  episode ends, median of 5 runs.  Each step: the action checked and mapped to a command, the
  world's integration steps to the next decision (robot, obstacles, clearance, swept collision
  check, metrics), the reward, the observation vector (goal, speed, the lidar cast) and the info.
  ``--against DIR`` times the same in another uvnav source tree (a worktree of the release),
  both sides in worker processes, alternating rounds, and reports the speed-up (ratio of the
  medians); the issue's target is 10x.  It times the batched env (K = 256) the same way, side by
  side: target 2x.

Both on a ``random-ch2`` scene with 10 obstacles, uniform actions from a seeded generator, CPU
time of the process.  Prints target, measured, ratio, PASS/FAIL; ``--out DIR`` writes
``DIR/vector_env.json``.
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

from ab_worker import SourceTreeWorker, serve, source_dir
from run_benchmarks import machine_info

from uvnav.scenarios.generators import generate

REPEATS = 5
#: env steps per CPU-second
TARGET_VEC = 100_000.0
#: single env: steps/s over the baseline tree's (``--against``)
TARGET_SINGLE_SPEEDUP = 10.0
#: batched env (K = 256): steps/s over the baseline tree's (``--against``)
TARGET_VEC_SPEEDUP = 2.0
_HERE_SRC = Path(__file__).resolve().parents[1] / "src"


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


def single_steps_per_s(steps: int, seed: int) -> tuple[float, int]:
    """Steps per CPU-second of one ``uvnav/Nav2D-v0`` (default settings) under a random policy,
    reset when an episode ends, and the number of episodes that ended."""
    import gymnasium as gym

    import uvnav.envs  # noqa: F401 - registers the envs

    env = gym.make("uvnav/Nav2D-v0", scenario=generate("random-ch2", 3, n_obstacles=10))
    rng = np.random.default_rng(seed)
    env.reset(seed=seed)
    acts = rng.uniform(-1, 1, (steps + 100, 2)).astype(np.float32)
    for a in acts[:100]:  # compiled kernels loaded, caches warm, before timing
        if any(env.step(a)[2:4]):
            env.reset()
    ended = 0
    cpu = time.process_time()
    for a in acts[100:]:
        _, _, term, trunc, _ = env.step(a)
        if term or trunc:
            ended += 1
            env.reset()
    cpu = time.process_time() - cpu
    env.close()
    return steps / cpu, ended


def _job(job: dict[str, Any]) -> dict[str, Any]:
    """A worker's job: ``{"env": "single" | "vector", "steps": n, "seed": s}`` (``"num_envs"``
    for the vector env) -> ``{"rate": env steps per CPU-second, "ended": episodes ended}``."""
    steps, seed = int(job["steps"]), int(job["seed"])
    if job.get("env", "single") == "vector":
        rate, ended = vector_steps_per_s(int(job["num_envs"]), steps, seed)
    else:
        rate, ended = single_steps_per_s(steps, seed)
    return {"rate": rate, "ended": ended}


def side_by_side(job: dict[str, Any], against: Path) -> dict[str, Any]:
    """``job`` (:func:`_job`'s, without the seed) in ``against``'s uvnav and in this checkout's,
    alternately (each side in its own worker process, the order swapped every round),
    :data:`REPEATS` rounds with seeds 0, 1, ...; the rates, their medians and the speed-up."""
    sides = {
        "baseline": SourceTreeWorker(Path(__file__), source_dir(against), 120.0),
        "current": SourceTreeWorker(Path(__file__), _HERE_SRC, 120.0),
    }
    rates: dict[str, list[float]] = {name: [] for name in sides}
    try:
        for r in range(REPEATS):
            for name in list(sides) if r % 2 == 0 else list(reversed(sides)):
                out = sides[name].run({**job, "seed": r})
                if "error" in out:
                    raise SystemExit(f"{job.get('env', 'single')} env, {name}: {out['error']}")
                rates[name].append(out["rate"])
    finally:
        for w in sides.values():
            w.close()
    med = {name: statistics.median(v) for name, v in rates.items()}
    return {"sources": {name: w.uvnav for name, w in sides.items()}, "steps": job["steps"],
            "env_steps_per_s": rates, "median": med,
            "speedup": med["current"] / med["baseline"]}  # fmt: skip


def speedup_verdict(name: str, ab: dict[str, Any], target: float) -> dict[str, Any]:
    """Print the side-by-side medians of ``ab`` (:func:`side_by_side`) and judge its speed-up
    against ``target``."""
    med, speedup = ab["median"], ab["speedup"]
    print(f"{name} side by side: baseline {med['baseline']:,.0f}, current "
          f"{med['current']:,.0f} env steps/CPU-s")  # fmt: skip
    return verdict(f"{name} vs baseline", f">= {target:g}x", f"{speedup:.2f}x",
                   speedup / target, speedup >= target)  # fmt: skip


def verdict(name: str, target: str, measured: str, ratio: float, ok: bool) -> dict[str, Any]:
    line = f"{name:<28} target {target:<14} measured {measured:<14} ratio {ratio:6.2f}"
    print(f"{line} {'PASS' if ok else 'FAIL'}")
    return {"name": name, "target": target, "measured": measured, "ratio": ratio, "pass": ok}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="shorter runs: a smoke test")
    ap.add_argument("--out", type=Path, help="write vector_env.json here")
    ap.add_argument(
        "--against", type=Path, help="also time both envs in this uvnav tree, side by side"
    )
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        raise SystemExit(serve(_job))
    vec_steps, single_steps = (40, 300) if args.quick else (200, 2000)
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
    singles, ended = [], 0
    for rep in range(REPEATS):
        one, e = single_steps_per_s(single_steps, rep)
        singles.append(one)
        ended += e
    single = statistics.median(singles)
    out["single_env"] = {"steps": single_steps, "env_steps_per_s": singles, "median": single,
                         "episodes_ended": ended}  # fmt: skip
    print(f"single env, 10 obstacles: {single:,.0f} env steps/CPU-s ({ended} episodes ended)")
    out["targets"] = [verdict("vector env, K = 256", f">= {TARGET_VEC:,.0f}/s", f"{rate:,.0f}/s",
                              rate / TARGET_VEC, rate >= TARGET_VEC)]  # fmt: skip
    if args.against is not None:
        ab = side_by_side({"env": "single", "steps": single_steps}, args.against)
        out["single_env_ab"] = ab
        out["targets"].append(speedup_verdict("single env", ab, TARGET_SINGLE_SPEEDUP))
        vab = side_by_side({"env": "vector", "steps": vec_steps, "num_envs": 256}, args.against)
        out["vector_env_ab"] = {**vab, "num_envs": 256}
        out["targets"].append(speedup_verdict("vector env", vab, TARGET_VEC_SPEEDUP))
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "vector_env.json").write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
