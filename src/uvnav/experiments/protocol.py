"""What an experiment is: a name, a title, whether it runs random seeds, its declared sizes
(:class:`Size`, quick and full), its place in the report, and a ``run`` that takes an
:class:`ExperimentContext` (with the chosen size) and returns an :class:`ExperimentRun` (its report
sections and its rows of the "thesis reported vs uvnav measured" table).

This module imports no experiment and no registry: the built-in experiments
(:mod:`uvnav.experiments.builtin`) and the plug-ins of the entry-point group
:data:`EXPERIMENT_GROUP` import it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from uvnav.experiments.sections import ChapterRenderers, ChapterSection

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
    """

    name: str
    title: str
    run: Callable[[ExperimentContext], ExperimentRun]
    seeded: bool = False
    order: int = 1000
    sections: tuple[str, ...] = ()
    sizes: Mapping[str, Size] = field(default_factory=dict, hash=False)

    def size(self, full: bool) -> Size:
        """Its declared ``full`` or ``quick`` size (an undeclared one runs nothing extra)."""
        return self.sizes.get("full" if full else "quick") or Size(runs="")

    @property
    def section_keys(self) -> tuple[str, ...]:
        """The keys of its sections (:attr:`sections`, or its name)."""
        return self.sections or (self.name,)
