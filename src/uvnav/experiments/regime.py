"""Where each law wins: the regime map campaign and its generated recommendations.

The regime map runs every registered 2D law (:func:`uvnav.experiments.crowds.crowd_laws`: the
unicycle laws and the holonomic ones, so laws registered later join by themselves) on CrowdNav's
circle crossing (:mod:`uvnav.scenarios.crowdnav`: humans on a 4 m circle walking to the opposite
point, the robot from (0, -4) to (0, 4) at V_max 1 m/s, 24 s) over a grid of regimes

* crowd density: :data:`DENSITIES` humans on the circle (``n_humans``);
* pedestrian speed / V_max: :data:`SPEED_RATIOS` (the humans' preferred speed ``human_v_pref``;
  the robot's V_max is CrowdNav's 1 m/s, so the ratio is the speed in m/s);
* the robot invisible to the humans (CrowdNav's test protocol) or visible (they avoid it);
* sensing: exact (velocities known) or noisy (velocities estimated by finite differences of
  centres sensed with Gaussian noise of :data:`NOISES` std, :mod:`uvnav.prediction`), or a lidar
  alone (:data:`LIDAR_BEAMS` beams over a full turn, :data:`LIDAR_NOISE` range noise, range and
  sensing range :data:`LIDAR_RANGE`; the humans the scan shows, tracked, their velocities
  estimated: :mod:`uvnav.sensors.scan_bodies`), for the robot visible or not as
  :data:`LIDAR_VISIBLE` says,

and, in a slice at the default regime (humans at V_max, robot invisible, exact sensing: CrowdNav's
protocol) rather than across the whole grid, two more axes:

* crowd size :data:`LARGE_CROWD` (20 humans on the same circle);
* vehicle limits: the unicycle ideal (speed and turn rate follow the command at once) or
  acceleration-limited (:data:`ACCEL_MAX`, :data:`TURN_ACCEL_MAX`: ``UnicycleSpec.accel_max``,
  ``turn_accel_max``) at :data:`LIMITED_DENSITIES`; only the laws whose vehicle keeps those
  limits run there (:func:`keeps_limits`: the unicycle laws; the holonomic robot has none, and
  would repeat its ideal cell),

with the same ``seeds`` test cases in every cell (:data:`QUICK_SEEDS` in ``uvnav run``,
:data:`FULL_SEEDS` with ``--full``), in one campaign :data:`CAMPAIGN` of the results store (the
campaign machinery: resumable, fingerprinted like Chapter 2's).  Every law runs in every cell,
beyond its declared assumption where the cell breaks it (the thesis's laws assume obstacles slower
than the robot, (2.6)): the map is a measurement of where each law works, and each such cell says
so (:attr:`CellStats.beyond`).

Per cell and law: success rate and *robot-driven* collision rate (a collision whose gap the robot
closed, ``collision_by == "robot"``, :mod:`uvnav.sim.social`), each with its 95 % Wilson interval
(:func:`uvnav.bench.summary.wilson_interval`).  :func:`recommend` turns one regime's numbers into a
paragraph: the best law by success, ties decided by overlapping intervals (every law whose interval
overlaps the best one's cannot be told apart from it on this evidence, and the text says so).

:func:`family_table` is the law x scene-family view of the report's first screen: for every 2D
scene family in the store, each law's success and collision rates on the *same* seeds (the scenes
every law of that family ran), so no law is compared on more or easier scenes than another.

Everything here reads the store or pure numbers; drawing is :mod:`uvnav.viz.regime`'s.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from uvnav.bench.fingerprint import DB_NAME, code_fingerprint
from uvnav.bench.jobs import Job
from uvnav.bench.store import STATUS_ERROR, STATUS_REFUSED, ResultsStore
from uvnav.bench.summary import wilson_interval
from uvnav.experiments.campaigns import run_checked
from uvnav.experiments.crowds import crowd_laws
from uvnav.experiments.rows import rate_text
from uvnav.experiments.sections import TITLES, ChapterSection, mode_text

CAMPAIGN = "regime-map"
GENERATOR = "crowdnav-circle"
#: humans on CrowdNav's 4 m circle (about 0.08, 0.14, 0.20 humans per m^2 of the disc; 12
#: slow humans cannot always be placed apart on the circle, CrowdSim's placement rule)
DENSITIES: tuple[int, ...] = (4, 7, 10)
#: humans' preferred speed / robot V_max
SPEED_RATIOS: tuple[float, ...] = (0.5, 1.0, 1.5)
VISIBLE: tuple[bool, ...] = (False, True)
#: std of the noise on sensed centres [m]; 0 = exact sensing (velocities known)
NOISES: tuple[float, ...] = (0.0, 0.1)
#: the lidar of the lidar cells: beams over a full turn, range noise std [m], range [m] (also the
#: sensing range), as ``benchmarks/bench_crowdnav.py --lidar 360`` senses
LIDAR_BEAMS, LIDAR_NOISE, LIDAR_RANGE = 360, 0.01, 5.0
#: the robot visibilities that get lidar cells: the invisible robot, CrowdNav's test protocol
#: (the visible robot's cells would add a third of the map's cost again)
LIDAR_VISIBLE: tuple[bool, ...] = (False,)
#: the robot's V_max in these scenes [m/s] (CrowdNav's robot ``v_pref``)
V_MAX = 1.0
#: the slice of the vehicle-limits and crowd-size axes: one speed ratio, the robot invisible,
#: exact sensing (module docstring)
SLICE_SPEED = 1.0
#: the large crowd of the slice (CrowdSim's rule cannot place 20 humans apart on the 4 m circle
#: for a few cases: those seeds are left out of that cell, :func:`placeable`)
LARGE_CROWD = 20
#: the acceleration-limited unicycle of the slice: speed [m/s^2] and turn-rate [rad/s^2] limits
#: (|dv| <= 0.1 m/s per 0.1 s)
ACCEL_MAX, TURN_ACCEL_MAX = 1.0, 2.0
#: the crowds of the slice run on the acceleration-limited unicycle
LIMITED_DENSITIES: tuple[int, ...] = (4, 7, 10, LARGE_CROWD)
QUICK_SEEDS, FULL_SEEDS = 30, 100
#: a rate on fewer episodes than this is flagged as a small sample
SMALL_SAMPLE = 30


@dataclass(frozen=True, order=True)
class Regime:
    """One cell of the grid: humans, their speed / V_max, robot visible, sensing noise [m],
    whether the robot senses by lidar alone (then ``noise`` is 0), and whether the unicycle has
    acceleration limits (:data:`ACCEL_MAX`, :data:`TURN_ACCEL_MAX`)."""

    n_humans: int
    speed_ratio: float
    visible: bool
    noise: float
    lidar: bool = False
    limited: bool = False

    def generator_params(self) -> dict[str, Any]:
        """Keyword arguments of the ``crowdnav-circle`` generator for this cell."""
        p: dict[str, Any] = {
            "n_humans": int(self.n_humans),
            "human_v_pref": float(self.speed_ratio) * V_MAX,
            "robot_visible": bool(self.visible),
        }
        if self.noise > 0:
            p.update(velocities="estimated", position_noise=float(self.noise))
        if self.lidar:
            p.update(
                bodies="lidar", velocities="estimated", lidar_beams=LIDAR_BEAMS,
                lidar_noise=LIDAR_NOISE, sensing_range=LIDAR_RANGE,
            )  # fmt: skip
        if self.limited:
            p.update(accel_max=ACCEL_MAX, turn_accel_max=TURN_ACCEL_MAX)
        return p

    @property
    def family(self) -> str:
        """The scenario family its episodes are stored under (the generator label)."""
        return Job(
            controller="straight-v1",
            seed=0,
            generator=GENERATOR,
            generator_seed=0,
            generator_params=self.generator_params(),
        ).family_label

    @property
    def sensing(self) -> str:
        """``"exact sensing"``, ``"noise 0.1 m"`` or ``"lidar 360 beams"``."""
        if self.lidar:
            return f"lidar {LIDAR_BEAMS} beams"
        return "exact sensing" if self.noise == 0 else f"noise {self.noise:g} m"

    @property
    def vehicle(self) -> str:
        """``"ideal vehicle"`` or ``"accel-limited 1 m/s², 2 rad/s²"``."""
        if not self.limited:
            return "ideal vehicle"
        return f"accel-limited {ACCEL_MAX:g} m/s², {TURN_ACCEL_MAX:g} rad/s²"

    @property
    def label(self) -> str:
        """``"8 humans, speed 1.5 V_max, invisible robot, exact sensing"``, with
        ``", accel-limited 1 m/s², 2 rad/s²"`` on a vehicle with limits."""
        seen = "visible" if self.visible else "invisible"
        return (
            f"{self.n_humans} humans, speed {self.speed_ratio:g} V_max, {seen} robot, "
            f"{self.sensing}" + (f", {self.vehicle}" if self.limited else "")
        )


def regimes(
    densities: Sequence[int] = DENSITIES,
    speed_ratios: Sequence[float] = SPEED_RATIOS,
    visible: Sequence[bool] = VISIBLE,
    noises: Sequence[float] = NOISES,
    lidar_visible: Sequence[bool] = LIDAR_VISIBLE,
    large: Sequence[int] = (LARGE_CROWD,),
    limited: Sequence[int] = LIMITED_DENSITIES,
) -> list[Regime]:
    """The grid, visible and sensing outermost (the report's panels), then speed, then density;
    the lidar cells (for the visibilities of ``lidar_visible``) after the others; then the slice
    (module docstring): the crowds of ``large`` on the ideal vehicle and those of ``limited`` on
    the acceleration-limited one, at :data:`SLICE_SPEED`, robot invisible, exact sensing."""
    cells = [
        Regime(int(n), float(s), bool(v), float(z))
        for v in visible
        for z in noises
        for s in speed_ratios
        for n in densities
    ]
    lidar = [
        Regime(int(n), float(s), bool(v), 0.0, True)
        for v in lidar_visible
        for s in speed_ratios
        for n in densities
    ]
    slice_ = [Regime(int(n), SLICE_SPEED, False, 0.0) for n in large]
    slice_ += [Regime(int(n), SLICE_SPEED, False, 0.0, limited=True) for n in limited]
    return cells + lidar + slice_


def keeps_limits(law: str) -> bool:
    """Whether ``law``'s vehicle keeps the acceleration limits of the limited cells (a unicycle
    does; the holonomic robot has none)."""
    from uvnav.controllers.base import controller_info
    from uvnav.dynamics.unicycle import UnicycleSpec
    from uvnav.dynamics.vehicles import make_vehicle

    spec = UnicycleSpec(V_MAX, 1.0, accel_max=ACCEL_MAX, turn_accel_max=TURN_ACCEL_MAX)
    return not getattr(make_vehicle(controller_info(law).vehicle, spec).spec, "ideal", True)


def placeable(cell: Regime, seed: int) -> bool:
    """Whether CrowdSim's rule places the cell's humans apart for test case ``seed`` (always
    for the grid's densities; a few cases of :data:`LARGE_CROWD` humans fail)."""
    from uvnav.scenarios.crowdnav import crowdnav_scenario
    from uvnav.scenarios.errors import ScenarioError

    if cell.n_humans <= max(DENSITIES):
        return True
    try:
        crowdnav_scenario(seed, rule="circle_crossing", **cell.generator_params())
    except ScenarioError:
        return False
    return True


def regime_jobs(laws: Sequence[str], cells: Sequence[Regime], seeds: range) -> list[Job]:
    """One job per cell, seed and law, every law beyond its assumptions (module docstring); a
    limited cell's laws are those that keep its limits, a cell's seeds those it can place."""
    keeps = {law: keeps_limits(law) for law in laws}
    return [
        Job(
            controller=law,
            seed=g,
            generator=GENERATOR,
            generator_seed=g,
            generator_params=cell.generator_params(),
            beyond_assumptions=True,
        )
        for cell in cells
        for g in seeds
        if placeable(cell, g)
        for law in laws
        if keeps[law] or not cell.limited
    ]


@dataclass
class RegimeSummary:
    """What :func:`run_regime_map` ran: laws, cells, seeds per cell, campaign counts."""

    db_path: Path
    laws: list[str]
    cells: list[Regime]
    seeds: int
    full: bool
    campaign: dict[str, Any] = field(default_factory=dict)
    wall_time: float = 0.0


def campaign_plans(
    *,
    full: bool = False,
    seeds: int | None = None,
    start_seed: int = 0,
    laws: Sequence[str] | None = None,
    cells: Sequence[Regime] | None = None,
) -> list[tuple[str, dict[str, Any], list[Job]]]:
    """The one campaign :func:`run_regime_map` runs with these arguments, as (name, config,
    jobs); nothing runs."""
    run_laws = list(crowd_laws()[0] if laws is None else laws)
    grid = list(regimes() if cells is None else cells)
    n = seeds if seeds is not None else (FULL_SEEDS if full else QUICK_SEEDS)
    cfg = {
        "generator": GENERATOR,
        "controllers": run_laws,
        "cells": [
            [c.n_humans, c.speed_ratio, c.visible, c.noise, c.lidar, c.limited] for c in grid
        ],
        "v_max": V_MAX,
        "beyond_assumptions": True,
        "fingerprint": code_fingerprint(),
    }
    return [(CAMPAIGN, cfg, regime_jobs(run_laws, grid, range(start_seed, start_seed + n)))]


def run_regime_map(
    results_dir: Path,
    *,
    full: bool = False,
    workers: int = 2,
    seeds: int | None = None,
    start_seed: int = 0,
    laws: Sequence[str] | None = None,
    cells: Sequence[Regime] | None = None,
    progress: bool = False,
) -> RegimeSummary:
    """Run the regime map into ``results_dir/uvnav.sqlite`` (stored episodes are skipped).

    Args:
        results_dir: folder of the results database (created).
        full: :data:`FULL_SEEDS` seeds per cell instead of :data:`QUICK_SEEDS`.
        workers: worker processes (1 = in-process).
        seeds: seeds (CrowdNav test cases) per cell, overriding the quick/full size.
        start_seed: the first seed.
        laws: laws to run (default every registered 2D law).
        cells: the grid (default :func:`regimes`).
        progress: rich progress bars on stderr.

    Raises:
        StaleCampaignError: the stored campaign was made by other code.
    """
    tic = time.perf_counter()
    results_dir = Path(results_dir)
    results_dir.mkdir(parents=True, exist_ok=True)
    db_path = results_dir / DB_NAME
    run_laws = list(crowd_laws()[0] if laws is None else laws)
    grid = list(regimes() if cells is None else cells)
    n = seeds if seeds is not None else (FULL_SEEDS if full else QUICK_SEEDS)
    plans = campaign_plans(full=full, seeds=seeds, start_seed=start_seed, laws=laws, cells=cells)
    with ResultsStore(db_path) as store:
        done = run_checked(store, plans, workers=workers, progress=progress)
    return RegimeSummary(
        db_path=db_path,
        laws=run_laws,
        cells=grid,
        seeds=n,
        full=full,
        campaign=done[CAMPAIGN],
        wall_time=time.perf_counter() - tic,
    )


# ----------------------------------------------------------------------------- cells from the store


@dataclass(frozen=True)
class Rate:
    """``k`` of ``n`` with its 95 % Wilson interval."""

    k: int
    n: int

    @property
    def p(self) -> float:
        return self.k / self.n if self.n else 0.0

    @property
    def interval(self) -> tuple[float, float]:
        return wilson_interval(self.k, self.n)

    @property
    def small(self) -> bool:
        """Fewer episodes than :data:`SMALL_SAMPLE`."""
        return self.n < SMALL_SAMPLE

    def text(self, digits: int = 2) -> str:
        """``"0.87 [0.62, 0.96]"``, with ``" n=15 (small)"`` for a small sample."""
        if self.n == 0:
            return "no episodes"
        return rate_text(self.k, self.n, f".{digits}f") + (
            f" n={self.n} (small)" if self.small else ""
        )


@dataclass(frozen=True)
class CellStats:
    """One law in one regime: success and robot-driven collision (and all collisions)."""

    law: str
    success: Rate
    robot_collision: Rate
    collision: Rate
    beyond: bool = False
    errors: int = 0


def _rates(g: Any) -> tuple[Rate, Rate, Rate, int]:
    status = g["status"].astype(str)
    errors = int((status == STATUS_ERROR).sum())
    ok = g[~status.isin((STATUS_ERROR, STATUS_REFUSED))]
    n = len(ok)
    st = ok["status"].astype(str)
    hit = st == "collision"
    by = ok["collision_by"].astype(object).where(hit, None)
    return (
        Rate(int((st == "success").sum()), n),
        Rate(int((by == "robot").sum()), n),
        Rate(int(hit.sum()), n),
        errors,
    )


def cell_stats(store: ResultsStore) -> dict[Regime, list[CellStats]]:
    """Per regime of the stored campaign, one :class:`CellStats` per law (laws sorted), on the
    seeds every law of that cell ran (equal samples); empty when the campaign is not stored."""
    camp = next((c for c in store.campaigns() if c["name"] == CAMPAIGN), None)
    if camp is None:
        return {}
    df = store.episodes_frame(CAMPAIGN)
    if df.empty:
        return {}
    cells = [_regime(row) for row in camp["config"]["cells"]]
    out: dict[Regime, list[CellStats]] = {}
    for cell in cells:
        g = equal_seeds(df[df["family"].astype(str) == cell.family])
        if g.empty:
            continue
        stats = []
        for law, gl in g.groupby("controller", sort=True):
            s, rc, c, err = _rates(gl)
            beyond = _slower(str(law)) and cell.speed_ratio >= 1.0
            stats.append(CellStats(str(law), s, rc, c, beyond=beyond, errors=err))
        out[cell] = stats
    return out


def _regime(row: Sequence[Any]) -> Regime:
    """A stored cell ``[n, speed ratio, visible, noise(, lidar(, limited))]``."""
    lidar = bool(row[4]) if len(row) > 4 else False
    limited = bool(row[5]) if len(row) > 5 else False
    return Regime(int(row[0]), float(row[1]), bool(row[2]), float(row[3]), lidar, limited)


@dataclass(frozen=True)
class SensingCost:
    """One law's success pooled over the regimes that have a lidar cell, per way of sensing,
    on the same crowds (densities, speeds, visibility): exact, noisy centres, lidar alone."""

    law: str
    exact: Rate
    noisy: Rate
    lidar: Rate

    @property
    def lidar_cost(self) -> float:
        """Success lost by sensing with the lidar instead of exactly (points of a rate)."""
        return self.exact.p - self.lidar.p


def sensing_costs(stats_by_cell: dict[Regime, list[CellStats]]) -> list[SensingCost]:
    """What sensing costs each law: per law its successes pooled over every lidar cell and the
    exact and noisy cells of the same crowds (each law on its own equal seeds per cell), laws
    by decreasing lidar success; empty without lidar cells."""
    pooled: dict[str, dict[str, list[int]]] = {}
    for cell in (c for c in stats_by_cell if c.lidar):
        twins = {"lidar": [cell]}
        same = [
            c
            for c in stats_by_cell
            if not c.lidar
            and not c.limited
            and (c.n_humans, c.speed_ratio, c.visible)
            == (cell.n_humans, cell.speed_ratio, cell.visible)
        ]
        twins["exact"] = [c for c in same if c.noise == 0]
        twins["noisy"] = [c for c in same if c.noise > 0]
        for mode, cells in twins.items():
            for c in cells:
                for s in stats_by_cell[c]:
                    k_n = pooled.setdefault(s.law, {}).setdefault(mode, [0, 0])
                    k_n[0] += s.success.k
                    k_n[1] += s.success.n
    out = [
        SensingCost(law, *(Rate(*modes.get(m, [0, 0])) for m in ("exact", "noisy", "lidar")))
        for law, modes in pooled.items()
    ]
    return sorted(out, key=lambda c: (-c.lidar.p, c.law))


def equal_seeds(df: Any) -> Any:
    """The rows of ``df`` (an episodes frame) on the scenes every controller in it ran, refused
    and error episodes aside: each law is then measured on the same scenes."""
    status = df["status"].astype(str)
    ok = df[~status.isin((STATUS_ERROR, STATUS_REFUSED))]
    if ok.empty:
        return ok
    keys = ok["scenario"].astype(str) + "#" + ok["seed"].astype(str)
    per_law = [set(keys[ok["controller"] == c]) for c in ok["controller"].unique()]
    common = set.intersection(*per_law)
    return ok[keys.isin(common)]


# ------------------------------------------------------------------------ the recommendation


def _overlap(a: tuple[float, float], b: tuple[float, float]) -> bool:
    return a[0] <= b[1] and b[0] <= a[1]


def ranking(stats: Sequence[CellStats]) -> tuple[list[CellStats], list[CellStats]]:
    """``(best, rest)``: the laws ordered by success (then fewer robot-driven collisions, then
    name); ``best`` is the top law and every law whose success interval overlaps its interval
    (the evidence cannot separate them), ``rest`` the laws clearly below."""
    ordered = sorted(
        (s for s in stats if s.success.n > 0),
        key=lambda s: (-s.success.p, s.robot_collision.p, s.law),
    )
    if not ordered:
        return [], []
    top = ordered[0].success.interval
    best = [s for s in ordered if _overlap(s.success.interval, top)]
    rest = [s for s in ordered if s not in best]
    return best, rest


def _pct(r: Rate) -> str:
    return rate_text(r.k, r.n, ".0%")


#: the mark of a law run beyond the assumption it declares (thesis (2.6)) in that cell
BEYOND_MARK = "†"


def _name(s: CellStats) -> str:
    return s.law + (BEYOND_MARK if s.beyond else "")


def recommend(regime_label: str, stats: Sequence[CellStats]) -> str:
    """One paragraph for one regime, generated from the numbers (module docstring).

    Names the best law by success with its interval and robot-driven collision rate; when other
    laws' success intervals overlap the best one's it says the evidence cannot separate them;
    flags small samples and cells where no law succeeds.
    """
    best, rest = ranking(stats)
    if not best:
        return f"{regime_label}: no episodes stored."
    n = min(s.success.n for s in best + rest)
    top = best[0]
    if top.success.k == 0:
        text = f"{regime_label}: no law reached the goal in {n} episodes each; none can be "
        return text + "recommended here."
    lead = (
        f"{_name(top)} succeeds most often: {_pct(top.success)}, robot-driven collisions "
        f"{_pct(top.robot_collision)}."
    )
    if len(best) == 1:
        runner = (
            f" The runner-up, {_name(rest[0])}, reaches {_pct(rest[0].success)}" if rest else ""
        )
        text = f"{regime_label}: use {top.law}. {lead}{runner}" + (
            "; the intervals do not overlap, so the lead is real." if rest else "."
        )
    else:
        others = ", ".join(f"{_name(s)} {s.success.p:.0%}" for s in best[1:])
        safest = min(best, key=lambda s: (s.robot_collision.p, -s.success.p, s.law))
        text = (
            f"{regime_label}: the evidence cannot separate {_name(top)} from {others} (success "
            f"intervals overlap its own). {lead}"
        )
        if safest is not top:
            text += (
                f" Among them {_name(safest)} drives into people least "
                f"({_pct(safest.robot_collision)} robot-driven collisions)."
            )
    below = [s for s in rest if s is not (rest[0] if len(best) == 1 else None)]
    if below:
        listed = ", ".join(f"{_name(s)} {s.success.p:.0%}" for s in below)
        text += f" Clearly below: {listed}."
    if n < SMALL_SAMPLE:
        text += f" Small sample ({n} episodes per law): run more seeds (--full) to narrow this."
    return text


def leaders(stats_by_cell: dict[Regime, list[CellStats]]) -> list[dict[str, str]]:
    """One short row per regime for a console: the regime, the law that succeeds most often
    with its rate and 95 % interval, and how many other laws the evidence cannot separate from
    it (:func:`ranking`); the paragraphs of :func:`recommend` are the report's."""
    rows = []
    for cell, stats in stats_by_cell.items():
        best, _ = ranking(stats)
        if not best:
            continue
        top = best[0]
        rows.append(
            {
                "regime": (
                    f"{cell.n_humans} × {cell.speed_ratio:g} V_max, "
                    f"{'visible' if cell.visible else 'invisible'}, {cell.sensing}"
                    + (f", {cell.vehicle}" if cell.limited else "")
                ),
                "best": _name(top),
                "success": _pct(top.success),
                "robot_driven": f"{top.robot_collision.p:.0%}",
                "tied": str(len(best) - 1),
            }
        )
    return rows


def law_lines(stats_by_cell: dict[Regime, list[CellStats]]) -> list[str]:
    """ "Which law, where" in a few lines: per panel of the map (robot visible or not, sensing)
    the law that is best or tied best (:func:`ranking`) in the most of its regimes, with how
    many; empty without a stored map."""
    panels: dict[tuple[bool, bool, bool, float], list[Regime]] = {}
    for cell in stats_by_cell:
        panels.setdefault((cell.limited, cell.visible, cell.lidar, cell.noise), []).append(cell)
    lines = []
    for (limited, visible, lidar, noise), cells in sorted(panels.items()):
        wins: dict[str, int] = {}
        for c in cells:
            for s in ranking(stats_by_cell[c])[0]:
                wins[s.law] = wins.get(s.law, 0) + 1
        if not wins:
            continue
        top = max(wins.values())
        laws = sorted(law for law, k in wins.items() if k == top)
        panel = Regime(0, 0.0, visible, noise, lidar, limited)
        shown = ", ".join(laws[:2]) + (f" +{len(laws) - 2}" if len(laws) > 2 else "")
        seen = "visible" if visible else "invisible"
        vehicle = f", {panel.vehicle}" if limited else ""
        lines.append(f"  {seen} robot, {panel.sensing}{vehicle}: {shown} ({top}/{len(cells)})")
    if lines:
        lines.insert(0, "which law, where (regime map: best or tied best in most regimes):")
    return lines


# --------------------------------------------------------------------- law x scene family


#: campaigns whose laws that assume slower obstacles ran beyond that assumption
_BEYOND_CAMPAIGNS = frozenset({"crowdnav-beyond", "crowds-eth"})
#: campaigns the family table leaves out (the regime map has its own view; 3D/UUV are other
#: vehicles' families, kept apart by their chapters)
_OTHER_CAMPAIGNS = frozenset({CAMPAIGN})


@dataclass(frozen=True)
class FamilyCell:
    """One law on one scene family, on the seeds every law of the family ran."""

    family: str
    law: str
    success: Rate
    collision: Rate
    beyond: bool
    ran: int  # episodes of this law on the family before equalising


def family_table(store: ResultsStore, *, families: Sequence[str] | None = None) -> list[FamilyCell]:
    """Law x scene family at equal seeds, for every 2D family of the store (or ``families``):
    per family the scenes every law of it ran (refused and error episodes aside; a law refused
    everywhere in a campaign but run in its ``-beyond`` twin counts with those episodes)."""
    from uvnav.controllers.base import available_controllers

    laws2d = set(available_controllers("unicycle")) | set(available_controllers("holonomic"))
    df = store.episodes_frame()
    if df.empty:
        return []
    df = df[~df["campaign"].astype(str).isin(_OTHER_CAMPAIGNS)]
    df = df[df["controller"].astype(str).isin(laws2d)]
    df = df[~df["scenario"].astype(str).str.startswith("thesis-")]  # one scene each: no rate
    df = df[~df["status"].astype(str).isin((STATUS_ERROR, STATUS_REFUSED))]
    if df.empty:
        return []
    fam = df["family"].astype(str).str.split("[", n=1).str[0]
    df = df.assign(family_base=fam)
    out: list[FamilyCell] = []
    chosen = sorted(set(fam)) if families is None else list(families)
    for family in chosen:
        g = df[df["family_base"] == family]
        if g.empty:
            continue
        g = g.drop_duplicates(["scenario", "controller", "seed"])
        ran = g.groupby("controller").size().to_dict()
        eq = equal_seeds(g)
        for law, gl in eq.groupby("controller", sort=True):
            st = gl["status"].astype(str)
            n = len(gl)
            beyond = bool(gl["campaign"].astype(str).isin(_BEYOND_CAMPAIGNS).any())
            out.append(
                FamilyCell(
                    family=family,
                    law=str(law),
                    success=Rate(int((st == "success").sum()), n),
                    collision=Rate(int((st == "collision").sum()), n),
                    beyond=beyond and _slower(str(law)),
                    ran=int(ran.get(law, n)),
                )
            )
    return out


def _slower(law: str) -> bool:
    """Whether ``law`` assumes obstacles slower than the robot (``False`` for a law stored by a
    plug-in no longer installed)."""
    from uvnav.controllers.base import UnknownControllerError, requires_slower_obstacles

    try:
        return requires_slower_obstacles(law)
    except UnknownControllerError:
        return False


# ------------------------------------------------------------------------------ the section


def regime_section(summary: RegimeSummary | None, *, full: bool) -> ChapterSection:
    """The regime map's section of the report from a run's :class:`RegimeSummary`
    (``None``: rebuilt from the store, what was run unknown).  Its numbers are the report's first
    screen ("Which law, where", drawn from the store), so the section only says what ran."""
    if summary is None:
        ran = "every stored cell and law"
    else:
        dens = ", ".join(str(d) for d in sorted({c.n_humans for c in summary.cells}))
        speeds = ", ".join(f"{v:g}" for v in sorted({c.speed_ratio for c in summary.cells}))
        noises = ", ".join(f"{z:g}" for z in sorted({c.noise for c in summary.cells}))
        lidar = (
            f" or a {LIDAR_BEAMS}-beam lidar alone" if any(c.lidar for c in summary.cells) else ""
        )
        limited = sorted({c.n_humans for c in summary.cells if c.limited})
        vehicle = (
            f"; the unicycle ideal or {Regime(0, 0.0, False, 0.0, limited=True).vehicle} "
            f"({', '.join(map(str, limited))} humans, the laws whose vehicle keeps the limits)"
            if limited
            else ""
        )
        ran = (
            f"{len(summary.cells)} regimes ({dens} humans; speed {speeds} x V_max; robot "
            f"invisible and visible; sensing noise {noises} m{lidar}{vehicle}), {summary.seeds} "
            f"seed{'' if summary.seeds == 1 else 's'} per regime "
            f"and law ({mode_text(full)}), laws {', '.join(summary.laws)}"
        )
    return ChapterSection(
        key="regime",
        title=TITLES["regime"],
        intro=(
            f"Every 2D law on CrowdNav's circle crossing over crowd density x pedestrian speed / "
            f"V_max x robot visible or not x sensing, and at the default regime (speed "
            f"{SLICE_SPEED:g} V_max, invisible robot, exact sensing) {LARGE_CROWD} humans and "
            f"vehicle limits (campaign {CAMPAIGN}): {ran}. Every "
            "law runs in every regime, beyond its declared assumption where the regime breaks it "
            "(marked †)."
        ),
        notes=[
            "The heat maps, the recommendation per regime and every cell's rates with 95 % "
            "intervals are the first screen of this report ('Which law, where'), read from the "
            "store."
        ],
    )
