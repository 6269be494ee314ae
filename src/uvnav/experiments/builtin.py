"""uvnav's own experiments: the thesis chapters ``ch2`` … ``ch7``, ``crowds``, ``regime`` and
``beyond``.  Each ``run_*`` runs one reproduction into the results store
``results_dir/uvnav.sqlite`` (and its own files under ``results_dir``), draws its figures with the
context's renderers into ``report_dir/<name>`` and returns its report section, its table rows and
its summary object; each ``plan_*`` returns the campaigns its ``run_*`` runs at the same context,
built from the same arguments by the reproduction's ``campaign_plans``, without running anything
(Chapters 6 and 7 are stages only: no campaign; their stages and Chapter 5's are named).

``seeds`` / ``start_seed`` choose the random scenes of the seeded ones: ``seeds`` scenes from
``start_seed`` (Ch. 2: the random and baseline campaigns; Ch. 3: the random-ch3 scenes; Ch. 4:
every family — random-ch4, the noise sweep, random-ch4-hard; Ch. 5: the random-ch5 closed-loop
scenes; crowds: CrowdNav's test cases ``start_seed`` .. ``start_seed + seeds - 1`` of each scene;
regime: the seeds of every regime).  Each declares its quick and full :class:`Size`; a size's
``params`` are passed to its reproduction as keyword arguments (Chapter 6's quick size is
:data:`uvnav.experiments.ch6.RUN_QUICK`; a test passes a tinier size in the context).  The
reproductions are imported when run, so the registry loads fast.
"""

from __future__ import annotations

import inspect
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import uvnav.experiments.ch2 as rp
import uvnav.experiments.sections as sec
from uvnav.bench.jobs import Job
from uvnav.experiments.ch6 import RUN_QUICK
from uvnav.experiments.protocol import (
    Experiment,
    ExperimentContext,
    ExperimentRun,
    PlannedCampaign,
    Size,
)
from uvnav.experiments.sections import ChapterSection


def _run(section: ChapterSection, summary: Any, rows: list[dict[str, str]]) -> ExperimentRun:
    failures = list(getattr(summary, "failures", []) or [])
    return ExperimentRun(sections=[section], rows=list(rows), summary=summary, failures=failures)


def _params(ctx: ExperimentContext, **given: Any) -> dict[str, Any]:
    """``given`` updated with the chosen size's ``params``."""
    return {**given, **(dict(ctx.size.params) if ctx.size is not None else {})}


def _planned(
    plans: Callable[..., list[tuple[str, dict[str, Any], list[Job]]]], given: dict[str, Any]
) -> list[PlannedCampaign]:
    """``plans(**given)`` as planned campaigns; of ``given`` (the run's keyword arguments) only
    those ``plans`` takes are passed (the rest decide no job: workers, renderers, progress)."""
    takes = inspect.signature(plans).parameters
    found = plans(**{k: v for k, v in given.items() if k in takes})
    return [PlannedCampaign(name, cfg, tuple(jobs)) for name, cfg, jobs in found]


def _no_campaigns(_ctx: ExperimentContext) -> list[PlannedCampaign]:
    """The plan of an experiment made of stages only: no campaign."""
    return []


def _say(name: str) -> Callable[[str], None]:
    def say(message: str) -> None:
        print(f"{name}: {message}", file=sys.stderr, flush=True)

    return say


def _ch2_args(ctx: ExperimentContext) -> dict[str, Any]:
    return _params(
        ctx, full=ctx.full, workers=ctx.workers, progress=ctx.progress, n_random=ctx.seeds,
        start_seed=ctx.start_seed, controllers=rp.CONTROLLERS, baselines=rp.BASELINES,
        n_baseline_seeds=ctx.seeds,
    )  # fmt: skip


def plan_ch2(ctx: ExperimentContext) -> list[PlannedCampaign]:
    """Chapter 2's campaigns (:func:`uvnav.experiments.ch2.campaign_plans`)."""
    return _planned(rp.campaign_plans, _ch2_args(ctx))


def run_ch2(ctx: ExperimentContext) -> ExperimentRun:
    """Chapter 2's campaigns and section; its figures are drawn when the page is written."""
    ch2 = rp.run_ch2(ctx.results_dir, **_ch2_args(ctx))

    def report(
        sections: list[ChapterSection], table: list[dict[str, str]]
    ) -> tuple[Path | None, list[Path]]:
        done = rp.finish(
            ch2, ctx.results_dir, ctx.report_dir, table=table, sections=sections,
            campaigns=dict(ch2.campaigns), render=ctx.render, save_sections=False,
            started=time.perf_counter(),
        )  # fmt: skip
        return done.report_path, list(done.figures)

    out = _run(ch2.section, ch2, ch2.table)
    out.campaigns, out.report = dict(ch2.campaigns), report
    return out


