"""Thesis Chapter 3 reproduction and campaign (3D flying robot, AR prediction).

:func:`reproduce_ch3` runs

1. every built-in ``thesis-ch3-*`` scene (Fig. 3.5 single cycle, Figs. 3.6-3.7 whole manoeuvre,
   several obstacles) with ``zhang2020-3d-v1`` (thesis Ch. 3 §3.3), ``apf3d-v1`` and ``vo3d-v1``,
   seed 0, rates estimated from what is sensed (AR-predicted by the thesis's law) — campaign
   ``ch3-thesis-scenes``, trajectories kept for the figures;
2. the three laws on ``random-ch3:<seed>`` scenes with the obstacles' motion *known* (oracle:
   true v_i, u_i) and *predicted* (finite differences of what is sensed, AR models in
   ``zhang2020-3d-v1``; the baselines use the finite differences as they are) — campaign
   ``ch3-random``; quick mode ``QUICK_SEEDS`` seeds, ``full=True`` ``FULL_SEEDS``;
3. the one-step velocity prediction error of the AR models against constant velocity on the AR
   motion of the random scenes' obstacles (sampled every T_s = 1 s);
4. *what prediction buys*: on the default family (``random-ch3``, slowly varying AR
   motion) and on the periodic one (``random-ch3-periodic``, weaving / circling bodies whose
   velocity is a noise-driven oscillator), the AR models' k-step velocity and position errors
   against constant velocity (:func:`horizon_errors`), and ``zhang2020-3d-v1`` closed loop with
   AR prediction (``prediction="ar"``), constant velocity (``prediction="last"``: the sensed rates
   as they are) and the oracle (true rates) — campaign ``ch3-prediction``, at least
   ``PREDICTION_MIN_SEEDS`` seeds per family; :func:`prediction_finding` turns the numbers into
   the section's one sentence.

Every episode is a scene campaign job (:func:`ch3_job`) run and stored by
:mod:`uvnav.experiments.campaigns` (resumable, fingerprinted, additive), the controller column
holding the law and ``params`` the motion knowledge (``{"motion": "known"|"predicted"}``, and
``"constant"`` in ``ch3-prediction``); the table "thesis reported vs uvnav measured" is read back
from the stored rows. Figures are made by an injected renderer (``render=``; the CLI passes
:func:`uvnav.viz.figures3d.render_ch3`), so this module never imports ``viz`` (DESIGN §1
layers).
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import uvnav.experiments.campaigns as cp
from uvnav.bench.campaign import Job
from uvnav.bench.fingerprint import DB_NAME
from uvnav.bench.store import FINGERPRINT_KEY, EpisodeKey, ResultsStore, check_fingerprints
from uvnav.experiments.rows import table_row

CONTROLLERS_3D: tuple[str, ...] = ("zhang2020-3d-v1", "apf3d-v1", "vo3d-v1")
SCENES_CAMPAIGN = "ch3-thesis-scenes"
RANDOM_CAMPAIGN = "ch3-random"
RANDOM_FAMILY = "random-ch3"
QUICK_SEEDS = 2
FULL_SEEDS = 500
MOTIONS: tuple[str, ...] = ("known", "predicted")
PREDICTION_CAMPAIGN = "ch3-prediction"
#: the law whose prediction is compared, the families (label prefix, ``motion`` of random-ch3)
#: and the motion knowledge of each arm: AR prediction, constant velocity, oracle
PREDICTION_LAW = "zhang2020-3d-v1"
PREDICTION_FAMILIES: dict[str, str] = {"random-ch3": "ar", "random-ch3-periodic": "periodic"}
PREDICTION_ARMS: dict[str, str] = {
    "predicted": "AR prediction", "constant": "constant velocity", "known": "oracle",
}  # fmt: skip
#: the comparison runs at least this many seeds per family (more when the run asks for more)
PREDICTION_MIN_SEEDS = 20
#: horizons [periods T_s] of :func:`horizon_errors`
HORIZONS: tuple[int, ...] = (1, 3)

#: What the thesis reports for its Chapter 3 experiments (§3.4).
THESIS_CLAIMS: dict[str, str] = {
    "thesis-ch3-fig3-5-single-cycle": "one M2 cycle shown (Fig. 3.5); no numbers",
    "thesis-ch3-fig3-6-whole-manoeuvre": "reaches E, avoids the obstacle (Figs. 3.6-3.7)",
    "thesis-ch3-several-obstacles": "claimed for several obstacles (§3.2); not shown",
}


@dataclass
class Ch3Summary:
    """Outcome of :func:`reproduce_ch3`."""

    table: list[dict[str, str]]
    db_path: Path
    failures: list[dict[str, Any]]
    prediction: dict[str, float]
    figures: list[Path] = field(default_factory=list)
    wall_time: float = 0.0
    #: what prediction buys: :func:`horizon_errors` by family and closed-loop rates by
    #: (family, arm), see :func:`prediction_study`
    study: dict[str, Any] = field(default_factory=dict)
    #: the one sentence of :func:`prediction_finding`
    finding: str = ""


Renderer = Callable[[Path, Path, list[tuple[str, str, Any]]], list[Path]]


def ch3_job(scene: str, law: str, seed: int, motion: str, *, record: bool = False) -> Job:
    """One episode as a campaign job: a scene (built-in name or generator label such as
    ``random-ch3:4``), a 3D law, a seed and the motion knowledge (the job's tags: the store's
    ``params``, part of the resume key): ``"known"`` (the scene senses true rates, the law is an
    oracle), ``"predicted"`` (estimated rates, the law's own prediction) or ``"constant"``
    (estimated rates used as they are, ``prediction="last"``); ``record`` keeps the result.

    The motion knowledge sets the scene's ``sensing.velocities`` (a generator's ``velocities``
    parameter) and the law's ``oracle`` / ``prediction``; the job runs as any scene job
    (:func:`uvnav.scenarios.episodes.run_scene`) without the scene's own law parameters."""
    family, _, number = scene.partition(":")
    velocities = "known" if motion == "known" else "estimated"
    params: dict[str, Any] = {}
    if motion == "known":
        params["oracle"] = True
    elif motion == "constant":  # the sensed rates as they are, no AR models
        params["prediction"] = "last"
    where: dict[str, Any]
    if number:
        gen_params = {"velocities": velocities}
        where = {"generator": family, "generator_seed": int(number), "generator_params": gen_params}
    else:
        where = {"scenario": scene, "scene_params": {"sensing.velocities": velocities}}
    return Job(
        law, int(seed), label=scene, family=family, tags={"motion": motion}, params=params,
        record=record, use_scenario_params=False, **where,
    )  # fmt: skip


