"""World steps per CPU second: ir-sim (optional peer) side by side with uvnav, in one run.

Scene: one unicycle / diff-drive robot driving straight along +x plus N moving non-convex polygon
obstacles wandering in an arena beside its path (N = 10 and 100), dt = 0.1 s, built by
``benchmarks/run_benchmarks.py``'s ``world_setup``.  uvnav runs it two ways, side by side: the
packed world step (``uvnav.sim.packed.PackedWorlds``, one compiled call a step, the robot on a
constant command; the side judged against the targets, when this uvnav has it) and the one loop
(``uvnav.sim.run_episode`` with ``zhang2019-v1`` and ``record=False``: sensing and a decision every
step on top; judged when there is no packed step), and that loop again deciding with
``straight-v1``, whose decision reads only the goal (the loop's own cost, reported beside).
Beside them, reported and not judged, the floor of any loop that asks a law written in Python
at every step: the compiled world step with sensing called from a bare Python ``for``, plus
``zhang2019-v1``'s ``act`` alone on the loop's observations (:func:`time_floor`); the loop
targets' records carry it as their note.
The ir-sim side is a YAML world generated at run time with *the same polygons* (same seed, same
``random_nonconvex`` bodies and start poses), the robot driven by a constant action ``[0.707, 0]``
and the obstacles on ir-sim's own ``dash`` + ``wander`` behavior (drive to a random goal in the
same arena, draw a new one on arrival). ir-sim runs headless (``headless=True``: no figure, no
rendering, no animation saving, no pauses).

Run (from the repository root)::

    .venv/bin/python benchmarks/peers/irsim_steps.py             # ~1 min
    .venv/bin/python benchmarks/peers/irsim_steps.py --quick     # smoke run, indicative only

Writes ``benchmarks/results/peers.json`` (``--out`` to change the folder) and prints a
table.  Timing: CPU time of the process (:func:`time.process_time`) around each episode's step
loop (building the world is not timed; a warm-up episode / step of each side is discarded);
``--repeats`` runs per side (default 5, seeds 0..), uvnav and ir-sim alternating run by run; the
figure of a side is the median over its runs of CPU µs per step.  uvnav runs 3000 steps an
episode; ir-sim 3000 with N = 10 and 1000 with N = 100, where it is slowest (``--irsim-steps`` to
change).  Both worlds are built from the 3000-step ``world_setup`` (same arena, same obstacle
density); with fewer steps the ir-sim robot just drives less far.

Targets (issue 20): a uvnav world step with 100 polygons <= 15 µs CPU and >= 1,000x ir-sim's
steps/s; with 10 polygons <= 3 µs.  Issue 37: the one loop >= 150x ir-sim's steps/s with 10
polygons and >= 600x with 100.  Without ir-sim the script says so in one line and records
``"available": false`` (the uvnav side is still measured: the absolute targets do not need ir-sim).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
from pathlib import Path
from typing import Any

os.environ.setdefault("MPLBACKEND", "Agg")

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/ -> run_benchmarks
sys.path.insert(0, str(HERE))  # peerstats

import peerstats  # noqa: E402
from peerstats import fmt  # noqa: E402

peerstats.single_threaded()

import numpy as np  # noqa: E402
from benchrecord import KEY, from_judged  # noqa: E402
from run_benchmarks import (  # noqa: E402
    CH2_SPEC,
    WORLD_COUNTS,
    _time_episode,
    machine_info,
    world_setup,
    write_json,
)

REPEATS = peerstats.MIN_REPEATS
UVNAV_STEPS = 3000
#: the uvnav sides: the packed world step (judged, when this uvnav has it) and the one loop
PACKED = "packed world step (uvnav.sim.packed.PackedWorlds, constant command)"
#: the law the loop side decides with (issue 37's general loop: sense, decide, advance)
LOOP_LAW = "zhang2019-v1"
LOOP = f"run_episode ({LOOP_LAW}, record off)"
#: the loop again with a law whose decision costs next to nothing (it reads only the goal): the
#: loop's own cost (sense, advance, bookkeeping) beside the law's, reported, not judged
BARE_LAW = "straight-v1"
BARE = f"run_episode ({BARE_LAW}, record off)"
DT = 0.1
IRSIM_STEPS = {10: 3000, 100: 1000}
#: --quick: steps per episode (uvnav, ir-sim) and repeats
QUICK = {"uvnav_steps": 500, "irsim_steps": 50, "repeats": 2}
#: issue 20's world-step targets: key -> (obstacles, what, limit, direction)
TARGETS: dict[str, tuple[int, str, float, str]] = {
    "world_step_us_100": (100, "uvnav CPU µs per world step, 100 polygons", 15.0, "<="),
    "world_step_us_10": (10, "uvnav CPU µs per world step, 10 polygons", 3.0, "<="),
    "vs_irsim_100": (100, "uvnav steps/s over ir-sim's, 100 polygons", 1000.0, ">="),
    "loop_vs_irsim_10": (10, "run_episode steps/s over ir-sim's, 10 polygons", 150.0, ">="),
    "loop_vs_irsim_100": (100, "run_episode steps/s over ir-sim's, 100 polygons", 600.0, ">="),
}
#: what each side does per step, by target (benchrecord's ``work``)
WORK = {
    "vs_irsim_100": "uvnav: the packed world step, one compiled call (every obstacle's motion, "
    "the robot on a constant command, clearance; no sensing, no law); ir-sim: EnvBase.step "
    "(every obstacle's behaviour and kinematics, the robot's, STRtree rebuild, collision query)",
    "loop": "uvnav: run_episode (every obstacle's motion, field rebuild, the robot's step and "
    "collision check, sensing within 8 m, a zhang2019-v1 decision); ir-sim: EnvBase.step (every "
    "obstacle's behaviour and kinematics, the robot's, STRtree rebuild, collision query)",
}


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
    """One ir-sim episode of ``n_steps`` steps: CPU s of the step loop and the end state."""
    import irsim

    path = tmp / f"irsim_{n_obstacles}_{seed}.yaml"
    path.write_text(irsim_world_yaml(n_obstacles, scene_steps, seed))
    env = irsim.make(
        str(path), headless=True, display=False, save_ani=False, log_level="WARNING", seed=seed
    )
    try:
        n_obs = len(env.obstacle_list)
        action = np.array([[CH2_SPEC.v_max], [0.0]])
        env.step(action)  # warm-up (first-call imports, caches), not timed
        cpu0 = peerstats.cpu_s()
        for _ in range(n_steps):
            env.step(action)
        cpu = peerstats.cpu_s() - cpu0
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
    return {"seed": seed, "steps": n_steps, "cpu_s": cpu, **status}


def time_uvnav(n_obstacles: int, n_steps: int, seed: int, law: str = LOOP_LAW) -> dict[str, Any]:
    """One uvnav episode of ``n_steps`` steps (``law``, record off): CPU s, status."""
    wall, res, cpu = _time_episode(
        lambda: world_setup(n_obstacles, n_steps, seed), law, seed, False
    )
    return {"seed": seed, "steps": n_steps, "cpu_s": cpu, "wall_s": wall, "status": res.status}


def packed_available() -> bool:
    """Whether this uvnav has the compiled packed world step (:mod:`uvnav.sim.packed`)."""
    try:
        from uvnav.sim.packed import PackedWorlds  # noqa: F401
    except ImportError:
        return False
    return True


def time_packed(n_obstacles: int, n_steps: int, seed: int) -> dict[str, Any]:
    """One packed world (:class:`uvnav.sim.packed.PackedWorlds`, one slot) of the same scene,
    the robot on a constant command (0.707 m/s straight ahead), ``n_steps`` steps: CPU s of the
    step loop (the first step, which compiles or loads the kernels, is not timed), status."""
    from uvnav.sim.packed import STATUS_NAMES, PackedWorlds

    worlds = PackedWorlds(1)
    worlds.load(0, world_setup(n_obstacles, n_steps, seed))
    worlds.command[0] = (CH2_SPEC.v_max, 0.0)
    worlds.step()  # not timed: compiles (or loads the cache)
    cpu0 = peerstats.cpu_s()
    for _ in range(n_steps - 1):
        worlds.step()
    cpu = peerstats.cpu_s() - cpu0
    status = STATUS_NAMES[int(worlds.status[0])]
    return {"seed": seed, "steps": n_steps - 1, "cpu_s": cpu, "status": status}


def time_floor(n_obstacles: int, n_steps: int, seed: int, law: str = LOOP_LAW) -> dict[str, Any]:
    """What no loop that asks a Python law at every step can go below, on the loop's scene:
    CPU µs per step of (a) the world's compiled step with sensing, called from a bare Python
    loop (:class:`~uvnav.sim.bodies2d.PackedBodies.measure`: every obstacle's motion, the
    clearance and the readings within 8 m, in one call; the robot moved on a constant command
    by two lines of Python) and (b) ``law``'s ``act`` alone, on the observations the loop gave
    it over the first ``n_steps // 10`` steps of the same episode (replayed in order, in a
    bare ``for``)."""
    from uvnav.controllers.base import make_law
    from uvnav.core import BaseProbe
    from uvnav.sim.episode import World2D
    from uvnav.sim.run import run_episode

    world = World2D(world_setup(n_obstacles, n_steps, seed), np.random.default_rng(seed),
                    exact=False, packed=True)  # fmt: skip
    bodies, radius = world.bodies, float(CH2_SPEC.radius)
    x, t, step = 0.0, 0.0, CH2_SPEC.v_max * DT
    bodies.measure(t, DT, x, 0.0, radius, 8.0)  # not timed: compiles (or loads the cache)
    cpu0 = peerstats.cpu_s()
    for _ in range(n_steps - 1):
        x += step
        t += DT
        bodies.measure(t, DT, x, 0.0, radius, 8.0)
    world_us = (peerstats.cpu_s() - cpu0) / (n_steps - 1) * 1e6

    class Keep(BaseProbe):
        def __init__(self) -> None:
            self.seen: list[Any] = []

        def on_decision(self, world: Any, agent: int, law: Any, obs: Any, applied: Any) -> None:
            self.seen.append(obs)

    keep, short = Keep(), max(n_steps // 10, 2)
    run_episode(world_setup(n_obstacles, short, seed), make_law(law),
                np.random.default_rng(seed), record=False, probes=[keep])  # fmt: skip
    actor = make_law(law)
    spec, goal, rng = world.law_setup()
    actor.reset(spec, goal, rng)
    actor.act(keep.seen[0])  # not timed: the first decision's warm-up
    cpu0 = peerstats.cpu_s()
    for obs in keep.seen:
        actor.act(obs)
    act_us = (peerstats.cpu_s() - cpu0) / len(keep.seen) * 1e6
    return {"seed": seed, "world_sense_us": world_us, "act_us": act_us,
            "floor_us": world_us + act_us}  # fmt: skip


def floor_summary(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """The medians over ``runs`` of :func:`time_floor`'s parts [µs per step]."""
    med = {k: float(np.median([r[k] for r in runs])) for k in ("world_sense_us", "act_us")}
    return {**med, "floor_us": med["world_sense_us"] + med["act_us"], "law": LOOP_LAW,
            "runs": runs}  # fmt: skip