def _ch3_args(ctx: ExperimentContext) -> dict[str, Any]:
    return _params(
        ctx, full=ctx.full, workers=ctx.workers, n_random=ctx.seeds, start_seed=ctx.start_seed,
        render=ctx.renderers.ch3, progress=False,
    )  # fmt: skip


def plan_ch3(ctx: ExperimentContext) -> list[PlannedCampaign]:
    """Chapter 3's campaigns (:func:`uvnav.experiments.ch3.campaign_plans`)."""
    from uvnav.experiments.ch3 import campaign_plans

    return _planned(campaign_plans, _ch3_args(ctx))


def run_ch3(ctx: ExperimentContext) -> ExperimentRun:
    """Chapter 3 (:func:`uvnav.experiments.ch3.reproduce_ch3`) and its section."""
    from uvnav.experiments.ch3 import reproduce_ch3

    s3 = reproduce_ch3(ctx.results_dir, ctx.report_dir, **_ch3_args(ctx))
    section = sec.ch3_section(s3, full=ctx.full, n_random=ctx.seeds, start_seed=ctx.start_seed)
    return _run(section, s3, s3.table)


def _ch4_args(ctx: ExperimentContext) -> dict[str, Any]:
    seeds = ctx.seeds
    return _params(
        ctx, full=ctx.full, workers=ctx.workers, render=ctx.renderers.ch4, seeds=seeds,
        noise_seeds=seeds, hard_seeds=seeds, start_seed=ctx.start_seed,
    )  # fmt: skip


def plan_ch4(ctx: ExperimentContext) -> list[PlannedCampaign]:
    """Chapter 4's campaigns (:func:`uvnav.experiments.ch4.campaign_plans`)."""
    from uvnav.experiments.ch4 import campaign_plans

    return _planned(campaign_plans, _ch4_args(ctx))


def run_ch4(ctx: ExperimentContext) -> ExperimentRun:
    """Chapter 4 (:func:`uvnav.experiments.ch4.reproduce_ch4`): ``seeds`` scenes of every
    family, and its section."""
    from uvnav.experiments.ch4 import reproduce_ch4

    s4 = reproduce_ch4(ctx.results_dir, ctx.report_dir, **_ch4_args(ctx))
    section = sec.ch4_section(s4, full=ctx.full, seeds=ctx.seeds, start_seed=ctx.start_seed)
    return _run(section, s4, s4.table)


def _ch5_args(ctx: ExperimentContext) -> dict[str, Any]:
    return _params(
        ctx, full=ctx.full, progress=ctx.progress, render=ctx.renderers.ch5,
        report_dir=ctx.report_dir, workers=ctx.workers, n_random=ctx.seeds,
        start_seed=ctx.start_seed, fresh=ctx.fresh,
    )  # fmt: skip


def plan_ch5(ctx: ExperimentContext) -> list[PlannedCampaign]:
    """Chapter 5's closed-loop campaigns (:func:`uvnav.experiments.ch5.campaign_plans`); its
    stages (data sets, learning rows, the closed-loop network) are named by the experiment's
    ``stages``.  The ``network`` jobs carry the digest of the network a previous run saved in
    the results folder (``untrained`` when none did): the network's own digest is known only
    once its stage ran."""
    from uvnav.experiments.ch5 import campaign_plans

    return _planned(campaign_plans, {"results_dir": ctx.results_dir, **_ch5_args(ctx)})


def run_ch5(ctx: ExperimentContext) -> ExperimentRun:
    """Chapter 5 (:func:`uvnav.experiments.ch5.reproduce_ch5`: its data sets and networks in the
    results folder's stage cache, its episodes in the store) and its section."""
    from uvnav.experiments.ch5 import reproduce_ch5

    s5 = reproduce_ch5(ctx.results_dir, **_ch5_args(ctx))
    return _run(sec.ch5_section(s5, full=ctx.full), s5, s5.table)


