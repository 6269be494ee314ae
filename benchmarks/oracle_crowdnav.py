"""An ORACLE bound for the acceleration-limited unicycle on CrowdNav's circle: is a target reachable
by ANY controller?

**This is not a law and no robot could run it: it reads the ground truth, including the humans'
whole future.**  With the robot invisible to the humans (CrowdNav's test protocol, the scenes'
default) the humans' motion does not depend on the robot (:func:`humans_ignore_robot` checks
it), so their positions are rolled out once for the whole episode at the world's integration
step (:func:`human_track`).  A search then looks for a sequence of robot commands, one per
decision period (0.25 s), that reaches the goal within the scene's time limit without touching
a human:

* each command goes through the limits the world applies (speed in [0, V_max], turn rate within
  U_max, the speed and the turn rate moving toward it by at most ``accel_max dt`` and
  ``turn_accel_max dt`` per integration step, CrowdNav's turn-then-move kinematics with the
  period's ramped turn taken at the decision: :mod:`uvnav.dynamics.unicycle`);
* a collision is judged as the world judges it: along every integration step (robot and humans
  moving straight within it), the discs' radius sum, contact when the distance drops below it;
  arrival when the centre ends an integration step within the goal tolerance;
* the search is a beam search over the reachable (x, y, heading, v, omega): every state of the
  beam is expanded by a grid of speed and turn-rate changes, colliding children are dropped,
  the survivors deduplicated on a coarse state grid, spread over space (at most
  ``per_cell`` per 0.25 m cell) and the ``beam`` closest to the goal (distance plus a heading
  term) kept.  Its first arrival is the oracle's success and time.  Every success found is
  replayed through the world itself (:func:`replay`) and counted only when the world agrees.
* where no success is found, a survival search (a finer control grid, no progress heuristic,
  a finer dedup) asks whether ANY command sequence stays clear of the humans for the first
  ``survive_s`` seconds; none is evidence that the case is lost for every law, not that the
  search was weak (the dedup keeps one state per cell, so it is evidence, not proof).

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/oracle_crowdnav.py --humans 20 --first 100
--cases 400`` (``--out DIR`` writes ``DIR/oracle-crowdnav-<humans>.json``; ``--sample N``: N of
those cases drawn by a generator seeded 0; ``--clearance M``: the oracle keeps M [m] from every
human, which says how much room its successes have).  Reported: the oracle's success fraction
with its 95 % Wilson interval (the bench's), the replay agreement, the cases with no surviving
sequence, the CPU time.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from uvnav.bench.summary import wilson_interval
from uvnav.controllers.zhang2019_limits import ramp_turns
from uvnav.dynamics.unicycle import UnicycleCommand, UnicycleSpec
from uvnav.obstacles.batch import ObstacleBatch
from uvnav.scenarios.build import build_episode
from uvnav.scenarios.catalog import kinds
from uvnav.scenarios.crowdnav import TIME_STEP, crowdnav_scenario
from uvnav.scenarios.errors import ScenarioError
from uvnav.sim.run import run_episode
from uvnav.sim.setup import EpisodeSetup

#: the settings of the issue's done-means (acceleration-limited unicycle, 5 integration steps)
ACCEL, TURN_ACCEL, SUBSTEPS = 1.0, 2.0, 5
#: a contact is judged this much early [m] (the world's: below the radius sum; kept strict)
MARGIN = 1e-9


@dataclass(frozen=True)
class Search:
    """The search's grids and sizes.

    Attributes:
        dv: speed-command steps as fractions of the reachable change in one period.
        du: turn-rate-command steps, as fractions likewise.
        cell: dedup cell sizes of (x [m], y [m], heading [rad], v [m/s], omega [rad/s]).
        beam: states kept after each period.
        per_cell: states kept per 0.25 m (x, y) cell (spread over space).
        heading_weight: [m/rad] of the heading error toward the goal in the progress measure.
    """

    dv: tuple[float, ...] = (-1.0, -0.5, 0.0, 0.5, 1.0)
    du: tuple[float, ...] = (-1.0, -0.5, 0.0, 0.5, 1.0)
    cell: tuple[float, float, float, float, float] = (0.1, 0.1, math.radians(10), 0.125, 0.25)
    beam: int = 3000
    per_cell: int = 60
    heading_weight: float = 0.3


#: the searches tried in turn until one finds an arrival (the wider one where the first fails)
LADDER = (Search(), Search(beam=8000, per_cell=200))

#: the survival search: a finer control grid and dedup, no progress preference
SURVIVE = Search(
    dv=(-1.0, -2 / 3, -1 / 3, 0.0, 1 / 3, 2 / 3, 1.0),
    du=(-1.0, -2 / 3, -1 / 3, 0.0, 1 / 3, 2 / 3, 1.0),
    cell=(0.05, 0.05, math.radians(5), 0.0625, 0.125),
    beam=8000,
    per_cell=400,
    heading_weight=0.0,
)


@dataclass(frozen=True)
class Case:
    """What the oracle knows of one case: the humans' whole future and the robot's limits.

    Attributes:
        centres: (steps + 1, humans, 2) the humans' centres at every integration step [m].
        radii: (humans,) their radii [m].
        spec: the robot (limits, radius, kinematics, acceleration limits).
        start: the robot's (x, y, heading).
        goal: the goal (x, y) [m]; ``tolerance`` its arrival radius [m].
        dt: the integration step [s]; ``ratio`` steps per decision.
        clearance: the gap [m] the oracle keeps from every human beyond touching (0: it may
            pass as close as the world allows).
    """

    centres: np.ndarray
    radii: np.ndarray
    spec: UnicycleSpec
    start: tuple[float, float, float]
    goal: tuple[float, float]
    tolerance: float
    dt: float
    ratio: int
    clearance: float = 0.0

    @property
    def steps(self) -> int:
        return int(self.centres.shape[0] - 1)


def scene(case: int, humans: int, accel: float, turn_accel: float, substeps: int) -> Any:
    """The bench's scene of ``case`` (:func:`crowdnav_scenario`, turn-then-move unicycle)."""
    return crowdnav_scenario(
        case, rule="circle_crossing", dt=TIME_STEP / substeps, n_humans=humans,
        accel_max=accel, turn_accel_max=turn_accel,
    )  # fmt: skip