def floor_note(row: dict[str, Any]) -> str | None:
    """The floor of a loop that asks a Python law at every step, as a record's note."""
    floor, ratio = row.get("floor"), row.get("ratio_floor_over_irsim")
    if floor is None or ratio is None:
        return None
    return (
        f"no loop can beat {ratio:,.0f}x here: the compiled world and sensing step "
        f"({floor['world_sense_us']:.2f} µs) plus the law's act alone "
        f"({floor['act_us']:.2f} µs) take {floor['floor_us']:.2f} µs a step"
    )


def targets(results: dict[str, Any]) -> dict[str, Any]:
    """Issue 20's world-step targets judged on the medians in ``results`` (keyed by N)."""
    out: dict[str, Any] = {}
    for key, (n, what, limit, direction) in TARGETS.items():
        row = results.get(str(n), {})
        note = None
        if key.startswith("vs_irsim"):
            measured = row.get("ratio_uvnav_over_irsim")
        elif key.startswith("loop_vs_irsim"):  # the loop is the judged side without packed
            measured = row.get("ratio_loop_over_irsim", row.get("ratio_uvnav_over_irsim"))
            note = floor_note(row)
        else:
            measured = row.get("uvnav", {}).get("median_us_per_step")
        out[key] = {"what": what, **peerstats.judge(measured, limit, direction)}
        if measured is None and "vs_irsim" in key:
            out[key]["note"] = "ir-sim not available: not measured"
        elif note is not None:
            out[key]["note"] = note
    return out