def run_ch6(ctx: ExperimentContext) -> ExperimentRun:
    """Chapter 6 at ``uvnav run``'s size (:data:`uvnav.experiments.ch6.RUN_QUICK`; the thesis
    size with ``full``) in ``results_dir/ch6-quick`` (``results_dir/ch6``); every pipeline option
    is ``uvnav drive reproduce``'s."""
    from uvnav.bench.stages import StageCache
    from uvnav.experiments.ch6 import fingerprint, reproduce_ch6

    s6 = reproduce_ch6(
        Path(ctx.results_dir) / ("ch6" if ctx.full else "ch6-quick"),
        full=ctx.full,
        progress=_say("ch6") if ctx.progress else None,
        cache=StageCache(ctx.results_dir, fingerprint(), fresh=ctx.fresh),
        **_params(ctx),
    )
    if ctx.renderers.ch6 is not None:
        s6.figures = list(ctx.renderers.ch6(s6, ctx.figures_dir("ch6")))
    return _run(sec.ch6_section(s6, full=ctx.full), s6, s6.table)


def run_ch7(ctx: ExperimentContext) -> ExperimentRun:
    """Chapter 7 (:func:`uvnav.experiments.ch7.reproduce_ch7`: its stages in the results
    folder's stage cache, JSON in ``results_dir/ch7``)."""
    from uvnav.bench.stages import StageCache
    from uvnav.experiments.ch7 import fingerprint, reproduce_ch7

    draw7 = ctx.renderers.ch7
    s7 = reproduce_ch7(
        Path(ctx.results_dir) / "ch7",
        full=ctx.full,
        cache=StageCache(ctx.results_dir, fingerprint(), fresh=ctx.fresh),
        render_plan=None
        if draw7 is None
        else (lambda plan, prefix: draw7(plan, ctx.figures_dir("ch7") / Path(prefix).name)),
        **_params(ctx),
    )
    return _run(sec.ch7_section(s7, full=ctx.full), s7, s7.table)


def plan_beyond(ctx: ExperimentContext) -> list[PlannedCampaign]:
    """The office-floor and multi-robot campaigns (:func:`uvnav.experiments.beyond.campaign_plans`;
    the replanning row is timed, not stored)."""
    from uvnav.experiments.beyond import campaign_plans

    return _planned(campaign_plans, _params(ctx, full=ctx.full))


def run_beyond(ctx: ExperimentContext) -> ExperimentRun:
    """The experiments beyond the thesis (:mod:`uvnav.experiments.beyond`; their episodes
    stored in ``results_dir``'s database); figures in ``report_dir/beyond``."""
    from uvnav.experiments.beyond import replan_rows, reproduce_beyond

    rows = reproduce_beyond(ctx.results_dir, **_params(ctx, full=ctx.full)) + replan_rows()
    draw = ctx.renderers.beyond
    figs = draw(ctx.figures_dir("beyond")) if draw is not None else []
    return _run(sec.beyond_section(rows, figs, full=ctx.full), rows, rows)


def _crowds_args(ctx: ExperimentContext) -> dict[str, Any]:
    return _params(
        ctx, full=ctx.full, workers=ctx.workers, cases=ctx.seeds, start_case=ctx.start_seed,
        progress=ctx.progress,
    )  # fmt: skip


def plan_crowds(ctx: ExperimentContext) -> list[PlannedCampaign]:
    """The crowd campaigns (:func:`uvnav.experiments.crowds.campaign_plans`)."""
    from uvnav.experiments.crowds import campaign_plans

    return _planned(campaign_plans, _crowds_args(ctx))


def run_crowds(ctx: ExperimentContext) -> ExperimentRun:
    """Every 2D law on CrowdNav's crowds (:func:`uvnav.experiments.crowds.reproduce_crowds`:
    ``seeds`` test cases per scene from ``start_seed``) and its section."""
    from uvnav.experiments.crowds import crowds_section, reproduce_crowds

    sc = reproduce_crowds(ctx.results_dir, **_crowds_args(ctx))
    section = crowds_section(sc)
    return _run(section, sc, section.rows)


def _regime_args(ctx: ExperimentContext) -> dict[str, Any]:
    return _params(
        ctx, full=ctx.full, workers=ctx.workers, seeds=ctx.seeds, start_seed=ctx.start_seed,
        progress=ctx.progress,
    )  # fmt: skip


def plan_regime(ctx: ExperimentContext) -> list[PlannedCampaign]:
    """The regime map's campaign (:func:`uvnav.experiments.regime.campaign_plans`)."""
    from uvnav.experiments.regime import campaign_plans

    return _planned(campaign_plans, _regime_args(ctx))