def fingerprint() -> str:
    """The code fingerprint of this chapter's campaigns: the packages that decide an episode
    and this module (its jobs)."""
    return cp.fingerprint("experiments/ch3.py")


def _say(campaign: str, progress: bool) -> cp.Progress | None:
    """With ``progress``, a ``progress`` printing one line per episode run."""
    return (lambda done, total: print(f"  {campaign}: {done}/{total}")) if progress else None


def prediction_errors(n_series: int = 20, length: int = 120) -> dict[str, float]:
    """One-step velocity prediction RMS error [m/s] of the AR models and of constant velocity on
    the AR motion of the random scenes' obstacles (:func:`horizon_errors` at k = 1)."""
    e = horizon_errors("ar", n_series, length, horizons=(1,))
    ar, cv = e["v1_ar"], e["v1_cv"]
    return {"ar_rms": ar, "constant_rms": cv, "series": e["series"], "ratio": ar / cv}


def horizon_errors(
    motion: str = "ar",
    n_series: int = 20,
    length: int = 120,
    horizons: Sequence[int] = HORIZONS,
    period: float = 1.0,
) -> dict[str, float]:
    """k-step prediction RMS errors of the AR models and of constant velocity on the bodies of
    the ``random-ch3`` scenes with ``motion`` (one series per body of scenes 0, 1, ... until
    ``n_series``, each ``length`` samples of the true velocity taken every ``period`` T_s [s],
    the predictor ``ARPredictor(dim=3, max_lag=3)``).

    After each sample v_i (from the predictor's ``min_samples`` on) both predict v_{i+k}: AR by
    iterating (3.13), constant velocity by v_i.  A sample is held over its period, so the body
    moves T_s (v_i + v_{i+1} + ... + v_{i+k-1}) in k periods; the position forecasts put the
    predicted samples in that sum (v_i is known), so the k = 1 position error is 0.

    Returns:
        ``v{k}_ar``, ``v{k}_cv`` [m/s] and ``p{k}_ar``, ``p{k}_cv`` [m] for each k, and
        ``series``."""
    from uvnav.obstacles.motion3d import ObstacleState3D
    from uvnav.prediction.autoregressive import ARPredictor, rms
    from uvnav.scenarios.generators3d import random_ch3_scenario

    kmax = max(horizons)
    err: dict[str, list[np.ndarray]] = {
        f"{q}{k}_{m}": [] for q in ("v", "p") for k in horizons for m in ("ar", "cv")
    }
    series = 0
    seed = 0
    while series < n_series:
        setup = random_ch3_scenario(seed, motion=motion).build(seed)  # type: ignore[arg-type]
        for ob in setup.obstacles:
            st = ObstacleState3D(np.zeros(3))
            y = np.array([ob.motion.rates(k * period, st)[0] for k in range(length)])
            pred = ARPredictor(dim=3, max_lag=3, period=period)
            for i in range(length - 1):
                pred.observe(i * period, y[i])
                if pred.n_samples < pred.min_samples:
                    continue
                ahead = pred.predict(kmax).mean  # (kmax, 3): v_{i+1} .. v_{i+kmax}
                for k in horizons:
                    if i + k >= length:
                        continue
                    truth = y[i + 1 : i + k + 1]
                    err[f"v{k}_ar"].append(ahead[k - 1] - y[i + k])
                    err[f"v{k}_cv"].append(y[i] - y[i + k])
                    # positions: the first k - 1 predicted samples against the true ones
                    err[f"p{k}_ar"].append(period * (ahead[: k - 1] - truth[: k - 1]).sum(0))
                    err[f"p{k}_cv"].append(period * (y[i] - truth[: k - 1]).sum(0))
            series += 1
        seed += 1
    out = {key: rms(np.array(v).reshape(-1, 3)) for key, v in err.items()}
    out["series"] = float(series)
    return out


