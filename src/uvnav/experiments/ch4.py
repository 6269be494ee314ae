"""Thesis Chapter 4 reproduction and the random-scene campaign (the Ch. 4 part of ``uvnav run``).

:func:`reproduce_ch4` runs

1. every built-in ``thesis-ch4-*`` scene (Figs. 4.2(b), 4.7-4.9) with the thesis's law
   ``zhang2022-uuv2d-v1`` and both baselines on the same sonar (``apf-uuv2d-v1``,
   ``zhang2019-uuv2d-v1``), seed 0, trajectories recorded for the figures — campaign
   ``ch4-thesis-scenes`` (re-run every time: the figures need the trajectories; a missing
   episode is stored, a stored one is kept);
2. a random campaign on ``random-ch4:<seed>`` (1-5 deforming obstacles) with the three laws
   (quick: 10 seeds; ``full``: 200) — campaign ``ch4-random``;
3. a sensor-noise sweep on the same generator: range noise 0.05 / 0.1 m and 10 % dropout
   (quick: 4 seeds per level; ``full``: 50) — campaign ``ch4-noise``;
4. the harder family ``random-ch4-hard:<seed>`` (faster deformation, translating bodies,
   narrower gaps; :func:`~uvnav.scenarios.uuv2d.random_ch4_hard_scenario`) with the three laws
   (quick: 4 seeds; ``full``: 100) — campaign ``ch4-hard``.

Every episode is a scene campaign job (:func:`ch4_job`) run and stored by
:mod:`uvnav.experiments.campaigns` (resumable, fingerprinted, additive) in
``results_dir/uvnav.sqlite``: the ``controller`` column holds the law, ``params`` the sensing
level (the job's tags ``{"noise_std", "dropout"}``, part of the resume key), ``family`` the
generator (``random-ch4``, ``random-ch4-hard``) or the scene; the number of obstacles and whether
a forbidden region (the Fig. 4.2(b) inner space) was entered are kept in ``effective_params``.
The summary
(``results_dir/ch4/summary.json``) and the table "thesis reported vs uvnav measured" are computed
from the stored rows, never typed in. The thesis reports no numbers for Chapter 4 (only Figs.
4.7-4.9: the vehicle reaches E without collision), so the table's thesis column states that; Fig.
4.7's one checkable statement, "t = 0...4 in target approach", is a row of its own
(:func:`target_approach_check` on the recorded run).

Figures are made by a renderer injected by the caller (``render=``; the CLI passes
:func:`uvnav.viz.figures_ch4.render_ch4`), because ``viz`` is a layer above this one (DESIGN §1).
"""

from __future__ import annotations

import functools
import json
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

import uvnav.experiments.campaigns as cp
from uvnav.bench.campaign import Job, outcome_record, run_job, stored_records
from uvnav.bench.fingerprint import DB_NAME
from uvnav.bench.store import FINGERPRINT_KEY, ResultsStore, check_fingerprints
from uvnav.experiments.rows import table_row
from uvnav.scenarios.uuv2d import UUV2D_GENERATORS, list_uuv2d_builtin
from uvnav.sim.episode_uuv2d import Uuv2dTrajectory
from uvnav.sim.metrics import METRIC_NAMES
from uvnav.sim.setup import EpisodeResult

LAW = "zhang2022-uuv2d-v1"
#: Fig. 4.7's scene and the end [s] of its "t = 0...4 in target approach"
FIG47_SCENE, FIG47_UNTIL = "thesis-ch4-fig4-7-approach", 4.0
BASELINES: tuple[str, ...] = ("apf-uuv2d-v1", "zhang2019-uuv2d-v1")
LAWS: tuple[str, ...] = (LAW, *BASELINES)
#: (range noise std [m], dropout probability) levels of the sweep
NOISE_LEVELS: tuple[tuple[float, float], ...] = ((0.05, 0.0), (0.1, 0.0), (0.0, 0.1))
QUICK_SEEDS, FULL_SEEDS = 10, 200
QUICK_NOISE_SEEDS, FULL_NOISE_SEEDS = 4, 50
QUICK_HARD_SEEDS, FULL_HARD_SEEDS = 4, 100
HARD_FAMILY = "random-ch4-hard"
SCENES_CAMPAIGN = "ch4-thesis-scenes"
RANDOM_CAMPAIGN = "ch4-random"
NOISE_CAMPAIGN = "ch4-noise"
HARD_CAMPAIGN = "ch4-hard"
CAMPAIGNS: tuple[str, ...] = (RANDOM_CAMPAIGN, NOISE_CAMPAIGN, HARD_CAMPAIGN)


