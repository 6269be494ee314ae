"""Thesis Chapter 5 reproduction: the BPNN experiment (:mod:`uvnav.experiments.ch5_bpnn`) and the
closed-loop runs of the law with each locator.

:func:`reproduce_ch5` trains the networks of the BPNN experiment (every sample count, seed,
variant and kind of targets; the literal experiment over ``literal_seeds`` seeds) and measures
them on an independent test set of ``n_test`` samples, then runs ``zhang2022-uuv3d-v1`` with the
geometric (min/argmin, the baseline), network (the BPNN) and oracle (true geometry) locators:

1. on the three thesis scenes, seed 0, trajectories recorded for the figures and the animation —
   campaign ``ch5-thesis-scenes`` (run again every time for the trajectories);
2. on ``random-ch5:<seed>`` scenes without sensor noise (quick: 3 seeds; ``full``: 300) —
   campaign ``ch5-random``;
3. on the same scenes with sonar range noise :data:`NOISE_STD` (quick: none; ``full``: 300) —
   campaign ``ch5-noise``;
4. on the harder ``random-ch5-dense`` family, noise 0 (quick: none; ``full``: 100) — campaign
   ``ch5-dense``.

Every episode is a scene campaign job (:func:`ch5_job`) run and stored by
:mod:`uvnav.experiments.campaigns` in ``results_dir/uvnav.sqlite``: the ``controller`` column
holds the law, ``params`` (the job's tags) the locator and the noise level (plus, for the
network, a digest of its checkpoint: part of the resume key, so a different network re-runs),
``family`` the generator or the scene; the number of obstacles and whether Scene 2's inner space
was entered (the scene runner's facts) go to ``effective_params``.

**Resumable.**  Nothing measured is lost when a run is interrupted: the data sets, learning rows
and networks are stages of the results folder's stage cache (``results_dir/stages``,
:mod:`uvnav.experiments.ch5_bpnn`), made by the code of :func:`fingerprint`, and every
random-campaign episode is one transaction of the store; a re-run skips what is there
(``fresh`` remakes the stages; stored episodes are never deleted or replaced by a later run, and
a network trained again to the same weights keeps its digest, which covers the weights only, and
so its stored episodes).  A campaign stored by other code is refused
(:class:`~uvnav.bench.store.StaleCampaignError`) before anything is trained, and so is a stage
made by other code (:class:`~uvnav.bench.stages.StaleStageError`, unless ``fresh``).
``results_dir/ch5.json`` (rows, table, per-group summary, failures) and the table
"thesis reported vs uvnav measured" are computed from the measured rows only.  Figures are drawn
by a renderer the caller injects (:mod:`uvnav.viz` is a layer above).
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import uvnav.experiments.campaigns as cp
from uvnav.bench.campaign import Job, outcome_record, run_job, stored_records
from uvnav.bench.fingerprint import DB_NAME
from uvnav.bench.stages import StageCache
from uvnav.bench.store import FINGERPRINT_KEY, ResultsStore, check_fingerprints
from uvnav.controllers.zhang_uuv3d import NAME as LAW
from uvnav.experiments.ch5_bpnn import (
    FULL_LITERAL_SEEDS,
    FULL_SEEDS,
    FULL_SIZES,
    QUICK_LITERAL_SEEDS,
    QUICK_SEEDS,
    QUICK_SIZES,
    TEST_SEED,
    VARIANT_KEYS,
    cached_dataset,
    json_default,
    learning_row,
    learning_table,
)
from uvnav.experiments.rows import table_row
from uvnav.learning.bpnn import (
    THESIS_ACCEPTED,
    VARIANTS,
    save_checkpoint,
    variant_config,
)
from uvnav.scenarios.ch5 import (
    GENERATOR_CH5,
    GENERATOR_CH5_DENSE,
    RANDOM_CH5_VERSION,
    list_ch5_builtin,
)
from uvnav.sim.episode_uuv3d import LocatedTrace
from uvnav.sim.metrics import METRIC_NAMES
from uvnav.sim.setup import EpisodeResult
from uvnav.stages import write_atomic

QUICK_RANDOM, FULL_RANDOM = 3, 300
#: scenes of the harder family beyond the assumptions (``random-ch5-dense``, noise 0 only)
QUICK_DENSE, FULL_DENSE = 0, 100
QUICK_NOISES: tuple[float, ...] = (0.0,)
LOCATORS: tuple[str, ...] = ("geometric", "network", "oracle")
#: sonar range noise [m] of the noisy closed-loop runs
NOISE_STD = 0.05
#: samples of the network used in closed loop
CLOSED_LOOP_SAMPLES = 500
SCENES_CAMPAIGN = "ch5-thesis-scenes"
RANDOM_CAMPAIGN = "ch5-random"
NOISE_CAMPAIGN = "ch5-noise"
DENSE_CAMPAIGN = "ch5-dense"
CAMPAIGNS: tuple[str, ...] = (SCENES_CAMPAIGN, RANDOM_CAMPAIGN, NOISE_CAMPAIGN, DENSE_CAMPAIGN)
#: seed of the closed-loop network's data
CLOSED_LOOP_SEED = 100


@dataclass
class Ch5Summary:
    """What :func:`reproduce_ch5` measured.

    Attributes:
        learning: one row per (samples, seed, variant, targets): error summaries on the split's
            test group, on all samples and on the independent test set, network and baseline,
            training time [s], epochs.
        closed_loop: one row per episode: scene, locator, noise, seed, status, metrics.
        table: rows ``{quantity, thesis, measured, note}``.
        campaign: per (family, locator, noise): episodes, success/collision/timeout rates, ...
        failures: the non-successful episodes (scene, seed, locator, noise, status, clearance).
        json_path: where everything was written.
        db_path: the results database holding every closed-loop episode.
        figures: figure files written by the renderer.
        wall_time: seconds.
    """

    learning: list[dict[str, Any]] = field(default_factory=list)
    closed_loop: list[dict[str, Any]] = field(default_factory=list)
    table: list[dict[str, Any]] = field(default_factory=list)
    campaign: list[dict[str, Any]] = field(default_factory=list)
    failures: list[dict[str, Any]] = field(default_factory=list)
    json_path: Path | None = None
    db_path: Path | None = None
    figures: list[Path] = field(default_factory=list)
    wall_time: float = 0.0
    models: dict[str, Any] = field(default_factory=dict, repr=False)
    datasets: dict[str, Any] = field(default_factory=dict, repr=False)


# ---------------------------------------------------------------------------------- closed loop


def ch5_job(
    scene: str,
    locator: str,
    seed: int,
    noise_std: float = 0.0,
    model: str | None = None,
    model_id: str = "",
) -> Job:
    """One closed-loop episode as a campaign job: a scene (built-in or ``random-ch5:<seed>``), a
    locator, a seed, the sonar range noise [m]; ``model`` is the network's checkpoint path
    (``network`` only) and ``model_id`` its digest.

    The law's parameters are the locator and the checkpoint (``make_law`` builds the law with
    them, over the scene's own parameters); the noise is the scene's (a generator's
    ``noise_std``, a built-in's ``sonar.noise_std``).  The job's tags (the store's ``params``,
    hashed into the resume key) are the locator and the noise, the digest for ``network`` (it
    stands for the checkpoint's path in the store: the tag ``model`` overrides the parameter)
    and, for a random scene, the generator's version (a newer generator re-runs its scenes).
    """
    tags: dict[str, Any] = {"locator": locator, "noise_std": float(noise_std)}
    params: dict[str, Any] = {"locator": locator}
    if locator == "network":
        tags["model"] = model_id
        params["model"] = str(model or "")
    family, _, number = scene.partition(":")
    where: dict[str, Any] = {"scenario": scene, "scene_params": {"sonar.noise_std": noise_std}}
    if number and family in (GENERATOR_CH5, GENERATOR_CH5_DENSE):
        tags["generator"] = RANDOM_CH5_VERSION
        where = {
            "generator": family, "generator_seed": int(number),
            "generator_params": {"noise_std": float(noise_std)},
        }  # fmt: skip
    return Job(LAW, int(seed), label=scene, family=family, tags=tags, params=params, **where)


def fingerprint() -> str:
    """The code fingerprint of this experiment's campaigns and stages: the packages that decide
    an episode, :mod:`uvnav.learning` (the network and its locator), this module (its jobs) and
    :mod:`uvnav.experiments.ch5_bpnn` (the data sets and learning rows)."""
    return cp.fingerprint("learning", "experiments/ch5.py", "experiments/ch5_bpnn.py")


def checkpoint_digest(path: Path) -> str:
    """First 16 hex digits of the SHA-256 of a checkpoint's weights: its arrays serialised
    without the header, so the digest, and the closed-loop episodes keyed on it, do not change
    with the header or the training record."""
    from safetensors.numpy import load_file, save

    st = Path(path).with_suffix(".safetensors")
    return hashlib.sha256(save(load_file(str(st)))).hexdigest()[:16]


def run_ch5_job(
    job: Job, *, record: bool = False
) -> tuple[dict[str, Any], EpisodeResult[LocatedTrace]]:
    """Run one job in this process; returns its row (as :func:`stored_rows` reads it back) and
    its result.

    Raises:
        RuntimeError: the episode failed.
    """
    out = run_job(dataclasses.replace(job, record=record))
    return _row(outcome_record(out)), out.result


def _row(rec: dict[str, Any]) -> dict[str, Any]:
    """A stored record (:func:`~uvnav.bench.campaign.stored_records`) as this chapter's row."""
    params, extra = rec["params"], rec["effective_params"]
    return {
        "scene": rec["scenario"],
        "locator": params["locator"],
        "noise_std": float(params.get("noise_std", 0.0)),
        "seed": int(rec["seed"]),
        "status": rec["status"],
        "entered_inner_space": bool(extra.get("entered_inner_space", False)),
        "n_obstacles": int(extra.get("n_obstacles", 0)),
        "model": str(params.get("model", "")),
        "wall_time": rec.get("wall_time"),
        **{m: rec.get(m) for m in METRIC_NAMES},
    }


def stored_rows(store: ResultsStore, campaign: str) -> list[dict[str, Any]]:
    """The episode rows of a campaign (store order)."""
    return [_row(r) for r in stored_records(store, campaign)]


#: ``run_jobs(jobs, store, campaign, *, workers=1, progress=None, config=...)``: the rows of
#: ``jobs`` (stored and new, in job order), those ``campaign`` lacks run first
#: (:func:`uvnav.experiments.campaigns.run_rows` with this chapter's row)
run_jobs = functools.partial(cp.run_rows, row=_row, config={"chapter": 5})


def summarise(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per (scene family, locator, noise): episodes, success / collision / timeout rates, inner
    space entries, median path length and detour ratio, minimum clearance, decision time."""
    return cp.group_stats(
        rows,
        lambda r: (cp.family(r), r["locator"], float(r["noise_std"])),
        ("family", "locator", "noise_std"),
        {"entered_inner_space": lambda r: bool(r["entered_inner_space"])},
    )


def failures(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The episodes that did not succeed: scene, seed, locator, noise, obstacles, status (the
    cause: ``collision`` or ``timeout``), minimum clearance [m]."""
    keep = ("scene", "seed", "locator", "noise_std", "n_obstacles", "status", "min_clearance")
    return cp.non_successes(rows, keep)


def build_ch5_table(summary: Ch5Summary) -> list[dict[str, Any]]:
    """Rows "thesis reported vs uvnav measured" from the measured rows only: the learning rows
    (:func:`~uvnav.experiments.ch5_bpnn.learning_table`), then per (locator, noise) the thesis
    scenes and each random family's success."""
    rows = learning_table(summary.learning)
    cl = summary.closed_loop
    for group in sorted({(r["locator"], r["noise_std"]) for r in cl}):
        loc, noise = group
        mine = [r for r in cl if (r["locator"], r["noise_std"]) == group]
        thesis_rows = [r for r in mine if str(r["scene"]).startswith("thesis-ch5")]
        rand_rows = [r for r in mine if cp.family(r) == GENERATOR_CH5]
        dense_rows = [r for r in mine if cp.family(r) == GENERATOR_CH5_DENSE]
        if thesis_rows:
            ok = sum(bool(r["success"]) for r in thesis_rows)
            inner = sum(bool(r["entered_inner_space"]) for r in thesis_rows)
            rows.append(
                table_row(
                    f"Ch5 thesis scenes reached, no collision ({loc}, noise {noise} m)",
                    "3/3",
                    f"{ok}/{len(thesis_rows)}",
                    f"entered Scene 2 inner space: {inner}",
                )
            )
        families = (
            ("random scenes", rand_rows),
            ("dense scenes (beyond the assumptions)", dense_rows),
        )
        for label, fam_rows in families:
            if not fam_rows:
                continue
            ok = sum(bool(r["success"]) for r in fam_rows)
            fails = [f"{r['scene']} {r['status']}" for r in fam_rows if not r["success"]]
            rows.append(
                table_row(
                    f"Ch5 {label} success ({loc}, noise {noise} m)",
                    "-",
                    f"{ok / len(fam_rows):.1%} of {len(fam_rows)}",
                    (
                        f"{len(fails)} failures: "
                        + ", ".join(fails[:6])
                        + (", ..." if len(fails) > 6 else "")
                    )
                    if fails
                    else "no failure",
                )
            )
    return rows


def _campaign_jobs(
    n_rand: int,
    noises: Sequence[float],
    model_path: Path,
    model_id: str,
    n_dense: int = 0,
    start: int = 0,
) -> dict[str, list[Job]]:
    """The random-scene jobs of each campaign (noise 0: ``ch5-random``; else ``ch5-noise``;
    the dense family, noise 0: ``ch5-dense``), scene by scene (all locators of a scene
    together)."""
    out: dict[str, list[Job]] = {RANDOM_CAMPAIGN: [], NOISE_CAMPAIGN: [], DENSE_CAMPAIGN: []}
    plan = [(RANDOM_CAMPAIGN if noise == 0 else NOISE_CAMPAIGN, GENERATOR_CH5, noise, n_rand)
            for noise in noises]  # fmt: skip
    plan.append((DENSE_CAMPAIGN, GENERATOR_CH5_DENSE, 0.0, n_dense))
    for name, generator, noise, count in plan:
        for g in range(start, start + count):
            for loc in LOCATORS:
                net = loc == "network"
                out[name].append(
                    ch5_job(
                        f"{generator}:{g}",
                        loc,
                        g,
                        float(noise),
                        str(model_path) if net else None,
                        model_id if net else "",
                    )
                )
    return out


#: the closed-loop network's tag in a plan made before it was trained
UNTRAINED = "untrained"


def campaign_plans(
    results_dir: Path,
    *,
    full: bool = False,
    n_random: int | None = None,
    n_dense: int | None = None,
    scenes: Sequence[str] | None = None,
    noises: Sequence[float] | None = None,
    start_seed: int = 0,
    model_id: str | None = None,
) -> list[tuple[str, dict[str, Any], list[Job]]]:
    """The closed-loop campaigns :func:`reproduce_ch5` runs with these arguments, (name, config,
    jobs) in order: the thesis scenes, then the random, noise and dense campaigns that have
    jobs; nothing runs or trains.

    The ``network`` locator's jobs carry the closed-loop network's digest (``model_id``): the
    run passes the network it trained; a plan made without it takes the digest of the
    checkpoint ``results_dir/ch5_bpnn`` a previous run saved (the network a run with unchanged
    stages trains again), or :data:`UNTRAINED` when there is none, whose ``network`` keys no
    run stores.  Every other job's key is the run's."""
    results_dir = Path(results_dir)
    model_path = results_dir / "ch5_bpnn"
    if model_id is None:
        saved = model_path.with_suffix(".safetensors").is_file()
        model_id = checkpoint_digest(model_path) if saved else UNTRAINED
    n_rand = n_random if n_random is not None else (FULL_RANDOM if full else QUICK_RANDOM)
    n_dns = n_dense if n_dense is not None else (FULL_DENSE if full else QUICK_DENSE)
    noise_list = (
        tuple(noises) if noises is not None else ((0.0, NOISE_STD) if full else QUICK_NOISES)
    )
    base_cfg = {
        "chapter": 5, "law": LAW, "locators": list(LOCATORS), "model": model_id,
        FINGERPRINT_KEY: fingerprint(),
    }  # fmt: skip
    net = {True: (str(model_path), model_id), False: (None, "")}
    scene_jobs = [
        ch5_job(scene, loc, 0, float(noise), *net[loc == "network"])
        for scene in (list(scenes) if scenes is not None else list_ch5_builtin())
        for noise in noise_list for loc in LOCATORS
    ]  # fmt: skip
    plans = [(SCENES_CAMPAIGN, {**base_cfg, "noises": list(noise_list)}, scene_jobs)]
    jobs = _campaign_jobs(n_rand, noise_list, model_path, model_id, n_dns, start_seed)
    for name, js in jobs.items():
        if js:
            seeds = len({j.seed for j in js})
            cfg = {**base_cfg, "seeds": seeds, "noise_std": dict(js[0].tags)["noise_std"]}
            plans.append((name, cfg, js))
    return plans


def reproduce_ch5(
    results_dir: Path,
    *,
    full: bool = False,
    sizes: Sequence[int] | None = None,
    n_seeds: int | None = None,
    n_random: int | None = None,
    n_dense: int | None = None,
    n_test: int = 500,
    scenes: Sequence[str] | None = None,
    noises: Sequence[float] | None = None,
    closed_loop_samples: int = CLOSED_LOOP_SAMPLES,
    progress: bool = True,
    render: Callable[[Ch5Summary, Path], list[Path]] | None = None,
    report_dir: Path | None = None,
    workers: int = 1,
    fresh: bool = False,
    start_seed: int = 0,
    literal_seeds: int | None = None,
    cache: StageCache | None = None,
) -> Ch5Summary:
    """Run the Chapter 5 reproduction (module docstring); write ``results_dir/ch5.json`` and the
    closed-loop episodes to ``results_dir/uvnav.sqlite``.  Resumes an interrupted run.

    Args:
        results_dir: folder of ``ch5.json``, the results database, the closed-loop network's
            checkpoint ``ch5_bpnn`` and the stage cache ``stages``.
        full: thesis-size runs (sizes up to 5000, 5 seeds, 300 random scenes, noise 0 and 0.05).
        sizes: sample counts (default 50, 150 quick).
        n_seeds: seeds per sample count (default 2 quick).
        n_random: random closed-loop scenes per locator and noise level (default 3 quick).
        n_dense: scenes of the harder ``random-ch5-dense`` family per locator, noise 0 (default
            0 quick, 100 full).
        n_test: size of the independent test set.
        scenes: thesis scenes to run (default all three).
        noises: sonar noise levels [m] of the closed-loop runs (default 0 quick, 0 and 0.05 full).
        closed_loop_samples: training samples of the closed-loop (residual) network.
        progress: rich progress bars on stderr.
        render: figure renderer ``(summary, report_dir) -> files`` (e.g.
            :func:`uvnav.viz.figures_ch5.render_ch5`); ``None`` skips figures.
        report_dir: folder of the figures.
        workers: processes for the random-scene campaigns.
        fresh: remake the stages (data sets, learning rows, networks; with the default
            cache); the stored episodes are kept (a network trained again to the same weights
            resumes them).
        start_seed: first scene of the random families (``random-ch5:<start_seed>`` onwards).
        literal_seeds: seeds of the literal experiment — the plain network on the thesis's
            targets (min/argmin of its inputs) at each of ``sizes`` the thesis reports (50, 150);
            default 20 quick, 50 full.
        cache: the stage cache (default ``StageCache(results_dir, fingerprint(), fresh=fresh)``).

    Additive (:mod:`uvnav.experiments.campaigns`): the thesis scenes run again for the figures'
    trajectories, only missing episodes are stored.

    Raises:
        StaleCampaignError: a stored campaign of this chapter was made by other code (its
            :func:`fingerprint` differs); checked before anything is trained or run.
        StaleStageError: a stage of these settings was made by other code (and not ``fresh``).
    """
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeElapsedColumn

    tic = time.perf_counter()
    results_dir = Path(results_dir)
    results_dir.mkdir(parents=True, exist_ok=True)
    db_path = results_dir / DB_NAME
    fp = fingerprint()
    with ResultsStore(db_path) as store:
        check_fingerprints(store, dict.fromkeys(CAMPAIGNS, fp))  # before any training
    cache = cache or StageCache(results_dir, fp, fresh=fresh)
    sizes = tuple(sizes) if sizes is not None else (FULL_SIZES if full else QUICK_SIZES)
    seeds = n_seeds if n_seeds is not None else (FULL_SEEDS if full else QUICK_SEEDS)
    n_rand = n_random if n_random is not None else (FULL_RANDOM if full else QUICK_RANDOM)
    n_dns = n_dense if n_dense is not None else (FULL_DENSE if full else QUICK_DENSE)
    summary = Ch5Summary(db_path=db_path)
    default_noises = (0.0, NOISE_STD) if full else QUICK_NOISES
    noise_list = tuple(noises) if noises is not None else default_noises
    variants = tuple(variant_config(v) for v in VARIANTS)
    n_literal = (
        literal_seeds
        if literal_seeds is not None
        else (FULL_LITERAL_SEEDS if full else QUICK_LITERAL_SEEDS)
    )
    literal_sizes = [n for n in sizes if n in THESIS_ACCEPTED]
    columns = (
        "[progress.description]{task.description}",
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
    )
    with Progress(*columns, disable=not progress, transient=True) as prog:
        n_units = len(sizes) * seeds * len(variants) + len(literal_sizes) * n_literal + 1
        task = prog.add_task("Ch5 BPNN data + training", total=n_units)
        sampling = prog.add_task("Ch5 sampling", total=None, visible=False)

        def sampler(n: int) -> Callable[[int], None]:
            prog.reset(sampling, total=n, visible=True, description=f"Ch5 sampling {n}")
            return lambda k: prog.update(sampling, completed=k)

        test, _ = cached_dataset(n_test, TEST_SEED, cache, sampler(n_test))
        summary.datasets["independent_test"] = test
        for n in sizes:
            for s in range(seeds):
                for cfg in variants:
                    row, model, ds = learning_row(
                        n, s, test, cfg, cache=cache, on_sample=sampler(n)
                    )
                    summary.learning.append(row)
                    if s == 0:
                        key = f"n{n}" + VARIANT_KEYS[cfg.variant]
                        summary.models[key] = model
                        summary.datasets[key] = ds
                    prog.advance(task)
        for n in literal_sizes:  # the thesis's set-up: targets computed from the inputs
            for s in range(n_literal):
                row, _, _ = learning_row(
                    n, s, test, variants[0], cache=cache, on_sample=sampler(n),
                    target_kind="readings",
                )  # fmt: skip
                summary.learning.append(row)
                prog.advance(task)
        # the closed-loop network: a residual one trained once on ``closed_loop_samples``
        cl_row, cl_model, _ = learning_row(
            closed_loop_samples,
            CLOSED_LOOP_SEED,
            test,
            variants[1],
            cache=cache,
            on_sample=sampler(closed_loop_samples),
        )
        prog.update(sampling, visible=False)
        summary.learning.append(cl_row)
        model_path = results_dir / "ch5_bpnn"
        save_checkpoint(cl_model, model_path)
        model_id = checkpoint_digest(model_path)
        summary.models["closed_loop"] = cl_model
        prog.advance(task)

        (_, scene_cfg, scene_jobs), *campaigns = campaign_plans(
            results_dir, full=full, n_random=n_random, n_dense=n_dense, scenes=scenes,
            noises=noises, start_seed=start_seed, model_id=model_id,
        )  # fmt: skip
        n_episodes = len(scene_jobs) + sum(len(js) for _, _, js in campaigns)
        task2 = prog.add_task("Ch5 closed loop", total=n_episodes)
        kept: dict[tuple[str, str, float], EpisodeResult[LocatedTrace]] = {}
        with ResultsStore(db_path) as store:
            check_fingerprints(store, dict.fromkeys(CAMPAIGNS, fp))
            # run again for the figures' trajectories; stored only when missing
            results = cp.run_recorded(
                store, SCENES_CAMPAIGN, scene_jobs, config=scene_cfg,
                on_episode=lambda _out: prog.advance(task2),
            )  # fmt: skip
            for j in scene_jobs:
                tags = dict(j.tags)
                kept[(str(j.label), tags["locator"], tags["noise_std"])] = results[j.key]
            scene_rows = [_row(r) for r in cp.job_records(store, SCENES_CAMPAIGN, scene_jobs)]
            rand_rows: list[dict[str, Any]] = []

            def advance_from(ran: float) -> cp.Progress:
                return lambda k, _n: prog.update(task2, completed=ran + k)

            for name, cfg_c, js in campaigns:
                ran = prog.tasks[task2].completed
                rand_rows += run_jobs(
                    js, store, name, workers=workers, config=cfg_c,
                    progress=advance_from(ran),
                )  # fmt: skip
                prog.update(task2, completed=ran + len(js))
    summary.models["episodes"] = kept
    summary.closed_loop = scene_rows + rand_rows
    summary.campaign = summarise(summary.closed_loop)
    summary.failures = failures(summary.closed_loop)
    summary.table = build_ch5_table(summary)
    summary.wall_time = time.perf_counter() - tic
    out = {
        "learning": summary.learning,
        "closed_loop": summary.closed_loop,
        "campaign": summary.campaign,
        "failures": summary.failures,
        "table": summary.table,
        "wall_time": round(summary.wall_time, 2),
        "database": DB_NAME,
        "campaigns": list(CAMPAIGNS),
        "config": {
            "sizes": list(sizes),
            "seeds": seeds,
            "literal_seeds": n_literal,
            "n_random": n_rand,
            "start_seed": start_seed,
            "n_dense": n_dns,
            "n_test": n_test,
            "noises": list(noise_list),
            "closed_loop_samples": closed_loop_samples,
            "model": model_id,
        },
    }
    summary.json_path = results_dir / "ch5.json"
    write_atomic(summary.json_path, json.dumps(out, indent=1, default=json_default))
    if render is not None and report_dir is not None:
        summary.figures = list(render(summary, Path(report_dir)))
    return summary