def human_track(setup: EpisodeSetup) -> np.ndarray:
    """The humans' centres at every integration step of the episode, (steps + 1, humans, 2),
    advanced as the world advances them (:class:`ObstacleBatch`, without a robot to see).
    The setup's obstacles are advanced in place: give a fresh one."""
    dt = float(setup.dt)
    steps = round(float(setup.t_max) / dt)
    n = len(setup.obstacles)
    out = np.empty((steps + 1, n, 2))
    if n == 0:
        return out
    batch = ObstacleBatch(setup.obstacles)
    out[0] = batch.positions
    for k in range(steps):
        batch.step(k * dt, dt)
        out[k + 1] = batch.positions
    return out


def oracle_case(scn: Any, case: int, clearance: float = 0.0) -> Case:
    """The ground truth of ``case`` of the scene (the humans' future included); the oracle
    keeps ``clearance`` [m] from the humans."""
    setup = build_episode(scn, case)
    spec = setup.spec
    assert isinstance(spec, UnicycleSpec)
    start = np.asarray(setup.start, dtype=float)
    radii = np.array([float(o.body.bounding_radius) for o in setup.obstacles])
    return Case(
        centres=human_track(setup), radii=radii, spec=spec,
        start=(float(start[0]), float(start[1]), float(start[2])),
        goal=(float(setup.goal[0]), float(setup.goal[1])),
        tolerance=float(setup.goal_tolerance), dt=float(setup.dt),
        ratio=round(float(setup.control_period) / float(setup.dt)), clearance=clearance,
    )  # fmt: skip


