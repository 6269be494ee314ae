"""Validation against CrowdNav's ORCA row (issue 18): ``orca-holonomic-v1`` on ``crowdnav-circle``.

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/bench_crowdnav.py --cases 500`` (``--out DIR``
writes ``DIR/crowdnav.json``).  Fewer cases are a sample of the 500 drawn by a generator seeded 0
(cases 0-99 alone are easier than the rest); ``--first F`` runs cases F, F + 1, ... instead.

The paper: Chen, Liu, Kreiss, Alahi, "Crowd-robot interaction: crowd-aware robot navigation with
attention-based deep reinforcement learning", ICRA 2019 (arXiv:1809.08835), Table I (invisible
robot, 5 ORCA humans, circle crossing, 500 test cases): ORCA success 0.43, collision 0.57, time
to goal 10.86 s.  Here: the same 500 test cases (``crowdnav-circle:0`` ... ``:499`` are CrowdSim's
test cases, :mod:`uvnav.scenarios.crowdnav`), the robot driven by ``orca-holonomic-v1`` with the
robot ORCA of CrowdNav (time horizon 5 s, neighbour distance 10 m, at most 10 neighbours,
reciprocal responsibility 0.5, combined radius 0.62 m: ``safety_margin`` 0.02).  Reported:
success / collision / timeout rates with 95 % Wilson intervals, the mean time to goal of the
successes, the mean intrusion ratio over the episodes (:mod:`uvnav.sim.social`: the share of
steps the robot spends on a visible human's 1.25 s constant-velocity forecast) with a 95 %
percentile bootstrap interval, the CPU time, and PASS when the paper's success rate 0.43 lies
inside our interval.  The v2 laws are held to their own targets (``--law``); any other law's run
reports its figures with no verdict and exits 0.

Options for the protocol study (defaults = the reproduction):

* ``--substeps K``: integrate every 0.25/K s (collision checked at every integration step; the
  robot and the crowd still decide every 0.25 s); CrowdNav checks the swept relative segment.
* ``--outcome crowdnav``: judge each episode as ``CrowdSim.step`` does, by a probe watching every
  decision: collision when the relative position swept over the step (the human's *previous*
  velocity against the robot's new one, from the positions at the step's start) comes within the
  radius sum; else success when the robot's position after the step is strictly within its
  radius of the goal; else on; the first of these events wins (the world's own end comes at or
  after it: a discrete overlap is a collision at CrowdSim's next step, whose swept segment starts
  inside; the time limit a timeout).  Needs ``--substeps 1``.
* ``--lidar BEAMS``: the robot senses the humans with a lidar alone (BEAMS beams over a full
  turn, 1 cm range noise, 5 m range: :mod:`uvnav.sensors.scan_bodies`), velocities estimated.
* ``--sampled``: judge collisions at the end of each step only (the world's judgement is along
  the whole step, :mod:`uvnav.sim.swept`, as CrowdSim's swept-segment test).
* ``--kinematics arc``: a unicycle law's robot turns on arcs (the thesis's) instead of CrowdNav's
  turn-then-move (``ActionRot``), the scenes' default.
* ``--accel A`` / ``--turn-accel B``: the unicycle robot changes its speed by at most A [m/s^2]
  and its turn rate by at most B [rad/s^2] (``UnicycleSpec.accel_max``, ``turn_accel_max``;
  default: at once).  Collisions the robot drove into (``collision_by`` ``robot``) are counted
  in every run.
* ``--sensing-range R``: the robot sees the humans within R [m] (CrowdNav's scenes: 20 m).
* ``--humans N``: N humans (0-1000) instead of CrowdNav's 5 (the scenes' ``n_humans``, the
  same case seeds).  A case whose humans CrowdSim's rule cannot place apart (20 humans on the
  4 m circle: a few cases) is left out and listed as ``unplaceable``; the rates are over the
  cases run.
* ``--rule crowd_dynamic``: the harder crowd of ``crowd-dynamic:<case>``
  (:mod:`uvnav.scenarios.crowd_dynamic`: 20 humans of random radius and speed who change goals at
  random times and on arrival, 6 m circle, 5 m sensing unless ``--sensing-range``) instead of
  CrowdNav's scenes; no paper figure or target applies (the verdict is ``no target``), cases run
  in order from ``--first`` (default 0), and ``--humans`` defaults to the scene's 20.
* ``--robot-visible``: the humans see the robot and avoid it as one more ORCA agent (CrowdNav's
  ``visible = true``; the scenes' ``robot_visible``) instead of walking as if it were not there;
  the test protocol's robot is invisible, so such a run reports no verdict.
* ``--control-period P``: the robot decides every P [s] (a whole multiple of the integration
  step ``0.25 / substeps``) instead of every 0.25 s; the humans still decide every 0.25 s.
* ``--pref crowdnav``: the robot's preferred velocity as CrowdNav's ORCA sets it (1 m/s toward
  the goal beyond 1 m, the gap within) instead of ``orca-holonomic-v1``'s (V_max, lowered to
  ``dist / period`` on the last step).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
from benchrecord import KEY, record

from uvnav.bench.summary import wilson_interval
from uvnav.cli.common import parse_params
from uvnav.cli.errors import CliError
from uvnav.controllers.base import ControllerParamsError, controller_info, make_law
from uvnav.controllers.holonomic import OrcaHolonomic
from uvnav.core import BaseProbe
from uvnav.scenarios import crowd_dynamic
from uvnav.scenarios.build import build_episode
from uvnav.scenarios.catalog import kinds
from uvnav.scenarios.crowd_dynamic import crowd_dynamic_scenario
from uvnav.scenarios.crowdnav import (
    CROWDNAV_ORCA_PARAMS,
    N_HUMANS,
    TIME_STEP,
    crowdnav_scenario,
)
from uvnav.scenarios.errors import FieldError, ScenarioError
from uvnav.scenarios.limits import check_timing
from uvnav.sim.run import run_episode

#: Chen et al. ICRA 2019, Table I, ORCA (invisible robot)
PAPER = {"success": 0.43, "collision": 0.57, "time_to_goal": 10.86}


class CrowdNavPrefOrca(OrcaHolonomic):
    """``orca-holonomic-v1`` with CrowdNav's preferred velocity (``ORCA.predict``: the unit
    vector toward the goal beyond 1 m, the gap within); otherwise the same query."""

    def preferred_velocity(self, position: np.ndarray, period: float) -> np.ndarray:
        gap = self._goal - position
        d = float(np.hypot(*gap))
        return np.asarray(gap / d if d > 1.0 else gap, dtype=float)


def _segment_distance(px: float, py: float, ex: float, ey: float) -> float:
    """Distance from the origin to the segment (px, py)-(ex, ey) [m]."""
    dx, dy = ex - px, ey - py
    dd = dx * dx + dy * dy
    s = 0.0 if dd == 0.0 else min(max(-(px * dx + py * dy) / dd, 0.0), 1.0)
    return math.hypot(px + s * dx, py + s * dy)


class CrowdSimOutcome(BaseProbe):
    """The outcome ``CrowdSim.step`` would give (``--outcome crowdnav``, module docstring)."""

    def __init__(self) -> None:
        self.status: str | None = None
        self.at: float | None = None

    def on_decision(self, world: Any, agent: int, law: Any, obs: Any, applied: Any) -> None:
        if self.status is not None:
            return
        x, y, dt = world.x, world.y, world.dt
        if hasattr(applied, "vx"):
            vx, vy = float(applied.vx), float(applied.vy)
        else:  # a unicycle: CrowdNav's rotate-then-move velocity over the step
            th = float(obs.heading) + float(applied.u) * dt
            vx, vy = float(applied.v) * math.cos(th), float(applied.v) * math.sin(th)
        r = float(world.spec.radius)
        pos, vel = world.field.centres, world.field.velocities
        for j, ob in enumerate(world.obstacles):
            px, py = float(pos[j, 0]) - x, float(pos[j, 1]) - y
            ex = px + (float(vel[j, 0]) - vx) * dt
            ey = py + (float(vel[j, 1]) - vy) * dt
            if _segment_distance(px, py, ex, ey) - float(ob.body.bounding_radius) - r < 0:
                self.status, self.at = "collision", world.t + dt
                return
        gx, gy = float(world.goal[0]), float(world.goal[1])
        if math.hypot(x + vx * dt - gx, y + vy * dt - gy) < r:
            self.status, self.at = "success", world.t + dt


#: issue 19's targets for the tangent law for crowds (success on the 500 circle-crossing cases)
TARGETS = {"zhang2019-holonomic-v2": 0.95, "zhang2019-v2": 0.90}
PAPER_LAW = "orca-holonomic-v1"


#: CrowdNav's test cases
TEST_CASES = 500
#: the harder crowd's rule (:mod:`uvnav.scenarios.crowd_dynamic`)
DYNAMIC = "crowd_dynamic"
#: the lidar of ``--lidar``: range noise std [m] and range [m] (also the sensing range)
LIDAR_NOISE, LIDAR_RANGE = 0.01, 5.0


class NoCaseError(ValueError):
    """No asked case could be built (every one unplaceable)."""


#: bootstrap resamples of the mean intrusion ratio's interval (generator seeded 0)
RESAMPLES = 2000


def mean_interval(values: list[float], resamples: int = RESAMPLES) -> dict[str, Any]:
    """The mean of ``values`` and its 95 % percentile bootstrap interval (``resamples`` means of
    resamples with replacement, drawn by a generator seeded 0); ``None`` figures when empty."""
    if not values:
        return {"mean": None, "ci95": [None, None], "episodes": 0}
    x = np.asarray(values, dtype=float)
    idx = np.random.default_rng(0).integers(0, len(x), size=(resamples, len(x)))
    lo, hi = np.percentile(x[idx].mean(axis=1), [2.5, 97.5])
    return {"mean": float(x.mean()), "ci95": [float(lo), float(hi)], "episodes": len(x)}


def case_numbers(cases: int, first: int | None) -> list[int]:
    """The cases to run: ``first`` .. ``first + cases - 1``, or (``first`` None) all 500 when
    ``cases`` is 500 or more, else a sample of them drawn by a generator seeded 0 (cases 0-99
    alone are easier than the rest: a quick run should be representative), in order."""
    if first is not None:
        return list(range(first, first + cases))
    if cases >= TEST_CASES:
        return list(range(cases))
    picked = np.random.default_rng(0).choice(TEST_CASES, size=cases, replace=False)
    return sorted(int(c) for c in picked)


def _cases_text(r: dict[str, Any]) -> str:
    """``cases 0..499 (500)`` or ``100 sampled cases of 500``, and the unplaceable ones."""
    asked, out = r["asked"], r["unplaceable"]
    left = f", {len(out)} unplaceable left out" if out else ""
    if r["first_case"] is None and asked < TEST_CASES:
        return f"{asked} sampled cases of {TEST_CASES}{left}"
    first = r["first_case"] or 0
    return f"cases {first}..{first + asked - 1} ({asked}){left}"


def run(
    cases: int,
    *,
    rule: str,
    substeps: int,
    pref: str,
    outcome: str = "uvnav",
    first: int | None = None,
    law_name: str = PAPER_LAW,
    kinematics: str = "turn-then-move",
    swept: bool = True,
    lidar: int | None = None,
    accel: float | None = None,
    turn_accel: float | None = None,
    humans: int | None = None,
    sensing_range: float | None = None,
    law_params: dict[str, Any] | None = None,
    robot_visible: bool = False,
    control_period: float | None = None,
) -> dict[str, Any]:
    """Run the cases; returns the counts, rates, intervals and times.  ``law_params``: the
    parameters of a law other than the paper's (its defaults where not given);
    ``robot_visible``, ``control_period``: the module docstring's ``--robot-visible`` and
    ``--control-period``."""
    rng_of = kinds()["nav2d"].episode_rng
    vehicle = controller_info(law_name).vehicle
    counts = {"success": 0, "collision": 0, "timeout": 0}
    times: list[float] = []
    intrusion: list[float] = []
    statuses: list[str] = []
    collided_by: list[str | None] = []
    unplaceable: list[int] = []
    cpu0, wall0 = time.process_time(), time.perf_counter()
    if rule == DYNAMIC and first is None:
        first = 0  # the harder crowd has no fixed case list to sample
    for case in case_numbers(cases, first):
        sensing: dict[str, Any] = (
            {"bodies": "lidar", "lidar_beams": lidar, "lidar_noise": LIDAR_NOISE,
             "velocities": "estimated", "sensing_range": LIDAR_RANGE}
            if lidar
            else {}
        )  # fmt: skip
        if sensing_range is not None:
            sensing["sensing_range"] = sensing_range
        try:
            scn = _scene(case, rule, substeps, kinematics, humans, sensing, (accel, turn_accel),
                         robot_visible, control_period)  # fmt: skip
        except ScenarioError as exc:
            if exc.path not in ("n_humans", "params.n_humans"):
                raise
            unplaceable.append(case)
            continue
        setup = build_episode(scn, case)
        law: Any
        if law_name != PAPER_LAW:
            law = make_law(law_name, **(law_params or {}))
        elif pref == "crowdnav":
            law = CrowdNavPrefOrca()
            law.params = type(law.params)(**CROWDNAV_ORCA_PARAMS)
        else:
            law = make_law(PAPER_LAW, **CROWDNAV_ORCA_PARAMS)
        probe = CrowdSimOutcome()
        probes: list[Any] = [probe] if outcome == "crowdnav" else []
        res = run_episode(setup, law, rng_of(case), record=False, vehicle=vehicle, probes=probes,
                          swept=swept)  # fmt: skip
        status, arrival = res.status, res.metrics.time_to_goal
        if outcome == "crowdnav":
            # no event before the world's end: a discrete overlap is a collision in CrowdSim's
            # next step (its swept segment starts inside), the time limit a timeout
            status = probe.status or res.status
            arrival = probe.at if probe.status == "success" else arrival
        counts[status] += 1
        statuses.append(status)
        collided_by.append(res.metrics.collision_by if status == "collision" else None)
        if res.metrics.intrusion_ratio is not None:
            intrusion.append(res.metrics.intrusion_ratio)
        if status == "success" and arrival is not None:
            times.append(float(arrival))
    cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
    asked, cases = cases, len(statuses)
    if not cases:
        raise NoCaseError(f"--humans {humans}: no case's humans could be placed apart")
    rates: dict[str, dict[str, Any]] = {}
    for key, k in counts.items():
        lo, hi = wilson_interval(k, cases)
        rates[key] = {"count": k, "rate": k / cases, "ci95": [lo, hi]}
    lo, hi = wilson_interval(counts["success"], cases)
    robot_driven = collided_by.count("robot")
    rd_lo, rd_hi = wilson_interval(robot_driven, cases)
    protocol = rule != DYNAMIC and not robot_visible  # CrowdNav's test protocol: judged
    return {
        "cases": cases,
        "first_case": first,
        "case_numbers": [c for c in case_numbers(asked, first) if c not in unplaceable],
        "asked": asked,
        "unplaceable": unplaceable,
        "rule": rule,
        "humans": humans
        if humans is not None
        else (crowd_dynamic.N_HUMANS if rule == DYNAMIC else N_HUMANS),
        "substeps": substeps,
        "dt": TIME_STEP / substeps,
        "pref": pref,
        "outcome": outcome,
        "law": law_name,
        "kinematics": kinematics if vehicle == "unicycle" else None,
        "judged": "along each step" if swept else "at each step's end",
        "sensing": (
            f"lidar {lidar} beams, {LIDAR_NOISE:g} m noise, {LIDAR_RANGE:g} m" if lidar else "exact"
        )
        + (f", humans seen within {sensing_range:g} m" if sensing_range is not None else "")
        + (
            f", humans seen within {crowd_dynamic.SENSING_RANGE:g} m"
            if sensing_range is None and rule == DYNAMIC
            else ""
        ),
        "params": dict(CROWDNAV_ORCA_PARAMS) if law_name == PAPER_LAW else dict(law_params or {}),
        "accel_max": accel,
        "turn_accel_max": turn_accel,
        "robot_visible": robot_visible,
        "control_period": TIME_STEP if control_period is None else control_period,
        "rates": rates,
        "robot_driven_collisions": {
            "count": robot_driven,
            "rate": robot_driven / max(cases, 1),
            "ci95": [rd_lo, rd_hi],
        },
        "time_to_goal_mean": float(np.mean(times)) if times else None,
        "intrusion_ratio": mean_interval(intrusion),
        "cpu_s": cpu,
        "wall_s": wall,
        "cpu_ms_per_episode": 1000.0 * cpu / max(cases, 1),
        "paper": PAPER,
        "target": TARGETS.get(law_name) if protocol else None,
        "has_target": protocol and (law_name in TARGETS or law_name == PAPER_LAW),
        "pass": bool(
            not protocol
            or (
                counts["success"] / max(cases, 1) >= TARGETS[law_name]
                if law_name in TARGETS
                else law_name != PAPER_LAW or lo <= PAPER["success"] <= hi
            )
        ),
        "statuses": statuses,
        "collided_by": collided_by,
    }


def _scene(
    case: int,
    rule: str,
    substeps: int,
    kinematics: str,
    humans: int | None,
    sensing: dict[str, Any],
    limits: tuple[float | None, float | None],
    robot_visible: bool = False,
    control_period: float | None = None,
) -> Any:
    """Case ``case``'s scene of ``rule`` (CrowdNav's, or the harder crowd's); ``limits``: the
    unicycle's (``accel_max``, ``turn_accel_max``).

    Raises:
        FieldError: ``control_period`` is not a whole multiple of the integration step.
    """
    n: dict[str, Any] = {} if humans is None else {"n_humans": humans}
    accel, turn_accel = limits
    common: dict[str, Any] = dict(dt=TIME_STEP / substeps, kinematics=kinematics, accel_max=accel,
                                  turn_accel_max=turn_accel, robot_visible=robot_visible,
                                  **n, **sensing)  # fmt: skip
    if rule == DYNAMIC:
        scn = crowd_dynamic_scenario(case, **common)
    else:
        scn = crowdnav_scenario(case, rule=rule, **common)  # type: ignore[arg-type]
    if control_period is None:
        return scn
    check_timing(scn.t_max, scn.dt, control_period)
    return scn.model_copy(update={"control_period": control_period})


def crowd_records(r: dict[str, Any]) -> list[dict[str, Any]]:
    """The run's target in the shared shape (:mod:`benchrecord`): the v2 laws' success, or the
    paper's ORCA success inside our interval; none for another law or the harder crowd."""
    if not r["has_target"]:
        return []
    success, smoke = r["rates"]["success"], r["cases"] < TEST_CASES
    lo, hi = success["ci95"]
    note = f"95 % interval [{lo:.3f}, {hi:.3f}] over {r['cases']} cases"
    if r["law"] in TARGETS:
        rec = record(f"crowdnav_success_{r['law']}", success["rate"], TARGETS[r["law"]], ">=",
                     note=note)  # fmt: skip
        return [rec | {"smoke": smoke}]
    return [{"name": f"crowdnav_success_{r['law']}", "target": f"CI ∋ {PAPER['success']:.2f}",
             "measured": success["rate"], "ratio": None, "pass": r["pass"], "work": "",
             "note": note, "smoke": smoke}]  # fmt: skip