def ar_usage(family: str, seeds: Sequence[int]) -> dict[str, float]:
    """How often ``PREDICTION_LAW`` with AR prediction actually used an AR model: over its
    decisions on ``family:<seed>`` (rates estimated) that predicted a body's motion (M2), the
    share whose velocity prediction came from AR fits (``"ar"`` or ``"mixed"``) rather than the
    constant-velocity fallback (fewer than ``min_samples`` samples of the body, or rejected fits).

    Returns:
        ``{"decisions": count, "ar_share": fraction (nan for none)}``."""
    from uvnav.core import BaseProbe
    from uvnav.scenarios.catalog import generate
    from uvnav.scenarios.episodes import run_scene

    class _Use(BaseProbe):
        def __init__(self) -> None:
            self.total = 0
            self.ar = 0

        def on_decision(self, world: Any, agent: int, law: Any, obs: Any, applied: Any) -> None:
            for _v, _u, model in (getattr(law, "predictions", None) or {}).values():
                self.total += 1
                self.ar += model in ("ar", "mixed")

    use = _Use()
    for g in seeds:
        scene = generate(family, g, {"velocities": "estimated"})
        run_scene(scene, PREDICTION_LAW, {}, g, use_scene_params=False, probes=(use,))
    share = use.ar / use.total if use.total else float("nan")
    return {"decisions": float(use.total), "ar_share": share}


