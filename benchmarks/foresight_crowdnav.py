"""How far ahead must a law see?  A receding-horizon planner on the acceleration-limited unicycle
among CrowdNav's circle crowd, given the humans' future for only the next few seconds.

:mod:`oracle_crowdnav` searches the whole episode at once with the humans' whole future and wins
0.99 of the 20-human cases; a causal law sees nothing of the future.  Between the two, this
planner decides every period (0.25 s) as a robot would, from where it is, but plans against a
forecast of the humans over only ``horizon`` seconds:

* ``--see truth`` (an ORACLE, not a law: it reads the ground truth): the humans' true centres
  over the next ``horizon`` seconds, pre-rolled as in :mod:`oracle_crowdnav` (the humans ignore
  the invisible robot, so their future does not depend on it);
* ``--see cv`` (a causal law: it reads only its observation): each sensed body walking on at its
  sensed velocity (constant velocity) over the horizon.

At every decision the oracle's beam search (:func:`oracle_crowdnav.expand` and
:func:`~oracle_crowdnav.prune`, the vehicle's limits and the world's swept contact) runs from the
robot's state for ``horizon`` seconds.  Its plan is the first arrival it finds, else, of the
states that get furthest in time without a contact, the one nearest the goal
(:func:`~oracle_crowdnav.progress`).  The planner keeps its previous plan (the part not yet
driven) unless the new one stays clear at least as long under the new forecast: a beam search
started afresh each period may lose a way out that the last one found, and the kept plan is
what carries it from one decision to the next.  Where nothing stays clear for one period it
brakes.  The first command of the plan is sent; the world judges the episode.

The search keeps the states nearest the goal, so it can lose a way out that exists: with the
truth over 4 s, case 100 of the 5-human circle follows a plan that stays clear one period less
at each decision until none is left, and collides.  The horizon a success rate needs is this
planner's, an estimate from above of what a better search would need, not a bound.

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/foresight_crowdnav.py --horizon 4 --sample 50``
(``--see cv`` for the causal law; ``--out DIR`` writes
``DIR/foresight-crowdnav-<see>-<horizon>.json``).
Reported: success with its 95 % Wilson interval (the bench's), collisions (and how many the
robot drove into), timeouts, the CPU time.  Units: metres, seconds, radians.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import oracle_crowdnav as oc

from uvnav.bench.summary import wilson_interval
from uvnav.dynamics.unicycle import UnicycleCommand, UnicycleSpec
from uvnav.scenarios.build import build_episode
from uvnav.scenarios.catalog import kinds
from uvnav.sensors.observation import Observation, read_arrays
from uvnav.sim.run import run_episode

#: the search of every decision (a smaller beam than the whole-episode oracle's: it runs each
#: period)
SEARCH = oc.Search(beam=600, per_cell=30)
#: what the planner may see of the humans' future
SEES = ("truth", "cv")


@dataclass
class Plan:
    """A command per period from now (periods, 2) and how many periods it stays clear."""

    cmds: np.ndarray
    clear: int


def window(track: np.ndarray, k: int, steps: int) -> np.ndarray:
    """Rows ``k .. k + steps`` of ``track`` (T, N, 2), the last row repeated past its end.

    >>> window(np.arange(3.0).reshape(3, 1, 1), 1, 3)[:, 0, 0].tolist()
    [1.0, 2.0, 2.0, 2.0]
    """
    rows = track[k : k + steps + 1]
    if len(rows) < steps + 1:
        rows = np.concatenate((rows, np.repeat(track[-1:], steps + 1 - len(rows), 0)))
    return rows


def constant_velocity(centres: np.ndarray, velocities: np.ndarray, steps: int, dt: float
                      ) -> np.ndarray:  # fmt: skip
    """The bodies' centres (N, 2) walking on at their velocities (N, 2) [m/s], at ``0, dt,
    ..., steps dt`` [s]: (steps + 1, N, 2)."""
    t = np.arange(steps + 1) * dt
    return centres[None] + velocities[None] * t[:, None, None]


def search_plan(c: oc.Case, v: float, u: float, periods: int, s: oc.Search = SEARCH
                ) -> Plan | None:  # fmt: skip
    """The beam search of the module docstring from ``c.start`` at speed ``v`` and turn rate
    ``u``, over ``periods`` periods of ``c``: the first arrival, else the state nearest the
    goal among those that stay clear longest; ``None`` when nothing stays clear one period."""
    x, y, th = c.start
    beam = oc.Beam(np.array([x]), np.array([y]), np.array([th]), np.array([v]), np.array([u]),
                   np.zeros((1, 0, 2)))  # fmt: skip
    deepest: oc.Beam | None = None
    for i in range(periods):
        children, arrived = oc.expand(c, beam, i, s)
        if arrived is not None:
            hit = np.flatnonzero(arrived >= 0)
            return Plan(children.cmds[hit[np.argmin(arrived[hit])]], periods)
        if len(children.x) == 0:
            break
        beam = deepest = oc.prune(c, children, s)
    if deepest is None:
        return None
    best = int(np.argmin(oc.progress(c, deepest, s)))
    return Plan(deepest.cmds[best], deepest.cmds.shape[1])


def stays_clear(c: oc.Case, v: float, u: float, cmds: np.ndarray, periods: int) -> int:
    """How many of the first ``periods`` periods the commands ``cmds`` (one per period) stay
    clear of the humans of ``c`` from its start at speed ``v`` and turn rate ``u`` (an arrival
    counts as clear to the end; the commands' end as their last period)."""
    state = tuple(np.array([a], dtype=float) for a in (*c.start, v, u))
    everyone = np.arange(len(c.radii))
    for i in range(min(periods, len(cmds))):
        state, alive, arrived = oc.advance(c, state, cmds[i : i + 1, 0], cmds[i : i + 1, 1],
                                           i * c.ratio, everyone)  # fmt: skip
        if arrived[0] >= 0:
            return periods
        if not alive[0]:
            return i
    return min(periods, len(cmds))


class Foresight:
    """The module docstring's planner as a law (one instance per episode).

    Args:
        spec: the robot.
        horizon: how far ahead it plans and sees [s].
        dt: the world's integration step [s]; ``period`` the decision period [s].
        truth: the episode's ground truth (:func:`oracle_crowdnav.oracle_case`: the humans'
            centres at every integration step, their radii), read over the horizon (``--see
            truth``: the law is then an oracle); ``None``: it forecasts the sensed bodies from
            its observation at constant velocity.
        clearance: the gap it keeps from every forecast human [m].
    """

    name = "foresight"
    mode = "plan"

    def __init__(self, spec: UnicycleSpec, horizon: float, dt: float, period: float,
                 truth: oc.Case | None = None, clearance: float = 0.0) -> None:  # fmt: skip
        self.spec, self.dt, self.truth, self.clearance = spec, dt, truth, clearance
        self.ratio = round(period / dt)
        self.periods = max(round(horizon / period), 1)
        self.oracle = truth is not None
        self.goal = np.zeros(2)
        self.v = self.u = 0.0
        self.plan: np.ndarray | None = None

    def reset(self, spec: Any, goal: np.ndarray, rng: np.random.Generator) -> None:
        self.goal = np.asarray(goal, dtype=float)
        self.v = self.u = 0.0
        self.plan = None

    def case(self, obs: Observation) -> oc.Case:
        """What the planner sees at ``obs``: the humans over its horizon, the robot's pose."""
        steps = self.periods * self.ratio
        if self.truth is not None:
            centres = window(self.truth.centres, round(obs.time / self.dt), steps)
            radii = self.truth.radii
        else:
            scal, pos, vel = read_arrays(obs.obstacles)
            centres = constant_velocity(pos, vel, steps, self.dt)
            radii = scal[:, 3]  # the bounding radii
        x, y, th = (float(a) for a in obs.pose)
        return oc.Case(centres=centres, radii=radii, spec=self.spec, start=(x, y, th),
                       goal=(float(self.goal[0]), float(self.goal[1])),
                       tolerance=self.spec.radius, dt=self.dt, ratio=self.ratio,
                       clearance=self.clearance)  # fmt: skip

    def act(self, obs: Observation) -> UnicycleCommand:
        c = self.case(obs)
        new = search_plan(c, self.v, self.u, self.periods)
        if self.plan is not None and len(self.plan):
            kept = stays_clear(c, self.v, self.u, self.plan, self.periods)
            if new is None or kept > new.clear:
                new = Plan(self.plan, kept)
        if new is None:
            cv, cu = max(self.v - self.spec.accel_max * self.dt * self.ratio, 0.0), self.u
            self.plan = None
        else:
            cv, cu = (float(a) for a in new.cmds[0])
            self.plan = new.cmds[1:]
        # the vehicle's own limits, step by step as the world applies them (one step of the
        # period's length differs in the last bits, and the search's cells then part ways)
        v, u = np.array(self.v), np.array(self.u)
        for _ in range(self.ratio):
            v = oc._approach(v, np.array(cv), self.spec.accel_max * self.dt)
            u = oc._approach(u, np.array(cu), self.spec.turn_accel_max * self.dt)
        self.v, self.u = float(v), float(u)
        return UnicycleCommand(cv, cu)


def run_case(case: int, scn: Any, see: str, horizon: float, clearance: float) -> dict[str, Any]:
    """One episode of the planner in the world: its status, time to goal and who drove into
    whom."""
    setup = build_episode(scn, case)
    spec = setup.spec
    assert isinstance(spec, UnicycleSpec)
    truth = oc.oracle_case(scn, case) if see == "truth" else None
    law = Foresight(spec, horizon, float(setup.dt), float(setup.control_period), truth, clearance)
    res = run_episode(setup, law, kinds()["nav2d"].episode_rng(case), record=False)
    return {
        "case": case,
        "status": res.status,
        "time": res.metrics.time_to_goal,
        "collision_by": res.metrics.collision_by if res.status == "collision" else None,
    }


def run(cases: list[int], *, humans: int, see: str, horizon: float, clearance: float = 0.0,
        label: str | None = None) -> dict[str, Any]:  # fmt: skip
    """Every case's row and the totals (module docstring); ``label``: a progress bar of that
    name on stderr."""
    rows: list[dict[str, Any]] = []
    unplaceable: list[int] = []
    cpu0 = time.process_time()
    for case, scn in oc.placeable(cases, humans, oc.ACCEL, oc.TURN_ACCEL, oc.SUBSTEPS,
                                  unplaceable, label):  # fmt: skip
        rows.append(run_case(case, scn, see, horizon, clearance))
    n = len(rows)
    count = {k: sum(r["status"] == k for r in rows) for k in ("success", "collision", "timeout")}
    lo, hi = wilson_interval(count["success"], n) if n else (math.nan, math.nan)
    times = [r["time"] for r in rows if r["status"] == "success"]
    return {
        "oracle": see == "truth",
        "see": see, "horizon_s": horizon, "humans": humans, "clearance": clearance,
        "cases": n, "unplaceable": unplaceable,
        "success": {"count": count["success"], "rate": count["success"] / n if n else math.nan,
                    "ci95": [lo, hi]},
        "collisions": count["collision"],
        "robot_driven": sum(r["collision_by"] == "robot" for r in rows),
        "timeouts": count["timeout"],
        "time_to_goal_mean": float(np.mean(times)) if times else None,
        "cpu_s": time.process_time() - cpu0,
        "rows": rows,
    }  # fmt: skip


def report(r: dict[str, Any]) -> str:
    """The summary in a few lines."""
    s = r["success"]
    lo, hi = s["ci95"]
    what = ("ORACLE: the humans' true future" if r["oracle"]
            else "causal: the sensed humans at constant velocity")  # fmt: skip
    ttg = r["time_to_goal_mean"]
    return "\n".join([
        f"receding-horizon planner seeing {r['horizon_s']:g} s ahead ({what}), crowdnav-circle, "
        f"{r['cases']} cases, {r['humans']} humans, keeping {r['clearance']:g} m"
        + (f", {len(r['unplaceable'])} unplaceable left out" if r["unplaceable"] else ""),
        f"  success {s['count']:4d}  {s['rate']:.3f}  95% [{lo:.3f}, {hi:.3f}]",
        f"  collisions {r['collisions']} ({r['robot_driven']} robot-driven), "
        f"timeouts {r['timeouts']}",
        f"  time to goal (successes) {ttg:.2f} s" if ttg is not None else "  no success",
        f"  CPU {r['cpu_s']:.1f} s ({r['cpu_s'] / max(r['cases'], 1):.1f} s/case)",
    ])  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    oc.add_case_options(ap)
    ap.add_argument("--see", choices=SEES, default="truth",
                    help="truth: the humans' future (oracle); cv: constant velocity")  # fmt: skip
    ap.add_argument("--horizon", type=float, default=4.0, metavar="S",
                    help="how far ahead it plans and sees [s] (default 4)")  # fmt: skip
    ap.add_argument("--clearance", type=float, default=0.0, metavar="M",
                    help="the gap kept from every forecast human [m] (default 0)")  # fmt: skip
    ap.add_argument("--out", type=Path, default=None, help="write the JSON record here")
    args = ap.parse_args(argv)
    if not (math.isfinite(args.horizon) and args.horizon >= 0.25):
        ap.error(f"--horizon must be a number >= 0.25 (got {args.horizon!r})")
    if not (math.isfinite(args.clearance) and args.clearance >= 0):
        ap.error(f"--clearance must be a number >= 0 (got {args.clearance!r})")
    cases = oc.chosen_cases(ap, args)
    r = run(cases, humans=args.humans, see=args.see, horizon=args.horizon,
            clearance=args.clearance, label=f"foresight {args.see} {args.horizon:g} s")  # fmt: skip
    r["case_numbers"] = cases
    print(report(r))
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        r["machine"] = {"cpus": os.cpu_count(), "load": os.getloadavg(),
                        "python": sys.version.split()[0]}  # fmt: skip
        name = f"foresight-crowdnav-{args.see}-{args.horizon:g}.json"
        (args.out / name).write_text(json.dumps(r, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