def report(r: dict[str, Any]) -> str:
    scene = "crowd-dynamic" if r["rule"] == DYNAMIC else f"crowdnav-{r['rule'].split('_')[0]}"
    lines = [
        f"{scene} {_cases_text(r)}, {r['humans']} humans, "
        f"{r['law']} {r['params']}, "
        f"dt {r['dt']:g} s, pref {r['pref']}, outcome {r['outcome']}, collisions judged "
        f"{r['judged']}, sensing {r['sensing']}"
        + (f", {r['kinematics']} unicycle" if r["kinematics"] else "")
        + (
            f", limits {r['accel_max']} m/s^2, {r['turn_accel_max']} rad/s^2"
            if r["accel_max"] is not None or r["turn_accel_max"] is not None
            else ""
        )
        + (f", robot decides every {r['control_period']:g} s"
           if r["control_period"] != TIME_STEP else "")
        + (", robot visible to the humans" if r["robot_visible"] else ""),
    ]  # fmt: skip
    for key in ("success", "collision", "timeout"):
        x = r["rates"][key]
        lo, hi = x["ci95"]
        paper = f"   paper {PAPER[key]:.2f}" if key in PAPER and r["rule"] != DYNAMIC else ""
        lines.append(
            f"  {key:<9} {x['count']:4d}  {x['rate']:.3f}  95% [{lo:.3f}, {hi:.3f}]{paper}"
        )
    rd = r["robot_driven_collisions"]
    lo, hi = rd["ci95"]
    lines.append(f"  robot-driven collisions {rd['count']:4d}  {rd['rate']:.3f}  95% "
                 f"[{lo:.3f}, {hi:.3f}]")  # fmt: skip
    ttg = r["time_to_goal_mean"]
    ref = f"   paper {PAPER['time_to_goal']:.2f} s" if r["rule"] != DYNAMIC else ""
    lines.append(
        f"  time to goal (successes) {ttg:.2f} s{ref}"
        if ttg is not None
        else "  time to goal: no success"
    )
    ir = r["intrusion_ratio"]
    if ir["mean"] is not None:
        lo, hi = ir["ci95"]
        lines.append(f"  intrusion ratio (mean of {ir['episodes']} episodes) {ir['mean']:.3f}  "
                     f"95% [{lo:.3f}, {hi:.3f}]")  # fmt: skip
    lines.append(
        f"  CPU {r['cpu_s']:.1f} s ({r['cpu_ms_per_episode']:.1f} ms/episode), "
        f"wall {r['wall_s']:.1f} s"
    )
    verdict = "PASS" if r["pass"] else "FAIL"
    if r["rule"] == DYNAMIC:
        lines.append("  no target: the harder crowd has no paper figure")
    elif r["robot_visible"]:
        lines.append("  no target: the test protocol's robot is invisible to the humans")
    elif r["target"] is not None:
        lines.append(f"  {verdict}: success {r['rates']['success']['rate']:.3f} against the "
                     f"target >= {r['target']:.2f}")  # fmt: skip
    elif r["has_target"]:
        lines.append(f"  {verdict}: paper's ORCA success 0.43 "
                     f"{'inside' if r['pass'] else 'outside'} our 95 % interval")  # fmt: skip
    else:
        lines.append(f"  no target: only {PAPER_LAW} (the paper's ORCA row) and "
                     f"{', '.join(TARGETS)} are judged")  # fmt: skip
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", type=int, default=500, help="number of test cases (default 500)")
    ap.add_argument("--first", type=int, default=None,
                    help="cases FIRST.. in order (default: a seeded sample)")  # fmt: skip
    ap.add_argument("--rule", choices=("circle_crossing", "square_crossing", DYNAMIC),
                    default="circle_crossing")  # fmt: skip
    ap.add_argument("--substeps", type=int, default=1, help="integration steps per 0.25 s")
    ap.add_argument("--pref", choices=("uvnav", "crowdnav"), default="uvnav",
                    help="robot's preferred velocity (default: orca-holonomic-v1's)")  # fmt: skip
    ap.add_argument("--outcome", choices=("uvnav", "crowdnav"), default="uvnav",
                    help="judge episodes by the world (default) or as CrowdSim.step")  # fmt: skip
    ap.add_argument("--law", default=PAPER_LAW,
                    help="2D law (default orca-holonomic-v1, the paper's row; zhang2019-v2 "
                    "and zhang2019-holonomic-v2 are held to issue 19's targets)")  # fmt: skip
    ap.add_argument("--kinematics", choices=("turn-then-move", "arc"), default="turn-then-move",
                    help="a unicycle law's robot: CrowdNav's or the arc")  # fmt: skip
    ap.add_argument("--lidar", type=int, default=None, metavar="BEAMS",
                    help="the robot senses the humans with a BEAMS-beam lidar alone")  # fmt: skip
    ap.add_argument("--sampled", action="store_true",
                    help="judge collisions at each step's end only")  # fmt: skip
    ap.add_argument(
        "--accel",
        type=float,
        default=None,
        metavar="A",
        help="the unicycle's largest speed change [m/s^2] (default: at once)",
    )
    ap.add_argument(
        "--turn-accel",
        type=float,
        default=None,
        metavar="B",
        help="the unicycle's largest turn-rate change [rad/s^2] (default: at once)",
    )
    ap.add_argument("--humans", type=int, default=None, metavar="N",
                    help=f"number of humans (default: the scene's, CrowdNav's {N_HUMANS}, "
                    "crowd_dynamic's 20)")  # fmt: skip
    ap.add_argument("--sensing-range", type=float, default=None, metavar="R",
                    help="the robot sees the humans within R [m] (default: the scenes' 20 m; "
                    "with --lidar, the lidar's range unless given)")  # fmt: skip
    ap.add_argument("--param", "-p", action="append", default=None, metavar="KEY=VALUE",
                    help="a parameter of --law (repeatable; value read as YAML; not with the "
                    "paper's law)")  # fmt: skip
    ap.add_argument("--robot-visible", action="store_true",
                    help="the humans see the robot and avoid it (no verdict)")  # fmt: skip
    ap.add_argument("--control-period", type=float, default=None, metavar="P",
                    help="the robot decides every P [s] (default 0.25, as the humans)")  # fmt: skip
    ap.add_argument("--out", type=Path, default=None, help="write crowdnav.json here")
    args = ap.parse_args(argv)
    try:
        law_params = parse_params(args.param)
    except CliError as exc:
        ap.error(str(exc))
    if law_params and args.law == PAPER_LAW:
        ap.error(f"--param: {PAPER_LAW} runs with the paper's parameters; name another --law")
    if args.sensing_range is not None and not (
        math.isfinite(args.sensing_range) and args.sensing_range > 0
    ):
        ap.error(f"--sensing-range must be a number > 0 (got {args.sensing_range!r})")
    if args.cases < 1 or args.substeps < 1:
        ap.error("--cases and --substeps must be >= 1")
    if args.humans is not None and not 0 <= args.humans <= 1000:
        ap.error(f"--humans must be in 0..1000 (got {args.humans})")
    if args.rule == DYNAMIC and (args.lidar or args.outcome == "crowdnav"):
        ap.error("--rule crowd_dynamic takes neither --lidar nor --outcome crowdnav")
    for name, value in (("--accel", args.accel), ("--turn-accel", args.turn_accel)):
        if value is not None and not (math.isfinite(value) and value > 0):
            ap.error(f"{name} must be a number > 0 (got {value!r})")
    if args.outcome == "crowdnav" and args.substeps != 1:
        ap.error("--outcome crowdnav judges 0.25 s steps: use --substeps 1")
    try:
        r = run(
            args.cases, rule=args.rule, substeps=args.substeps, pref=args.pref,
            outcome=args.outcome, first=args.first, law_name=args.law, kinematics=args.kinematics,
            swept=not args.sampled, lidar=args.lidar, accel=args.accel, turn_accel=args.turn_accel,
            humans=args.humans, sensing_range=args.sensing_range, law_params=law_params,
            robot_visible=args.robot_visible, control_period=args.control_period,
        )  # fmt: skip
    except NoCaseError as exc:
        ap.error(str(exc))
    except FieldError as exc:
        ap.error(f"--control-period: {exc}")
    except ControllerParamsError as exc:
        ap.error(f"--param: {exc}")
    print(report(r))
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        r["machine"] = {
            "cpus": os.cpu_count(),
            "load": os.getloadavg(),
            "python": sys.version.split()[0],
            "platform": platform.platform(),
            "numpy": np.__version__,
            "time": datetime.now(UTC).isoformat(timespec="seconds"),
        }
        name = "crowdnav.json" if args.law == PAPER_LAW else f"crowdnav-{args.law}.json"
        if args.rule == DYNAMIC:
            name = f"crowd-dynamic-{args.law}.json"
        r[KEY] = crowd_records(r)
        (args.out / name).write_text(json.dumps(r, indent=1))
    return 0 if r["pass"] else 1


if __name__ == "__main__":
    raise SystemExit(main())