def prediction_jobs(n_seeds: int, start_seed: int = 0) -> list[Job]:
    """The ``ch3-prediction`` episodes: every family x arm x seed, ``PREDICTION_LAW``."""
    return [
        ch3_job(f"{fam}:{g}", PREDICTION_LAW, g, arm)
        for fam in PREDICTION_FAMILIES for g in range(start_seed, start_seed + n_seeds)
        for arm in PREDICTION_ARMS
    ]  # fmt: skip


def prediction_plan(
    n_seeds: int, start_seed: int, fp: str
) -> tuple[str, dict[str, Any], list[Job]]:
    """The ``ch3-prediction`` campaign as (name, config, jobs); ``fp``: :func:`fingerprint`'s."""
    config = {"chapter": 3, "law": PREDICTION_LAW, "seeds": n_seeds, FINGERPRINT_KEY: fp}
    return PREDICTION_CAMPAIGN, config, prediction_jobs(n_seeds, start_seed)


def closed_loop_rates(frame: Any) -> dict[str, dict[str, float]]:
    """Success / collision rates and mean min clearance by ``"family|arm"`` of stored
    ``ch3-prediction`` episodes (``frame`` from :meth:`ResultsStore.episodes_frame`)."""
    out: dict[str, dict[str, float]] = {}
    fam = frame["scenario"].astype(str).str.split(":").str[0]
    arm = frame["params"].map(lambda p: json.loads(str(p)).get("motion", ""))
    for (f, a), grp in frame.groupby([fam, arm]):
        out[f"{f}|{a}"] = {
            "n": float(len(grp)),
            "success": float(grp["success"].astype(float).mean()),
            "collision": float(grp["collision"].astype(float).mean()),
            "min_clearance": float(grp["min_clearance"].astype(float).mean()),
        }
    return out


def prediction_study(
    store: ResultsStore,
    *,
    n_seeds: int,
    start_seed: int = 0,
    workers: int = 1,
    progress: bool = False,
    fp: str | None = None,
) -> dict[str, Any]:
    """What prediction buys (module docstring, item 4): the ``ch3-prediction`` episodes the
    store lacks are run and stored, each as it finishes; returns ``{"errors": {family:
    horizon_errors}, "closed_loop": closed_loop_rates, "usage": {family: ar_usage}, "seeds": n}``
    (the usage episodes run again every call: their counts are not stored).

    ``fp`` is :func:`fingerprint`'s (computed when not given).

    Raises:
        StaleCampaignError: the stored campaign was made by other code (nothing runs).
    """
    fp = fp if fp is not None else fingerprint()
    check_fingerprints(store, {PREDICTION_CAMPAIGN: fp})
    _, config, jobs = prediction_plan(n_seeds, start_seed, fp)
    cp.run_jobs(store, PREDICTION_CAMPAIGN, jobs, config=config, workers=workers,
                progress=_say(PREDICTION_CAMPAIGN, progress))  # fmt: skip
    frame = _requested(store.episodes_frame(PREDICTION_CAMPAIGN), jobs)
    errors = {fam: horizon_errors(motion) for fam, motion in PREDICTION_FAMILIES.items()}
    seeds = range(start_seed, start_seed + n_seeds)
    usage = {fam: ar_usage(fam, seeds) for fam in PREDICTION_FAMILIES}
    return {
        "errors": errors, "closed_loop": closed_loop_rates(frame), "usage": usage,
        "seeds": n_seeds,
    }  # fmt: skip


