"""What an experiment is: a name, a title, whether it runs random seeds, its declared sizes
(:class:`Size`, quick and full), its place in the report, a ``run`` that takes an
:class:`ExperimentContext` (with the chosen size) and returns an :class:`ExperimentRun` (its report
sections and its rows of the "thesis reported vs uvnav measured" table) and, optionally, a
``plan`` that returns the campaigns (:class:`PlannedCampaign`) the run would run at that size
without running anything (``uvnav reproduce NAME --plan``), and the names of its stages.

This module imports no experiment and no registry: the built-in experiments
(:mod:`uvnav.experiments.builtin`) and the plug-ins of the entry-point group
:data:`EXPERIMENT_GROUP` import it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from uvnav.experiments.sections import ChapterRenderers, ChapterSection

if TYPE_CHECKING:
    from uvnav.bench.jobs import Job

#: entry-point group of plug-in experiments
EXPERIMENT_GROUP = "uvnav.experiments"

#: ``(sections, table) -> (index.html, figure files)``: a run that draws figures only when the
#: page is written (Chapter 2) writes the page with every section and row given.
ReportHook = Callable[[list[ChapterSection], list[dict[str, str]]], tuple[Path | None, list[Path]]]


class ExperimentError(ValueError):
    """An unknown experiment, an option it does not take, or a broken plug-in (one line)."""


#: the sizes every experiment may declare: ``quick`` (the default) and ``full`` (``--full``)
SIZE_NAMES: tuple[str, ...] = ("quick", "full")


@dataclass(frozen=True)
class Size:
    """One declared size of an experiment.

    Attributes:
        runs: one line: what this size runs (shown by ``uvnav reproduce --list``).
        seeds: the random scenes it runs by default (seeded experiments; ``--seeds`` overrides).
        params: keyword arguments the experiment's run passes to its reproduction (empty: the
            reproduction's own defaults for ``full``).
    """

    runs: str
    seeds: int | None = None
    params: Mapping[str, Any] = field(default_factory=dict, hash=False)


@dataclass(frozen=True)
class ExperimentContext:
    """Where and how an experiment runs.

    Attributes:
        results_dir: folder of the results database (``uvnav.sqlite``), the experiment's own
            files and ``sections/``.
        report_dir: folder of the report; the experiment's figures go to ``report_dir/<name>``.
        full: thesis-size runs (else the quick size).
        workers: worker processes.
        seeds: random scenes to run (seeded experiments; ``None``: the experiment's size).
        start_seed: first random scene (seeded experiments).
        renderers: figure renderers injected by the caller (the CLI passes
            :func:`uvnav.viz.reproduction.chapter_renderers`); a field left ``None`` draws nothing.
        render: the report renderer (:func:`uvnav.viz.reproduction.render_reproduction`), which
            an experiment may use to write the page (Chapter 2's :data:`ReportHook`).
        progress: progress output on stderr.
        fresh: remake the stages of the stage cache this run reaches, even those made by other
            code (stored episodes are never deleted).
        size: the chosen size (``None``: the runner fills in the experiment's declared
            ``full`` or ``quick`` size).
    """

    results_dir: Path
    report_dir: Path
    full: bool = False
    workers: int = 2
    seeds: int | None = None
    start_seed: int = 0
    renderers: ChapterRenderers = field(default_factory=ChapterRenderers)
    render: Any = None
    progress: bool = True
    fresh: bool = False
    size: Size | None = None

    def figures_dir(self, name: str) -> Path:
        """``report_dir/<name>``, the folder of one experiment's figures."""
        return Path(self.report_dir) / name


@dataclass
class ExperimentRun:
    """What one experiment's run produced.

    Attributes:
        sections: its report sections (each key among its :attr:`Experiment.section_keys`).
        rows: its rows of the "thesis reported vs uvnav measured" table.
        summary: the experiment's own summary object (for tests and the CLI's extras).
        failures: failed episodes it lists.
        campaigns: per campaign run: its counts (jobs, ran, skipped, errors, wall time).
        report: writes the report page when the experiment has figures drawn only with the page
            (``None``: the page is written from the sections alone).
    """

    sections: list[ChapterSection]
    rows: list[dict[str, str]] = field(default_factory=list)
    summary: Any = None
    failures: list[Any] = field(default_factory=list)
    campaigns: dict[str, dict[str, Any]] = field(default_factory=dict)
    report: ReportHook | None = None


@dataclass(frozen=True)
class PlannedCampaign:
    """One campaign an experiment's run runs into the store.

    Attributes:
        name: the campaign's name in the store.
        config: the config it is created with (its code fingerprint among it).
        jobs: its jobs, in run order (their :attr:`~uvnav.bench.jobs.Job.key` are the resume
            keys the run stores).
    """

    name: str
    config: Mapping[str, Any] = field(hash=False)
    jobs: tuple[Job, ...] = ()


@dataclass(frozen=True)
class Experiment:
    """One reproduction, run by ``uvnav reproduce NAME`` and, in :attr:`order`, by ``uvnav run``.

    Attributes:
        name: what ``uvnav reproduce`` takes (lower case, no spaces).
        title: one line, shown by ``uvnav reproduce --list``.
        run: ``run(ctx) -> ExperimentRun``.
        seeded: it runs random seeds (``--seeds`` / ``--start-seed`` apply).
        order: its place in ``uvnav run``, in the report and in the table (smaller first; ties by
            name).
        sections: the keys of the sections it returns (default: its name); the saved sections are
            found again by these keys.
        sizes: its declared sizes by name (:data:`SIZE_NAMES`).
        plan: ``plan(ctx) -> [PlannedCampaign]``: the campaigns ``run(ctx)`` runs, in order, built
            by the same functions and without running or storing anything (``None``: it declares
            no plan).
        stages: the names of its stages (training, planning, ...) that are not campaigns, in the
            order run (shown by ``--plan``; they are run and cached by ``run``).
    """

    name: str
    title: str
    run: Callable[[ExperimentContext], ExperimentRun]
    seeded: bool = False
    order: int = 1000
    sections: tuple[str, ...] = ()
    sizes: Mapping[str, Size] = field(default_factory=dict, hash=False)
    plan: Callable[[ExperimentContext], list[PlannedCampaign]] | None = None
    stages: tuple[str, ...] = ()

    def size(self, full: bool) -> Size:
        """Its declared ``full`` or ``quick`` size (an undeclared one runs nothing extra)."""
        return self.sizes.get("full" if full else "quick") or Size(runs="")

    def prepare(self, ctx: ExperimentContext) -> ExperimentContext:
        """``ctx`` as its ``run`` and ``plan`` get it: no seeds for an unseeded experiment, and
        its declared size filled in when ``ctx`` has none."""
        if not self.seeded:
            ctx = dataclasses.replace(ctx, seeds=None, start_seed=0)
        if ctx.size is None:
            ctx = dataclasses.replace(ctx, size=self.size(ctx.full))
        return ctx

    @property
    def section_keys(self) -> tuple[str, ...]:
        """The keys of its sections (:attr:`sections`, or its name)."""
        return self.sections or (self.name,)