def _approach(value: np.ndarray, target: np.ndarray, most: float) -> np.ndarray:
    """``value`` moved toward ``target`` by at most ``most`` (the vehicle's ``approach``)."""
    if math.isinf(most):
        return target.copy()
    return value + np.clip(target - value, -most, most)


def _wrap(a: np.ndarray) -> np.ndarray:
    """Angles wrapped to (-pi, pi]."""
    return np.pi - np.mod(np.pi - a, 2.0 * np.pi)


def commands(
    v: np.ndarray, u: np.ndarray, spec: UnicycleSpec, period: float, s: Search
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every state's children commands: (parent index, v command, u command), the steps of
    ``s`` as fractions of the change reachable in one ``period``, saturated to the limits."""
    reach_v = min(spec.accel_max * period, spec.v_max)
    reach_u = min(spec.turn_accel_max * period, 2.0 * spec.u_max)
    dv, du = np.meshgrid(np.asarray(s.dv), np.asarray(s.du), indexing="ij")
    dv, du = dv.ravel(), du.ravel()
    n, m = len(v), len(dv)
    parent = np.repeat(np.arange(n), m)
    cv = np.clip(v[parent] + np.tile(dv, n) * reach_v, 0.0, spec.v_max)
    cu = np.clip(u[parent] + np.tile(du, n) * reach_u, -spec.u_max, spec.u_max)
    return parent, cv, cu


def _swept_hit(
    r0: np.ndarray, r1: np.ndarray, h0: np.ndarray, h1: np.ndarray, reach2: np.ndarray
) -> np.ndarray:
    """Per robot, a contact along the step: robot from ``r0`` to ``r1`` (C, 2), humans from
    ``h0`` to ``h1`` (H, 2), both straight; contact when the distance drops below the radius
    sum (``reach2``: its square per human)."""
    px = h0[None, :, 0] - r0[:, 0, None]
    py = h0[None, :, 1] - r0[:, 1, None]
    dx = (h1[:, 0] - h0[:, 0])[None, :] - (r1[:, 0] - r0[:, 0])[:, None]
    dy = (h1[:, 1] - h0[:, 1])[None, :] - (r1[:, 1] - r0[:, 1])[:, None]
    dd = dx * dx + dy * dy
    s = np.clip(-(px * dx + py * dy) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
    px += s * dx
    py += s * dy
    return np.asarray((px * px + py * py < reach2[None, :]).any(axis=1))


@dataclass
class Beam:
    """States of the search at a decision: (x, y, heading, v, omega) and each one's commands."""

    x: np.ndarray
    y: np.ndarray
    th: np.ndarray
    v: np.ndarray
    u: np.ndarray
    cmds: np.ndarray  # (states, periods, 2) the commands that led here

    def take(self, idx: np.ndarray) -> Beam:
        return Beam(self.x[idx], self.y[idx], self.th[idx], self.v[idx], self.u[idx],
                    self.cmds[idx])  # fmt: skip


def _near_humans(c: Case, beam: Beam, k0: int, reach: float) -> np.ndarray:
    """The humans that may come within ``reach`` [m] of the beam's box during the period
    starting at step ``k0`` (the others cannot touch any child)."""
    h = c.centres[k0 : k0 + c.ratio + 1]
    lo = np.array((beam.x.min(), beam.y.min())) - reach - c.radii.max(initial=0.0)
    hi = np.array((beam.x.max(), beam.y.max())) + reach + c.radii.max(initial=0.0)
    box = (h.min(axis=0) <= hi) & (h.max(axis=0) >= lo)
    return np.flatnonzero(box.all(axis=1))


def advance(
    c: Case, state: tuple[np.ndarray, ...], cv: np.ndarray, cu: np.ndarray, k0: int,
    near: np.ndarray,
) -> tuple[tuple[np.ndarray, ...], np.ndarray, np.ndarray]:  # fmt: skip
    """Every state ``(x, y, heading, v, omega)`` driven by its command ``(cv, cu)`` over the
    period starting at integration step ``k0``, judged against the humans ``near``: the states
    at its end, which stayed clear of them (an arrival first counts as clear), and the step of
    each one's arrival (-1: none)."""
    spec, dt, period = c.spec, c.dt, c.dt * c.ratio
    x, y, th, v, u = state
    reach2 = (c.radii[near] + spec.radius + c.clearance + MARGIN) ** 2
    alive = np.ones(len(x), dtype=bool)
    arrived = np.full(len(x), -1)
    gx, gy = c.goal
    for j in range(c.ratio):
        if j == 0:  # the period's turn at the decision, as the vehicle takes it
            th = _wrap(th + ramp_turns(u, cu, spec.turn_accel_max, period))
        v = _approach(v, cv, spec.accel_max * dt)
        u = _approach(u, cu, spec.turn_accel_max * dt)
        nx, ny = x + v * dt * np.cos(th), y + v * dt * np.sin(th)
        if len(near):
            k = k0 + j
            hit = _swept_hit(np.stack((x, y), 1), np.stack((nx, ny), 1),
                             c.centres[k, near], c.centres[k + 1, near], reach2)  # fmt: skip
            alive &= ~hit | (arrived >= 0)
        x, y = nx, ny
        at_goal = alive & (arrived < 0) & (np.hypot(gx - x, gy - y) <= c.tolerance)
        arrived[at_goal] = k0 + j + 1
    return (x, y, th, v, u), alive, arrived


def expand(c: Case, beam: Beam, period_index: int, s: Search) -> tuple[Beam, np.ndarray | None]:
    """Every child of ``beam`` over the period ``period_index``: the survivors (no contact over
    the period) and, where some child arrives, the arrival step of each survivor (-1: none)."""
    spec, period = c.spec, c.dt * c.ratio
    parent, cv, cu = commands(beam.v, beam.u, spec, period, s)
    k0 = period_index * c.ratio
    near = _near_humans(c, beam, k0, spec.v_max * period + spec.radius + c.clearance + 0.01)
    state = (beam.x[parent], beam.y[parent], beam.th[parent], beam.v[parent], beam.u[parent])
    (x, y, th, v, u), alive, arrived = advance(c, state, cv, cu, k0, near)
    keep = np.flatnonzero(alive)
    cmds = np.concatenate((beam.cmds[parent[keep]], np.stack((cv, cu), 1)[keep, None, :]), 1)
    out = Beam(x[keep], y[keep], th[keep], v[keep], u[keep], cmds)
    return out, (arrived[keep] if (arrived[keep] >= 0).any() else None)


def progress(c: Case, b: Beam, s: Search) -> np.ndarray:
    """The search's preference (lower first): distance to the goal plus a heading term."""
    gx, gy = c.goal
    err = np.abs(_wrap(np.arctan2(gy - b.y, gx - b.x) - b.th))
    return np.hypot(gx - b.x, gy - b.y) + s.heading_weight * err


def _cell_ids(fields: list[np.ndarray], widths: tuple[float, ...]) -> np.ndarray:
    """One integer per grid cell of the ``fields`` (cell sizes ``widths``)."""
    ids = np.zeros(len(fields[0]), dtype=np.int64)
    for f, w in zip(fields, widths, strict=True):
        q = np.floor(f / w).astype(np.int64)
        q -= q.min()
        ids = ids * (int(q.max()) + 1) + q
    return ids


def prune(c: Case, b: Beam, s: Search) -> Beam:
    """One state per dedup cell (the most advanced), at most ``per_cell`` per 0.25 m cell,
    then the ``beam`` most advanced."""
    if len(b.x) == 0:
        return b
    order = np.argsort(progress(c, b, s), kind="stable")
    fields = [f[order] for f in (b.x, b.y, _wrap(b.th) + np.pi, b.v, b.u)]
    _, first = np.unique(_cell_ids(fields, s.cell), return_index=True)
    order = order[np.sort(first)]
    _, inv = np.unique(_cell_ids([b.x[order], b.y[order]], (0.25, 0.25)), return_inverse=True)
    by = np.argsort(inv, kind="stable")
    starts = np.r_[0, np.flatnonzero(np.diff(inv[by])) + 1]
    rank = np.empty(len(order), dtype=np.int64)
    rank[by] = np.arange(len(by)) - np.repeat(starts, np.diff(np.r_[starts, len(by)]))
    return b.take(order[rank < s.per_cell][: s.beam])


def initial(c: Case) -> Beam:
    """The robot at its start, at rest."""
    x, y, th = c.start
    z = np.zeros(1)
    return Beam(z + x, z + y, z + th, z.copy(), z.copy(), np.zeros((1, 0, 2)))


def search(c: Case, s: Search = Search()) -> tuple[float | None, np.ndarray | None]:
    """The oracle's first arrival: (time [s], commands (periods, 2)), or (None, None)."""
    beam = initial(c)
    for i in range(math.ceil(c.steps / c.ratio)):
        beam, arrived = expand(c, beam, i, s)
        if arrived is not None:
            hit = np.flatnonzero(arrived >= 0)
            best = hit[np.argmin(arrived[hit])]
            return float(arrived[best]) * c.dt, beam.cmds[best]
        beam = prune(c, beam, s)
        if len(beam.x) == 0:
            break
    return None, None


def survives(c: Case, seconds: float, s: Search = SURVIVE) -> float:
    """How long [s] (up to ``seconds``) some command sequence stays clear of every human."""
    beam = initial(c)
    periods = min(math.ceil(seconds / (c.dt * c.ratio)), math.ceil(c.steps / c.ratio))
    for i in range(periods):
        beam, arrived = expand(c, beam, i, s)
        if arrived is not None:
            return seconds
        beam = prune(c, beam, s)
        if len(beam.x) == 0:
            return i * c.ratio * c.dt
    return seconds


class Replay:
    """The oracle's commands, one per decision, replayed through the world (a law's interface;
    ``oracle`` True: it reads nothing, but it was planned on the ground truth)."""

    name = "oracle-replay"

    def __init__(self, cmds: np.ndarray) -> None:
        self.cmds = cmds
        self.oracle = True
        self.mode = "replay"
        self._i = 0

    def reset(self, spec: Any, goal: np.ndarray, rng: np.random.Generator) -> None:
        self._i = 0

    def act(self, obs: Any) -> UnicycleCommand:
        i = min(self._i, len(self.cmds) - 1)
        self._i += 1
        return UnicycleCommand(float(self.cmds[i, 0]), float(self.cmds[i, 1]))


def replay(scn: Any, case: int, cmds: np.ndarray) -> tuple[str, float | None]:
    """The world's own outcome (status, time to goal) of the command sequence ``cmds``."""
    setup = build_episode(scn, case)
    res = run_episode(setup, Replay(cmds), kinds()["nav2d"].episode_rng(case), record=False)
    return res.status, res.metrics.time_to_goal


def run_case(case: int, scn: Any, survive_s: float, clearance: float = 0.0) -> dict[str, Any]:
    """One case: the oracle's search, the world's replay, and the survival search on a miss."""
    c = oracle_case(scn, case, clearance)
    for tier in range(len(LADDER)):
        t, cmds = search(c, LADDER[tier])
        if t is not None:
            break
    row: dict[str, Any] = {"case": case, "found": t is not None, "time": t, "tier": tier}
    if cmds is not None:
        row["replay"], row["replay_time"] = replay(scn, case, cmds)
    else:
        row["survives_s"] = survives(c, survive_s)
    return row


def placeable(
    cases: list[int], humans: int, accel: float, turn_accel: float, substeps: int,
    unplaceable: list[int], label: str | None = None,
) -> Iterator[tuple[int, Any]]:  # fmt: skip
    """Each case whose humans CrowdSim could place apart, with its scene (:func:`scene`); the
    others are appended to ``unplaceable``.  ``label``: a progress bar of that name on stderr
    (none when ``None``)."""
    for case in _shown(cases, label):
        try:
            scn = scene(case, humans, accel, turn_accel, substeps)
        except ScenarioError as exc:
            if exc.path not in ("n_humans", "params.n_humans"):
                raise
            unplaceable.append(case)
            continue
        yield case, scn


def _shown(cases: list[int], label: str | None) -> Iterable[int]:
    """``cases``, under a transient rich progress bar on stderr when ``label`` is given."""
    if label is None:
        return cases
    from rich.console import Console
    from rich.progress import track

    return track(cases, description=label, console=Console(stderr=True), transient=True)


def run(
    cases: list[int],
    *,
    humans: int,
    accel: float,
    turn_accel: float,
    substeps: int,
    survive_s: float,
    clearance: float = 0.0,
    label: str | None = None,
) -> dict[str, Any]:
    """Every case's oracle row and the totals (success = found and confirmed by the world);
    ``label``: :func:`placeable`'s progress bar."""
    rows: list[dict[str, Any]] = []
    unplaceable: list[int] = []
    cpu0 = time.process_time()
    for case, scn in placeable(cases, humans, accel, turn_accel, substeps, unplaceable, label):
        rows.append(run_case(case, scn, survive_s, clearance))
    cpu = time.process_time() - cpu0
    return summarise(rows, unplaceable, cpu, humans=humans, accel=accel, turn_accel=turn_accel,
                     substeps=substeps, survive_s=survive_s, clearance=clearance)  # fmt: skip


def summarise(
    rows: list[dict[str, Any]], unplaceable: list[int], cpu: float, **settings: Any
) -> dict[str, Any]:
    """The totals of the rows: success with its 95 % Wilson interval, replay disagreements,
    cases with no surviving sequence, CPU time."""
    n = len(rows)
    ok = sum(r.get("replay") == "success" for r in rows)
    lo, hi = wilson_interval(ok, n) if n else (math.nan, math.nan)
    times = [r["replay_time"] for r in rows if r.get("replay") == "success"]
    return {
        "oracle": "reads the ground truth, including the humans' future: not a causal law",
        **settings,
        "cases": n,
        "unplaceable": unplaceable,
        "success": {"count": ok, "rate": ok / n if n else math.nan, "ci95": [lo, hi]},
        "found_not_confirmed": [r["case"] for r in rows if r["found"] and r["replay"] != "success"],
        "no_success": [r["case"] for r in rows if not r["found"]],
        "no_survivor": [
            r["case"] for r in rows if not r["found"] and r["survives_s"] < settings["survive_s"]
        ],
        "time_to_goal_mean": float(np.mean(times)) if times else None,
        "cpu_s": cpu,
        "rows": rows,
    }


def report(r: dict[str, Any]) -> str:
    """The summary in a few lines."""
    s = r["success"]
    lo, hi = s["ci95"]
    ttg = r["time_to_goal_mean"]
    return "\n".join([
        f"ORACLE (reads the ground truth, the humans' future included; no causal law can do "
        f"this) on crowdnav-circle, {r['cases']} cases, {r['humans']} humans, limits "
        f"{r['accel']:g} m/s^2, {r['turn_accel']:g} rad/s^2, {r['substeps']} substeps, "
        f"keeping {r['clearance']:g} m from the humans"
        + (f", {len(r['unplaceable'])} unplaceable left out" if r["unplaceable"] else ""),
        f"  oracle success {s['count']:4d}  {s['rate']:.3f}  95% [{lo:.3f}, {hi:.3f}] "
        f"(each confirmed by replaying its commands in the world)",
        f"  found but not confirmed by the world: {len(r['found_not_confirmed'])}",
        f"  no success found: {len(r['no_success'])}; of these, no command sequence survives "
        f"the first {r['survive_s']:g} s: {len(r['no_survivor'])}",
        f"  time to goal (successes) {ttg:.2f} s" if ttg is not None else "  no success",
        f"  CPU {r['cpu_s']:.1f} s ({1000 * r['cpu_s'] / max(r['cases'], 1):.0f} ms/case)",
    ])  # fmt: skip


def add_case_options(ap: argparse.ArgumentParser) -> None:
    """The options that choose the cases: ``--humans``, ``--first``, ``--cases``, ``--sample``."""
    ap.add_argument("--humans", type=int, default=20, help="number of humans (default 20)")
    ap.add_argument("--first", type=int, default=100, help="first case (default 100)")
    ap.add_argument("--cases", type=int, default=400, help="number of cases (default 400)")
    ap.add_argument("--sample", type=int, default=None, metavar="N",
                    help="N of those cases, drawn by a generator seeded 0")  # fmt: skip


def chosen_cases(ap: argparse.ArgumentParser, args: argparse.Namespace) -> list[int]:
    """The cases :func:`add_case_options`' options choose (a bad value: ``ap.error``, exit 2)."""
    if args.cases < 1 or args.first < 0:
        ap.error(f"--cases must be >= 1 and --first >= 0 (got {args.cases}, {args.first})")
    if not 0 <= args.humans <= 1000:
        ap.error(f"--humans must be in 0..1000 (got {args.humans})")
    cases = list(range(args.first, args.first + args.cases))
    if args.sample is None:
        return cases
    if not 1 <= args.sample <= args.cases:
        ap.error(f"--sample must be in 1..{args.cases} (got {args.sample})")
    drawn = np.random.default_rng(0).choice(cases, args.sample, replace=False)
    return sorted(int(x) for x in drawn)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_case_options(ap)
    ap.add_argument("--accel", type=float, default=ACCEL, help="largest speed change [m/s^2]")
    ap.add_argument("--turn-accel", type=float, default=TURN_ACCEL,
                    help="largest turn-rate change [rad/s^2]")  # fmt: skip
    ap.add_argument("--substeps", type=int, default=SUBSTEPS, help="integration steps per 0.25 s")
    ap.add_argument(
        "--survive",
        type=float,
        default=4.0,
        metavar="T",
        help="horizon of the survival search where no success is found [s]",
    )
    ap.add_argument("--clearance", type=float, default=0.0, metavar="M",
                    help="the gap the oracle keeps from every human [m] (default 0)")  # fmt: skip
    ap.add_argument("--out", type=Path, default=None, help="write oracle-crowdnav-N.json here")
    args = ap.parse_args(argv)
    if args.substeps < 1:
        ap.error(f"--substeps must be >= 1 (got {args.substeps})")
    for name, value in (("--accel", args.accel), ("--turn-accel", args.turn_accel),
                        ("--survive", args.survive)):  # fmt: skip
        if not (math.isfinite(value) and value > 0):
            ap.error(f"{name} must be a number > 0 (got {value!r})")
    if not (math.isfinite(args.clearance) and args.clearance >= 0):
        ap.error(f"--clearance must be a number >= 0 (got {args.clearance!r})")
    cases = chosen_cases(ap, args)
    r = run(cases, humans=args.humans, accel=args.accel, turn_accel=args.turn_accel,
            substeps=args.substeps, survive_s=args.survive, clearance=args.clearance,
            label="oracle")  # fmt: skip
    r["case_numbers"] = cases
    r["sampled"] = args.sample is not None
    print(report(r))
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        r["machine"] = {"cpus": os.cpu_count(), "load": os.getloadavg(),
                        "python": sys.version.split()[0]}  # fmt: skip
        tag = f"-clearance{args.clearance:g}" if args.clearance else ""
        (args.out / f"oracle-crowdnav-{args.humans}{tag}.json").write_text(json.dumps(r, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