def prediction_rows(study: dict[str, Any]) -> list[dict[str, str]]:
    """The table rows of :func:`prediction_study`'s result."""
    rows: list[dict[str, str]] = []
    for fam, e in study["errors"].items():
        for k in HORIZONS:
            rows.append(
                table_row(
                    f"{fam}: {k}-step velocity prediction RMS error [m/s]",
                    "AR model (3.13)-(3.14), no numbers",
                    f"AR {e[f'v{k}_ar']:.4f} vs constant velocity {e[f'v{k}_cv']:.4f}",
                    f"{int(e['series'])} body series, T_s = 1 s, true velocities",
                )
            )
        k = max(HORIZONS)
        rows.append(
            table_row(
                f"{fam}: {k} s position prediction RMS error [m]",
                "",
                f"AR {e[f'p{k}_ar']:.4f} vs constant velocity {e[f'p{k}_cv']:.4f}",
                "positions from the predicted velocity samples",
            )
        )
    cl = study["closed_loop"]
    for fam in study["errors"]:
        parts = []
        for arm, label in PREDICTION_ARMS.items():
            r = cl.get(f"{fam}|{arm}")
            if r is not None:
                parts.append(f"{label} {100 * r['success']:.1f}%")
        n = int(next((r["n"] for key, r in cl.items() if key.startswith(f"{fam}|")), 0))
        clear = ", ".join(
            f"{PREDICTION_ARMS[a]} {cl[f'{fam}|{a}']['min_clearance']:.3f} m"
            for a in PREDICTION_ARMS if f"{fam}|{a}" in cl
        )  # fmt: skip
        rows.append(
            table_row(
                f"{fam}: {PREDICTION_LAW} success by prediction",
                "",
                f"{' / '.join(parts)} of {n}",
                f"mean min clearance: {clear}",
            )
        )
        use = study.get("usage", {}).get(fam)
        if use is not None:
            rows.append(
                table_row(
                    f"{fam}: M2 predictions made by AR fits (not the fallback)",
                    "",
                    f"{100 * use['ar_share']:.1f}% of {int(use['decisions'])}",
                    "the rest: constant velocity (under 12 samples of the body, or fits rejected)",
                )
            )
    return rows


def prediction_finding(study: dict[str, Any]) -> str:
    """One sentence from :func:`prediction_study`'s numbers: AR's one-step velocity error as a
    share of constant velocity's on each family, the closed-loop success of the three arms, how
    often the law's AR fits were used, and whether AR changed the success rate."""
    errors, cl = study["errors"], study["closed_loop"]
    fams = list(errors)

    def both(parts: list[str]) -> str:
        return " and ".join(parts)

    shares: list[str] = []
    for fam, e in errors.items():
        ratio = e["v1_ar"] / e["v1_cv"] if e["v1_cv"] > 0 else float("nan")
        whose = "" if shares else " of constant velocity's"
        shares.append(f"{100 * ratio:.0f}%{whose} on {fam}")
    succ: list[str] = []
    gains: list[float] = []
    for fam in fams:
        ar, cv, orc = (cl.get(f"{fam}|{a}", {}).get("success", float("nan"))
                       for a in ("predicted", "constant", "known"))  # fmt: skip
        gains.append(ar - cv)
        succ.append(f"{100 * ar:.1f}% / {100 * cv:.1f}% / {100 * orc:.1f}% on {fam}")
    n = int(study.get("seeds", 0))
    usage = study.get("usage", {})
    used = ""
    if usage:
        pct = both([f"{100 * usage[f]['ar_share']:.0f}%" for f in fams if f in usage])
        used = (
            f", its AR fits making {pct} of its M2 predictions (the rest fell back to constant "
            "velocity)"
        )
    if all(abs(g) < 0.5 / max(n, 1) for g in gains):
        conj, verdict = "yet", "in closed loop AR prediction buys nothing measurable"
    elif all(g >= 0 for g in gains):
        conj, verdict = "and", "AR prediction raises the closed-loop success rate"
    else:
        conj, verdict = "and", "AR prediction does not consistently help in closed loop"
    return (
        f"AR prediction's one-step velocity error is {both(shares)}, {conj} {PREDICTION_LAW} "
        f"(AR / constant velocity / oracle, {n} seeds per family) succeeds in {both(succ)}"
        f"{used}: {verdict}."
    )


def _requested(frame: Any, jobs: list[Job]) -> Any:
    """The rows of ``frame`` (a campaign's episodes) that belong to ``jobs``, in job order: the
    table of a run describes what it asked for; the store keeps every other run's rows."""
    order: dict[EpisodeKey, int] = {}
    for i, job in enumerate(jobs):
        order.setdefault(job.key, i)
    keys = zip(frame["scenario"], frame["controller"], frame["params_hash"], frame["seed"],
               strict=True)  # fmt: skip
    pos = [order.get((str(sc), str(c), str(h), int(sd))) for sc, c, h, sd in keys]
    rows = sorted((p, i) for i, p in enumerate(pos) if p is not None)
    return frame.iloc[[i for _, i in rows]]