def ch4_job(scene: str, law: str, seed: int, noise_std: float = 0.0, dropout: float = 0.0) -> Job:
    """One episode as a campaign job: a scene (built-in name or ``random-ch4:<seed>``), a law,
    a seed and the sonar's sensing level (the job's tags: the store's ``params``, part of the
    resume key).  A generated scene is drawn with the sensing level (the generator's
    ``noise_std`` and ``dropout``); a built-in keeps its own sonar.  The job runs as any scene
    job (:func:`uvnav.scenarios.episodes.run_scene`) without the scene's own law parameters."""
    tags = {"noise_std": float(noise_std), "dropout": float(dropout)}
    family, _, number = scene.partition(":")
    where: dict[str, Any] = {"scenario": scene}
    if number and family in UUV2D_GENERATORS:
        where = {"generator": family, "generator_seed": int(number), "generator_params": tags}
    return Job(
        law, int(seed), label=scene, family=family, tags=tags, use_scenario_params=False, **where
    )


def run_ch4_job(
    job: Job, *, record: bool = False
) -> tuple[dict[str, Any], EpisodeResult[Uuv2dTrajectory]]:
    """Run one job in this process; returns its row (as :func:`stored_rows` reads it back) and
    the full result.

    Raises:
        RuntimeError: the episode failed.
    """
    out = run_job(replace(job, record=record))
    return _row(outcome_record(out)), out.result


def _row(rec: dict[str, Any]) -> dict[str, Any]:
    """A stored record (:func:`~uvnav.bench.campaign.stored_records`) as this chapter's row."""
    params, extra = rec["params"], rec["effective_params"]
    return {
        "scene": rec["scenario"],
        "law": rec["controller"],
        "seed": int(rec["seed"]),
        "noise_std": float(params.get("noise_std", 0.0)),
        "dropout": float(params.get("dropout", 0.0)),
        "n_obstacles": int(extra.get("n_obstacles", 0)),
        "status": rec["status"],
        "entered_forbidden": bool(extra.get("entered_forbidden", False)),
        "wall_time": rec.get("wall_time"),
        **{m: rec.get(m) for m in METRIC_NAMES},
        "key": "|".join((rec["scenario"], rec["controller"], str(int(rec["seed"])),
                         f"{params.get('noise_std', 0.0):g}", f"{params.get('dropout', 0.0):g}")),
    }  # fmt: skip


def stored_rows(store: ResultsStore, campaign: str) -> list[dict[str, Any]]:
    """The episode rows of a campaign (store order)."""
    return [_row(r) for r in stored_records(store, campaign)]


#: ``run_jobs(jobs, store, campaign, *, workers=1, progress=None, config=...)``: the rows of
#: ``jobs`` (stored and new, in job order), those ``campaign`` lacks run first
#: (:func:`uvnav.experiments.campaigns.run_rows` with this chapter's row)
run_jobs = functools.partial(cp.run_rows, row=_row, config={"chapter": 4})


def campaign_jobs(
    seeds: int, noise_seeds: int, laws: Iterable[str] = LAWS, start: int = 0
) -> tuple[list[Job], list[Job]]:
    """Jobs of the random campaign (noise-free) and of the sensor-noise sweep (seeds ``start``
    onwards)."""
    laws = tuple(laws)
    seed_range = range(start, start + seeds)
    clean = [ch4_job(f"random-ch4:{s}", law, s) for law in laws for s in seed_range]
    noisy = [
        ch4_job(f"random-ch4:{s}", law, s, noise, drop)
        for noise, drop in NOISE_LEVELS
        for law in laws
        for s in range(start, start + noise_seeds)
    ]
    return clean, noisy


def hard_jobs(seeds: int, laws: Iterable[str] = LAWS, start: int = 0) -> list[Job]:
    """Jobs of the harder family ``random-ch4-hard`` (noise-free), seed by seed from ``start``."""
    return [
        ch4_job(f"{HARD_FAMILY}:{s}", law, s) for s in range(start, start + seeds) for law in laws
    ]


