"""Running registered experiments: one (``uvnav reproduce NAME``, :func:`run_experiment`) or
every one in report order (``uvnav run``, :func:`run_all`), and the saved sections a report is
built from.

Every run adds to the store ``results_dir/uvnav.sqlite``: stored episodes are skipped (resume)
and never deleted or replaced; a campaign stored by other code is refused
(:class:`~uvnav.bench.store.StaleCampaignError`).  Each section is saved in
``results_dir/sections/<key>.json`` after the page is written, so a later run's report shows it
beside its own.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from uvnav.bench.fingerprint import DB_NAME
from uvnav.experiments.protocol import (
    Experiment,
    ExperimentContext,
    ExperimentError,
    ExperimentRun,
)
from uvnav.experiments.registry import check_options, experiments, get_experiment, section_order
from uvnav.experiments.sections import (
    SECTION_ORDER,
    SECTIONS_DIR,
    ChapterSection,
    load_sections,
    save_section,
)
from uvnav.experiments.stored import report_sections as builtin_sections


@dataclass
class Reproduction:
    """What :func:`run_experiment` or :func:`run_all` ran and wrote.

    Attributes:
        runs: each experiment's run by name, in the order run.
        table: every run's table rows, in that order.
        sections: every run's sections, in that order.
        db_path: the results database.
        report_path: ``index.html`` when a run wrote the page (``None``: the caller writes it
            from :attr:`sections` or the saved ones).
        figures: the figure files the page's writer drew.
        section_paths: where the sections were saved.
        campaigns: every run's campaign counts by campaign name.
        failures: every run's failed episodes.
        wall_time: elapsed time [s].
    """

    runs: dict[str, ExperimentRun]
    table: list[dict[str, str]]
    sections: list[ChapterSection]
    db_path: Path
    report_path: Path | None = None
    figures: list[Path] = field(default_factory=list)
    section_paths: list[Path] = field(default_factory=list)
    campaigns: dict[str, dict[str, Any]] = field(default_factory=dict)
    failures: list[Any] = field(default_factory=list)
    wall_time: float = 0.0


def saved_sections(results_dir: Path) -> list[ChapterSection]:
    """The sections saved in ``results_dir/sections``, in report order."""
    return load_sections(Path(results_dir) / SECTIONS_DIR, section_order())


def _run_one(experiment: Experiment, ctx: ExperimentContext) -> ExperimentRun:
    run = experiment.run(experiment.prepare(ctx))
    keys = experiment.section_keys
    for s in run.sections:
        if s.key not in keys:
            raise ExperimentError(
                f"experiment {experiment.name!r} returned section {s.key!r}; its sections are "
                f"{', '.join(keys)}"
            )
    return run


def _finish(
    runs: dict[str, ExperimentRun],
    ctx: ExperimentContext,
    *,
    others: Sequence[ChapterSection],
    started: float,
) -> Reproduction:
    """Write the page (the first run with a report hook, with ``others`` after the runs'
    sections), then save the runs' sections and sum up."""
    sections = [s for r in runs.values() for s in r.sections]
    table = [row for r in runs.values() for row in r.rows]
    hook = next((r.report for r in runs.values() if r.report is not None), None)
    report_path: Path | None = None
    figures: list[Path] = []
    if hook is not None:
        page_rows = [*table, *(row for s in others for row in s.rows)]
        report_path, figures = hook([*sections, *others], page_rows)
    folder = Path(ctx.results_dir) / SECTIONS_DIR
    paths = [save_section(s, folder) for s in sections]  # after the page: it may add figures
    return Reproduction(
        runs=runs,
        table=table,
        sections=sections,
        db_path=Path(ctx.results_dir) / DB_NAME,
        report_path=report_path,
        figures=list(figures),
        section_paths=paths,
        campaigns={k: v for r in runs.values() for k, v in r.campaigns.items()},
        failures=[f for r in runs.values() for f in r.failures],
        wall_time=time.perf_counter() - started,
    )


def run_experiment(name: str, ctx: ExperimentContext) -> Reproduction:
    """Run the experiment ``name`` into the store and save its sections; an experiment that
    writes the page (Chapter 2) writes it with the sections saved by earlier runs after its own.

    Raises:
        ExperimentError: unknown experiment, ``seeds``/``start_seed`` it does not take, or a
            broken plug-in.
        StaleCampaignError: a stored campaign cannot be resumed.
    """
    experiment = get_experiment(name)
    check_options(experiment, ctx.seeds, ctx.start_seed)
    Path(ctx.results_dir).mkdir(parents=True, exist_ok=True)
    tic = time.perf_counter()
    run = _run_one(experiment, ctx)
    own = {s.key for s in run.sections}
    others = [s for s in saved_sections(ctx.results_dir) if s.key not in own]
    return _finish({name: run}, ctx, others=others, started=tic)


def run_all(ctx: ExperimentContext, names: Sequence[str] | None = None) -> Reproduction:
    """``uvnav run``: every registered experiment (or those ``names``) in report order, one page
    over all of them, every section saved.  ``ctx.seeds`` / ``ctx.start_seed`` reach the seeded
    experiments only.

    Raises:
        ExperimentError: an unknown name, or a broken plug-in.
        StaleCampaignError: a stored campaign cannot be resumed.
    """
    known = experiments()
    chosen = list(known) if names is None else [get_experiment(n).name for n in names]
    for name in chosen:
        if known[name].seeded:
            check_options(known[name], ctx.seeds, ctx.start_seed)
    Path(ctx.results_dir).mkdir(parents=True, exist_ok=True)
    tic = time.perf_counter()
    runs = {name: _run_one(known[name], ctx) for name in known if name in chosen}
    return _finish(runs, ctx, others=[], started=tic)


def report_sections(db_path: Path) -> list[ChapterSection]:
    """The sections of the report of a results database (``uvnav report DB``): the built-ins'
    (:func:`uvnav.experiments.stored.report_sections`: saved, or rebuilt from the stored rows)
    and the plug-ins' saved sections, in report order.  The database is only read."""
    db_path = Path(db_path)
    found = {s.key: s for s in builtin_sections(db_path)}
    extra = [k for k in section_order() if k not in SECTION_ORDER]
    found.update({s.key: s for s in load_sections(db_path.parent / SECTIONS_DIR, extra)})
    return [found[k] for k in section_order() if k in found]
