"""uvnav's own experiments: the thesis chapters ``ch2`` … ``ch7``, ``crowds``, ``regime`` and
``beyond``, each a thin adapter over its runner in :mod:`uvnav.bench.chapters` (Chapter 2:
:func:`uvnav.bench.reproduce.run_ch2` and :func:`~uvnav.bench.reproduce.finish`).

``seeds`` / ``start_seed`` choose the random scenes of the seeded ones: ``seeds`` scenes from
``start_seed`` (Ch. 2: the random and baseline campaigns; Ch. 3: the random-ch3 scenes; Ch. 4:
every family — random-ch4, the noise sweep, random-ch4-hard; Ch. 5: the random-ch5 closed-loop
scenes; crowds: CrowdNav's test cases ``start_seed`` .. ``start_seed + seeds - 1`` of each scene;
regime: the seeds of every regime).
"""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from uvnav.bench import chapters as ch
from uvnav.bench import reproduce as rp
from uvnav.bench.sections import ChapterSection
from uvnav.experiments.protocol import Experiment, ExperimentContext, ExperimentRun


def _run(section: ChapterSection, summary: Any, rows: list[dict[str, str]]) -> ExperimentRun:
    failures = list(getattr(summary, "failures", []) or [])
    return ExperimentRun(sections=[section], rows=list(rows), summary=summary, failures=failures)


def _seeded(ctx: ExperimentContext) -> dict[str, Any]:
    return {"full": ctx.full, "workers": ctx.workers, "seeds": ctx.seeds,
            "start_seed": ctx.start_seed}  # fmt: skip


def run_ch2(ctx: ExperimentContext) -> ExperimentRun:
    """Chapter 2's campaigns and section; its figures are drawn when the page is written."""
    ch2 = rp.run_ch2(
        ctx.results_dir, full=ctx.full, workers=ctx.workers, progress=ctx.progress,
        n_random=ctx.seeds, start_seed=ctx.start_seed, controllers=rp.CONTROLLERS,
        baselines=rp.BASELINES, n_baseline_seeds=ctx.seeds,
    )  # fmt: skip

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


def run_ch3(ctx: ExperimentContext) -> ExperimentRun:
    """Chapter 3 (:func:`uvnav.bench.chapters.run_ch3`)."""
    dirs = (ctx.results_dir, ctx.report_dir)
    section, s3 = ch.run_ch3(*dirs, **_seeded(ctx), renderers=ctx.renderers, progress=False)
    return _run(section, s3, s3.table)


def run_ch4(ctx: ExperimentContext) -> ExperimentRun:
    """Chapter 4 (:func:`uvnav.bench.chapters.run_ch4`)."""
    dirs = (ctx.results_dir, ctx.report_dir)
    section, s4 = ch.run_ch4(*dirs, **_seeded(ctx), renderers=ctx.renderers)
    return _run(section, s4, s4.table)


def run_ch5(ctx: ExperimentContext) -> ExperimentRun:
    """Chapter 5 (:func:`uvnav.bench.chapters.run_ch5`)."""
    dirs = (ctx.results_dir, ctx.report_dir)
    kw = _seeded(ctx)
    section, s5 = ch.run_ch5(*dirs, **kw, renderers=ctx.renderers, progress=ctx.progress)
    return _run(section, s5, s5.table)


def run_ch6(ctx: ExperimentContext) -> ExperimentRun:
    """Chapter 6 at ``uvnav run``'s size (:func:`uvnav.bench.chapters.run_ch6`)."""
    section, s6 = ch.run_ch6(
        ctx.results_dir, ctx.report_dir, full=ctx.full, renderers=ctx.renderers,
        fresh=ctx.fresh, progress=ctx.progress,
    )  # fmt: skip
    return _run(section, s6, s6.table)


def run_ch7(ctx: ExperimentContext) -> ExperimentRun:
    """Chapter 7 (:func:`uvnav.bench.chapters.run_ch7`)."""
    dirs = (ctx.results_dir, ctx.report_dir)
    section, s7 = ch.run_ch7(*dirs, full=ctx.full, renderers=ctx.renderers)
    return _run(section, s7, s7.table)


def run_beyond(ctx: ExperimentContext) -> ExperimentRun:
    """The experiments beyond the thesis (:func:`uvnav.bench.chapters.run_beyond`)."""
    section, rows = ch.run_beyond(
        ctx.report_dir, full=ctx.full, renderers=ctx.renderers, results_dir=ctx.results_dir
    )
    return _run(section, rows, rows)


def run_crowds(ctx: ExperimentContext) -> ExperimentRun:
    """Every 2D law on CrowdNav's crowds (:func:`uvnav.bench.chapters.run_crowds`)."""
    section, sc = ch.run_crowds(ctx.results_dir, **_seeded(ctx), progress=ctx.progress)
    return _run(section, sc, section.rows)


def run_regime(ctx: ExperimentContext) -> ExperimentRun:
    """The regime map (:func:`uvnav.bench.chapters.run_regime`): a section, no table rows."""
    section, rm = ch.run_regime(ctx.results_dir, **_seeded(ctx), progress=ctx.progress)
    out = _run(section, rm, [])
    out.campaigns = {"regime-map": rm.campaign}
    return out


#: The built-in experiments, in report order.
BUILTINS: tuple[Experiment, ...] = (
    Experiment("ch2", "Chapter 2: a unicycle among moving, deforming obstacles", run_ch2,
               seeded=True, order=10),
    Experiment("crowds", "Every 2D law on CrowdNav's crowds (circle and square crossing)",
               run_crowds, seeded=True, order=20),
    Experiment("regime", "Where each law wins: the regime map", run_regime, seeded=True,
               order=30),
    Experiment("ch3", "Chapter 3: a 3D flying robot with AR prediction", run_ch3, seeded=True,
               order=40),
    Experiment("ch4", "Chapter 4: a UUV among shape-changing obstacles", run_ch4, seeded=True,
               order=50),
    Experiment("ch5", "Chapter 5: a 3D UUV with nine sonars and a BPNN", run_ch5, seeded=True,
               order=60),
    Experiment("ch6", "Chapter 6: a CNN that drives (PilotNet on CarRacing)", run_ch6,
               order=70),
    Experiment("ch7", "Chapter 7: UAV reconnaissance of a terrain", run_ch7, order=80),
    Experiment("beyond", "Beyond the thesis: planners, office floor, multi-robot swap",
               run_beyond, order=90),
)  # fmt: skip