def run_regime(ctx: ExperimentContext) -> ExperimentRun:
    """The regime map (:func:`uvnav.experiments.regime.run_regime_map`: ``seeds`` seeds per
    regime and law from ``start_seed``): a section, no table rows."""
    from uvnav.experiments.regime import regime_section, run_regime_map

    rm = run_regime_map(ctx.results_dir, **_regime_args(ctx))
    out = _run(regime_section(rm, full=ctx.full), rm, [])
    out.campaigns = {"regime-map": rm.campaign}
    return out


#: The declared sizes of the built-ins (the seeds are the reproductions' defaults, which a test
#: checks).
SIZES: dict[str, dict[str, Size]] = {
    "ch2": {
        "quick": Size("thesis scenes, 200 random scenes per law, baselines, crowds", 200),
        "full": Size("thesis scenes, 1000 random scenes per law, baselines, crowds", 1000),
    },
    "crowds": {
        "quick": Size("100 CrowdNav test cases per scene, every 2D law", 100),
        "full": Size("500 CrowdNav test cases per scene (the test set), every 2D law", 500),
    },
    "regime": {
        "quick": Size("30 seeds per regime and law", 30),
        "full": Size("100 seeds per regime and law", 100),
    },
    "ch3": {
        "quick": Size("thesis scenes, 2 random scenes, prediction study", 2),
        "full": Size("thesis scenes, 500 random scenes, prediction study", 500),
    },
    "ch4": {
        "quick": Size("thesis scenes; random 10, noise 4, hard 4 seeds", 10),
        "full": Size("thesis scenes; random 200, noise 50, hard 100 seeds", 200),
    },
    "ch5": {
        "quick": Size("BPNN rows of 50/150 samples, thesis scenes, 3 random scenes", 3),
        "full": Size("BPNN rows up to 5000 samples, thesis scenes, 300 random scenes", 300),
    },
    "ch6": {
        "quick": Size("2 expert episodes of 500 steps, 3 epochs, 2 tracks", params=RUN_QUICK),
        "full": Size("20 episodes of 1200 steps, 30 epochs, DAgger, 20 tracks"),
    },
    "ch7": {
        "quick": Size("counts, coverage; 2 plans (synthetic 300 m, Jacksboro 600 m)"),
        "full": Size("counts, coverage; 12 plans (2 terrains x 2 sides x 3 radii)"),
    },
    "beyond": {
        "quick": Size("office floor with 2 laws, 16-robot swap, replanning"),
        "full": Size("office floor with 4 laws, 16-robot swap with ORCA, replanning"),
    },
}

#: The built-in experiments, in report order.
BUILTINS: tuple[Experiment, ...] = (
    Experiment("ch2", "Chapter 2: a unicycle among moving, deforming obstacles", run_ch2,
               seeded=True, sizes=SIZES["ch2"], order=10, plan=plan_ch2),
    Experiment("crowds", "Every 2D law on CrowdNav's crowds (circle and square crossing)",
               run_crowds, seeded=True, sizes=SIZES["crowds"], order=20, plan=plan_crowds),
    Experiment("regime", "Where each law wins: the regime map", run_regime, seeded=True,
               sizes=SIZES["regime"], order=30, plan=plan_regime),
    Experiment("ch3", "Chapter 3: a 3D flying robot with AR prediction", run_ch3, seeded=True,
               sizes=SIZES["ch3"], order=40, plan=plan_ch3),
    Experiment("ch4", "Chapter 4: a UUV among shape-changing obstacles", run_ch4, seeded=True,
               sizes=SIZES["ch4"], order=50, plan=plan_ch4),
    Experiment("ch5", "Chapter 5: a 3D UUV with nine sonars and a BPNN", run_ch5, seeded=True,
               sizes=SIZES["ch5"], order=60, plan=plan_ch5,
               stages=("data sets", "BPNN learning rows", "closed-loop network")),
    Experiment("ch6", "Chapter 6: a CNN that drives (PilotNet on CarRacing)", run_ch6,
               sizes=SIZES["ch6"], order=70, plan=_no_campaigns,
               stages=("expert recording", "training", "target-speed readout", "DAgger rounds",
                       "closed loops")),
    Experiment("ch7", "Chapter 7: UAV reconnaissance of a terrain", run_ch7,
               sizes=SIZES["ch7"], order=80, plan=_no_campaigns,
               stages=("lattice counts", "coverage cases", "plans")),
    Experiment("beyond", "Beyond the thesis: planners, office floor, multi-robot swap",
               run_beyond, sizes=SIZES["beyond"], order=90, plan=plan_beyond),
)  # fmt: skip