# --------------------------------------------------------------------------------------------


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=HERE.parent / "results")
    ap.add_argument("--irsim-steps", type=int, default=None, help="default: 3000 / 1000 steps")
    ap.add_argument("--uvnav-steps", type=int, default=None, help=f"default: {UVNAV_STEPS}")
    ap.add_argument("--repeats", type=int, default=None, help=f"runs per side (default {REPEATS})")
    ap.add_argument("--quick", action="store_true", help="short smoke run, indicative only")
    args = ap.parse_args(argv)
    uv_steps = args.uvnav_steps or (QUICK["uvnav_steps"] if args.quick else UVNAV_STEPS)
    repeats = args.repeats or (QUICK["repeats"] if args.quick else REPEATS)

    info = machine_info()
    try:
        import irsim

        info["irsim"] = irsim.__version__
        available = True
    except ImportError:
        print("ir-sim is not installed: its side is not measured (pip install -e '.[peers]')")
        available = False
    packed = packed_available()

    results: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="uvnav_peers_") as tmpdir:
        tmp = Path(tmpdir)
        for n in WORLD_COUNTS:
            ir_steps = args.irsim_steps or (
                QUICK["irsim_steps"] if args.quick else IRSIM_STEPS.get(n, 300)
            )
            time_uvnav(n, 20, 99)  # warm-up episodes, discarded
            if packed:
                time_packed(n, 20, 99)
            ir_runs: list[dict[str, Any]] = []
            loop_runs: list[dict[str, Any]] = []
            bare_runs: list[dict[str, Any]] = []
            floor_runs: list[dict[str, Any]] = []
            packed_runs: list[dict[str, Any]] = []
            for r in range(repeats):  # interleaved so drifting machine load hits every side
                if available:
                    ir_runs.append(time_irsim(n, ir_steps, uv_steps, r, tmp))
                if packed:
                    packed_runs.append(time_packed(n, uv_steps, r))
                loop_runs.append(time_uvnav(n, uv_steps, r))
                bare_runs.append(time_uvnav(n, uv_steps, r, BARE_LAW))
                floor_runs.append(time_floor(n, uv_steps, r))
            loop = {"side": LOOP, **peerstats.summarize(loop_runs), "runs": loop_runs}
            bare = {"side": BARE, **peerstats.summarize(bare_runs), "runs": bare_runs}
            row: dict[str, Any] = {"irsim": {"available": False}}
            if packed:
                row["uvnav"] = {"side": PACKED, **peerstats.summarize(packed_runs)}
                row["uvnav"]["runs"] = packed_runs
                row["uvnav_loop"] = loop
                row["uvnav_loop_bare"] = bare
                row["floor"] = floor_summary(floor_runs)
            else:
                row["uvnav"] = loop
            uv = row["uvnav"]
            judged_runs = packed_runs or loop_runs
            if available:
                ir = {"steps": ir_steps, **peerstats.summarize(ir_runs), "runs": ir_runs}
                row["irsim"] = ir
                row["ratio_uvnav_over_irsim"] = peerstats.ratio(
                    ir["median_us_per_step"], uv["median_us_per_step"]
                )
                row["ratio_by_round"] = [
                    peerstats.ratio(peerstats.us_per_step(a), peerstats.us_per_step(b))
                    for a, b in zip(ir_runs, judged_runs, strict=True)
                ]
                if packed:
                    row["ratio_loop_over_irsim"] = peerstats.ratio(
                        ir["median_us_per_step"], loop["median_us_per_step"]
                    )
                    row["ratio_loop_bare_over_irsim"] = peerstats.ratio(
                        ir["median_us_per_step"], bare["median_us_per_step"]
                    )
                    row["ratio_floor_over_irsim"] = peerstats.ratio(
                        ir["median_us_per_step"], row["floor"]["floor_us"]
                    )
            warnings = [
                f"uvnav run {i} ended early ({x['status']})"
                for i, x in enumerate(packed_runs + loop_runs + bare_runs)
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

    judged = targets(results)
    payload = {
        "benchmark": "peers_irsim",
        "description": "world steps per CPU second, 1 robot + N moving non-convex polygons, "
        "dt 0.1 s: ir-sim EnvBase.step (headless) vs uvnav's packed world step (judged, when this "
        f"uvnav has uvnav.sim.packed) and run_episode ({LOOP_LAW}, record off)",
        "available": available,
        "uvnav_judged": PACKED if packed else LOOP,
        "irsim": info.get("irsim"),
        "quick": args.quick,
        "machine": info,
        "params": {
            "dt": DT,
            "obstacle_counts": WORLD_COUNTS,
            "repeats": repeats,
            "statistic": "median over runs of CPU µs per step (time.process_time)",
            "seeds": list(range(repeats)),
        },
        "per_step": {
            "irsim": "behaviour velocity (dash to a wander goal) + kinematics for every obstacle, "
            "robot kinematics from the given action, STRtree rebuild over all objects, sensor "
            "step (none configured), one batched all-pairs shapely intersects query (collision "
            "status of every object; mode unobstructed_obstacles: only the robot stops), "
            "arrival/status bookkeeping",
            "uvnav packed": "one compiled call: obstacle motion (random turn, arena steering, "
            "spin) for every obstacle, robot unicycle step, exact clearance, arrival and "
            "collision tests; no sensing, no controller (a constant command)",
            "uvnav loop": "obstacle motion (RandomTurn) for every obstacle, ObstacleField rebuild, "
            "robot unicycle step, robot clearance/collision check, sensing within 8 m and a "
            f"{LOOP_LAW} decision every step",
            "uvnav loop, bare": f"the same loop deciding with {BARE_LAW} (it reads only the goal): "
            "the loop's own cost without the law's",
            "floor": "reported, not judged: the compiled world step with sensing called from a "
            f"bare Python loop, plus {LOOP_LAW}'s act alone on the loop's observations; what "
            "no loop that asks a Python law at every step can go below",
        },
        "results": results,
        "targets": judged,
        KEY: [
            from_judged(key, t, unit="x" if "vs_irsim" in key else " µs",
                        work=WORK.get(key, WORK["loop"] if key.startswith("loop") else ""))
            for key, t in judged.items()
        ],
    }  # fmt: skip
    path = write_json(args.out, "peers", payload)

    print(f"world step, CPU time, median of {repeats} runs" + (" (quick)" if args.quick else ""))
    print(f"uvnav judged: {PACKED if packed else LOOP}")
    head = f"{'N':>4} {'ir-sim µs/step':>15} {'uvnav µs/step':>14} {'uvnav/ir-sim':>13}"
    loop_head = f" {'loop µs/step':>13} {'loop/ir-sim':>12} {'bare µs':>8} {'floor µs':>9}"
    print(head + (loop_head if packed else ""))
    for n, row in results.items():
        ir_us = row.get("irsim", {}).get("median_us_per_step")
        ratio = row.get("ratio_uvnav_over_irsim")
        line = (
            f"{n:>4} {fmt(ir_us, 15, 1)} {fmt(row['uvnav']['median_us_per_step'], 14, 2)}"
            f" {fmt(ratio, 12, 2)}x"
        )
        if packed:
            loop_us = row["uvnav_loop"]["median_us_per_step"]
            line += f" {fmt(loop_us, 13, 1)} {fmt(row.get('ratio_loop_over_irsim'), 11, 2)}x"
            line += f" {fmt(row['uvnav_loop_bare']['median_us_per_step'], 8, 1)}"
            line += f" {fmt(row['floor']['floor_us'], 9, 2)}"
        print(line)
        for w in row.get("warnings", []):
            print(f"      warning: {w}")
    for key, t in judged.items():
        verdict = {True: "PASS", False: "FAIL", None: "not measured"}[t["pass"]]
        measured = fmt(t["measured"], 0, 2)
        print(f"target {key}: {t['direction']} {t['limit']:g}, measured {measured} -> {verdict}")
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