def _counts(full: bool, n_random: int | None, prediction_seeds: int | None) -> tuple[int, int]:
    """The random scenes and the prediction study's seeds per family of a run."""
    n_seeds = n_random if n_random is not None else (FULL_SEEDS if full else QUICK_SEEDS)
    n_pred = (
        prediction_seeds if prediction_seeds is not None else max(n_seeds, PREDICTION_MIN_SEEDS)
    )
    return n_seeds, n_pred


def campaign_plans(
    *,
    full: bool = False,
    n_random: int | None = None,
    start_seed: int = 0,
    controllers: Sequence[str] = CONTROLLERS_3D,
    prediction_seeds: int | None = None,
) -> list[tuple[str, dict[str, Any], list[Job]]]:
    """The campaigns :func:`reproduce_ch3` runs with these arguments, (name, config, jobs) in
    order: the thesis scenes, the random scenes and (unless its seeds are 0) the prediction
    study; nothing runs.  The study's AR-usage episodes run again every call and are not
    stored, so they are no campaign."""
    import uvnav.scenarios as scenarios

    n_seeds, n_pred = _counts(full, n_random, prediction_seeds)
    fp = fingerprint()
    scenes = [n for n in scenarios.list_builtin() if n.startswith("thesis-ch3-")]
    rand_jobs = [
        ch3_job(f"{RANDOM_FAMILY}:{g}", c, g, m)
        for g in range(start_seed, start_seed + n_seeds) for m in MOTIONS for c in controllers
    ]  # fmt: skip
    size = {"chapter": 3, "controllers": list(controllers), FINGERPRINT_KEY: fp}
    plans = [
        (SCENES_CAMPAIGN, {**size, "seed": 0},
         [ch3_job(s, c, 0, "predicted") for s in scenes for c in controllers]),
        (RANDOM_CAMPAIGN, {**size, "seeds": n_seeds}, rand_jobs),
    ]  # fmt: skip
    if n_pred > 0:
        plans.append(prediction_plan(n_pred, start_seed, fp))
    return plans