def summarise(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per (scene family, law, noise, dropout): episodes, success / collision / timeout rates,
    forbidden entries, median path length, detour ratio, minimum clearance and decision time."""
    return cp.group_stats(
        rows,
        lambda r: (cp.family(r), r["law"], r["noise_std"], r["dropout"]),
        ("family", "law", "noise_std", "dropout"),
        {
            "entered_forbidden": lambda r: bool(r["entered_forbidden"]),
            "limit_violations": lambda r: int(r["limit_violations"]),
        },
    )


def failures(rows: list[dict[str, Any]], law: str | None = LAW) -> list[dict[str, Any]]:
    """The episodes (of ``law``; every law for ``None``) that did not succeed: scene, seed, law,
    sensing level, obstacles, status (the cause: ``collision`` or ``timeout``), clearance."""
    keep = ("scene", "seed", "law", "noise_std", "dropout", "n_obstacles", "status",
            "min_clearance")  # fmt: skip
    return cp.non_successes((r for r in rows if law is None or r["law"] == law), keep)


@dataclass
class Ch4Summary:
    """What :func:`reproduce_ch4` measured and wrote."""

    scene_rows: list[dict[str, Any]]
    campaign: list[dict[str, Any]]
    failures: list[dict[str, Any]]
    table: list[dict[str, Any]]
    figures: list[Path] = field(default_factory=list)
    #: the results database (``results_dir/uvnav.sqlite``) holding every episode
    rows_path: Path | None = None
    summary_path: Path | None = None
    #: non-successes of every law on the harder family (seed, law, cause)
    hard_failures: list[dict[str, Any]] = field(default_factory=list)


def target_approach_check(traj: Uuv2dTrajectory, until: float = FIG47_UNTIL) -> dict[str, float]:
    """Fig. 4.7's claim on a recorded run: whether every decision up to ``until`` [s] was target
    approach (mode ``M1``), where the vehicle is at ``until`` (``x_m``, ``y_m`` [m]), its
    clearance there [m] and the time of its first avoidance decision [s] (NaN: none)."""
    times = np.asarray(traj.decision_times, dtype=float)
    early = [m for m, t in zip(traj.modes, times, strict=True) if t <= until + 1e-9]
    later = [t for m, t in zip(traj.modes, times, strict=True) if m != "M1"]
    i = min(int(np.searchsorted(traj.times, until - 1e-9)), len(traj.times) - 1)
    return {
        "target_approach": float(all(m == "M1" for m in early)),
        "x_m": float(traj.poses[i, 0]),
        "y_m": float(traj.poses[i, 1]),
        "clearance_m": float(traj.clearance[i]),
        "first_avoidance_s": float(later[0]) if later else math.nan,
    }


def _fig47_row(check: dict[str, float]) -> dict[str, Any]:
    held = "held" if check["target_approach"] else "NOT held"
    return table_row(
        f"Ch.4 Fig. 4.7: target approach for t = 0...{FIG47_UNTIL:g} s",
        f"t = 0...{FIG47_UNTIL:g} in target approach",
        f"{held}; at ({check['x_m']:.2f}, {check['y_m']:.2f}) m at t = {FIG47_UNTIL:g} s",
        f"{LAW}; clearance {check['clearance_m']:.2f} m there; first avoidance decision at "
        f"t = {check['first_avoidance_s']:.1f} s",
    )


def _table(
    scene_rows: list[dict[str, Any]],
    campaign: list[dict[str, Any]],
    fig47: dict[str, float] | None = None,
) -> list[dict[str, Any]]:
    table: list[dict[str, Any]] = [] if fig47 is None else [_fig47_row(fig47)]
    for r in scene_rows:
        if r["law"] != LAW:
            continue
        clear = r["min_clearance"]
        table.append(
            table_row(
                f"Ch.4 {r['scene']}: outcome",
                "reaches E, no collision (figure only)",
                f"{r['status']}, min clearance "
                + (f"{clear:.3f} m" if clear is not None else "-")
                + (", ENTERED inner space" if r["entered_forbidden"] else ""),
                LAW,
                verdict="reproduced"
                if r["status"] == "success" and not r["entered_forbidden"]
                else "differs",
            )
        )
    for c in campaign:
        if c["noise_std"] == 0 and c["dropout"] == 0:
            table.append(
                table_row(
                    f"Ch.4 {c['family']} success ({c['law']}, n={c['episodes']})",
                    "not reported",
                    f"{100 * c['success_rate']:.1f} %",
                    f"collisions {100 * c['collision_rate']:.1f} %",
                )
            )
    return table


def campaign_plans(
    *,
    full: bool = False,
    seeds: int | None = None,
    noise_seeds: int | None = None,
    hard_seeds: int | None = None,
    start_seed: int = 0,
) -> list[tuple[str, dict[str, Any], list[Job]]]:
    """The campaigns :func:`reproduce_ch4` runs with these arguments, (name, config, jobs) in
    order: the thesis scenes, the random family, the noise sweep and the hard family; nothing
    runs."""
    n = seeds if seeds is not None else (FULL_SEEDS if full else QUICK_SEEDS)
    nn = (
        noise_seeds
        if noise_seeds is not None
        else (FULL_NOISE_SEEDS if full else QUICK_NOISE_SEEDS)
    )
    nh = hard_seeds if hard_seeds is not None else (FULL_HARD_SEEDS if full else QUICK_HARD_SEEDS)
    size = {"chapter": 4, "laws": list(LAWS), FINGERPRINT_KEY: cp.fingerprint("experiments/ch4.py")}
    scene_jobs = [ch4_job(scene, law, 0) for scene in list_uuv2d_builtin() for law in LAWS]
    clean, noisy = campaign_jobs(n, nn, start=start_seed)
    return [
        (SCENES_CAMPAIGN, {**size, "seed": 0}, scene_jobs),
        (RANDOM_CAMPAIGN, {**size, "seeds": n}, clean),
        (NOISE_CAMPAIGN, {**size, "seeds": nn, "levels": NOISE_LEVELS}, noisy),
        (HARD_CAMPAIGN, {**size, "seeds": nh}, hard_jobs(nh, start=start_seed)),
    ]


def reproduce_ch4(
    results_dir: Path,
    report_dir: Path | None = None,
    *,
    full: bool = False,
    workers: int = 1,
    render: Callable[..., list[Path]] | None = None,
    seeds: int | None = None,
    noise_seeds: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    hard_seeds: int | None = None,
    start_seed: int = 0,
) -> Ch4Summary:
    """Run the Chapter 4 reproduction and campaign (see the module docstring).

    Args:
        results_dir: where the results database ``uvnav.sqlite`` and ``ch4/summary.json`` go.
        report_dir: where the renderer puts figures (``report_dir/ch4``).
        full: thesis-size campaign (200 seeds, 50 per noise level, 100 hard) instead of the
            quick one.
        workers: processes for the campaign.
        render: ``render(out_dir, scene_results, summary) -> [paths]`` (figures).
        seeds, noise_seeds, hard_seeds: override the campaign sizes.
        progress: ``progress(done, total)`` after each campaign episode.
        start_seed: first seed of every random family (seeds ``start_seed`` onwards).

    Additive (:mod:`uvnav.experiments.campaigns`): the thesis scenes run again for the figures'
    trajectories, only missing episodes are stored.

    Raises:
        StaleCampaignError: a stored campaign of this chapter was made by other code (its
            :func:`fingerprint` differs; nothing runs).
    """
    results_dir = Path(results_dir)
    out_dir = results_dir / "ch4"
    out_dir.mkdir(parents=True, exist_ok=True)
    db_path = results_dir / DB_NAME
    plans = campaign_plans(
        full=full, seeds=seeds, noise_seeds=noise_seeds, hard_seeds=hard_seeds,
        start_seed=start_seed,
    )  # fmt: skip
    (_, scene_cfg, scene_jobs), *campaigns = plans
    with ResultsStore(db_path) as store:
        check_fingerprints(store, {name: cfg[FINGERPRINT_KEY] for name, cfg, _ in plans})
        # run again for the figures' trajectories; stored only when missing
        kept = cp.run_recorded(store, SCENES_CAMPAIGN, scene_jobs, config=scene_cfg)
        scene_results: dict[tuple[str, str], EpisodeResult[Uuv2dTrajectory]] = {
            (str(j.label), j.controller): kept[j.key] for j in scene_jobs
        }
        scene_rows = [_row(r) for r in cp.job_records(store, SCENES_CAMPAIGN, scene_jobs)]
        rows_random, rows_noise, rows_hard = [
            run_jobs(jobs, store, name, workers=workers, progress=progress, config=cfg)
            for name, cfg, jobs in campaigns
        ]
    rows = rows_random + rows_noise + rows_hard
    campaign = summarise(rows)
    fails = failures(rows_random)
    hard_fails = failures(rows_hard, law=None)
    fig = scene_results.get((FIG47_SCENE, LAW))
    traj = None if fig is None else fig.trajectory
    table = _table(scene_rows, campaign, None if traj is None else target_approach_check(traj))
    summary_path = out_dir / "summary.json"
    summary_path.write_text(
        json.dumps(
            {
                "scenes": scene_rows,
                "campaign": campaign,
                "failures": fails,
                "hard_failures": hard_fails,
                "table": table,
                "database": str(db_path),
                "campaigns": [SCENES_CAMPAIGN, *CAMPAIGNS],
            },
            indent=1,
            default=lambda x: None if isinstance(x, float) and not math.isfinite(x) else str(x),
        ),
        encoding="utf-8",
    )
    summary = Ch4Summary(scene_rows, campaign, fails, table, [], db_path, summary_path, hard_fails)
    if render is not None and report_dir is not None:
        summary.figures = list(render(Path(report_dir) / "ch4", scene_results, summary))
    return summary