def reproduce_ch3(
    results_dir: Path,
    report_dir: Path,
    *,
    full: bool = False,
    workers: int = 2,
    progress: bool = False,
    n_random: int | None = None,
    start_seed: int = 0,
    controllers: Sequence[str] = CONTROLLERS_3D,
    render: Renderer | None = None,
    prediction_seeds: int | None = None,
) -> Ch3Summary:
    """Chapter 3 scenes, random campaign (known vs predicted motion), prediction errors, table.

    Args:
        results_dir: folder of ``uvnav.sqlite`` (created).
        report_dir: folder of the figures (created by the renderer).
        full: ``FULL_SEEDS`` random scenes instead of ``QUICK_SEEDS``.
        workers: worker processes.
        progress: print one line per episode.
        n_random: override the number of random scenes.
        start_seed: first random scene (scenes ``start_seed .. start_seed + n - 1``).
        controllers: the 3D laws to compare.
        render: figure renderer ``(db_path, report_dir, recorded) -> figure paths``.
        prediction_seeds: seeds per family of the prediction comparison (default: the random
            campaign's, at least ``PREDICTION_MIN_SEEDS``); 0 skips it.

    Resumable and additive (:mod:`uvnav.experiments.campaigns`; the thesis scenes run again
    only for the figures' trajectories); the table describes the episodes this call asked for.

    Raises:
        StaleCampaignError: a stored campaign of this run was made by other code (its
            fingerprint differs; nothing runs).
    """
    tic = time.perf_counter()
    results_dir = Path(results_dir)
    results_dir.mkdir(parents=True, exist_ok=True)
    db_path = results_dir / DB_NAME
    _, n_pred = _counts(full, n_random, prediction_seeds)
    plans = campaign_plans(
        full=full, n_random=n_random, start_seed=start_seed, controllers=controllers,
        prediction_seeds=prediction_seeds,
    )  # fmt: skip
    (_, scene_cfg, scene_jobs), (_, rand_cfg, rand_jobs) = plans[:2]
    fp = fingerprint()
    recorded: dict[EpisodeKey, Any] = {}
    with ResultsStore(db_path) as store:
        check_fingerprints(store, {name: fp for name, _, _ in plans})  # before anything runs
        if render is not None:  # the figures' trajectories (not stored): the scenes run again
            recorded = cp.run_recorded(
                store, SCENES_CAMPAIGN, scene_jobs, config=scene_cfg, workers=workers
            )
        else:
            cp.run_jobs(store, SCENES_CAMPAIGN, scene_jobs, config=scene_cfg, workers=workers,
                        progress=_say(SCENES_CAMPAIGN, progress))  # fmt: skip
        cp.run_jobs(store, RANDOM_CAMPAIGN, rand_jobs, config=rand_cfg,
                    workers=workers, progress=_say(RANDOM_CAMPAIGN, progress))  # fmt: skip
        frame = _requested(store.episodes_frame(RANDOM_CAMPAIGN), rand_jobs)
        scene_frame = _requested(store.episodes_frame(SCENES_CAMPAIGN), scene_jobs)
        study = (
            prediction_study(store, n_seeds=n_pred, start_seed=start_seed, workers=workers,
                             progress=progress, fp=fp)
            if n_pred > 0 else {}
        )  # fmt: skip
    pred = prediction_errors()
    table: list[dict[str, str]] = []
    for _, row in scene_frame.iterrows():
        if row["controller"] != controllers[0]:
            continue
        table.append(
            table_row(
                f"{row['scenario']} ({row['controller']})",
                THESIS_CLAIMS.get(str(row["scenario"]), ""),
                f"{row['status']}, min clearance {row['min_clearance']:.2f} m, "
                f"path {row['path_length']:.1f} m",
                "rates estimated from sensing, AR-predicted",
            )
        )
    failures: list[dict[str, Any]] = []
    for (ctrl, params), grp in frame.groupby(["controller", "params"]):
        motion = json.loads(str(params)).get("motion", "") if str(params).startswith("{") else ""
        rate = float(grp["success"].astype(float).mean())
        table.append(
            table_row(
                f"random-ch3 success, {ctrl}, motion {motion or params}",
                ">= 98% (issue target for zhang2020-3d)" if ctrl == controllers[0] else "",
                f"{100 * rate:.1f}% of {len(grp)}",
                f"collisions {int(grp['collision'].astype(float).sum())}",
            )
        )
        for _, fr in grp[~grp["success"].astype(bool)].iterrows():
            cause = (
                f"collision (min clearance {fr['min_clearance']:.3f} m)"
                if fr["status"] == "collision"
                else f"{fr['status']} (did not reach E within t_max)"
            )
            failures.append({
                "scene": fr["scenario"], "seed": int(fr["seed"]), "controller": ctrl,
                "motion": motion, "params": params, "status": fr["status"],
                "min_clearance": fr["min_clearance"], "cause": cause,
            })  # fmt: skip
    table.append(
        table_row(
            "one-step velocity prediction RMS error [m/s]",
            "AR model (3.13)-(3.14), no numbers",
            f"AR {pred['ar_rms']:.4f} vs constant velocity {pred['constant_rms']:.4f}",
            f"{int(pred['series'])} obstacle series of the random scenes",
        )
    )
    finding = ""
    if study:
        table += prediction_rows(study)
        finding = prediction_finding(study)
    figures: list[Path] = []
    if render is not None:
        trajectories = [
            (str(j.label), j.controller, recorded[j.key].trajectory) for j in scene_jobs
        ]
        figures = render(db_path, Path(report_dir), trajectories)
    return Ch3Summary(
        table, db_path, failures, pred, figures, time.perf_counter() - tic, study, finding
    )
