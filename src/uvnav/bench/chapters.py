"""One chapter's reproduction at a time: the job behind ``uvnav reproduce CHAPTER``.

:func:`reproduce_chapter` runs one of :data:`CHAPTERS` — a thesis chapter ``ch2`` … ``ch7``,
``beyond`` (the experiments beyond the thesis: planners, office floor, multi-robot swap) or
``crowds`` (every 2D law on CrowdNav's crowds, :mod:`uvnav.bench.reproduce_crowds`) or
``regime`` (the regime map, :mod:`uvnav.bench.regime`) — into
the results store ``results_dir/uvnav.sqlite`` (and the chapter's own files under
``results_dir``), draws its figures with the injected renderers
(:class:`~uvnav.bench.sections.ChapterRenderers`) into ``report_dir/<chapter>``, and saves its
report section in ``results_dir/sections/<chapter>.json`` (:func:`~uvnav.bench.sections.
save_section`), so the report shows it beside the sections of the chapters run before.

``uvnav run`` (:func:`reproduce_all`) runs Chapter 2 (:mod:`uvnav.bench.reproduce`) and then the
same per-chapter runners (:func:`run_ch3` … :func:`run_beyond`, :func:`run_crowds`,
:func:`run_regime`), so the two entry points run the same experiments.

Every chapter adds to the store: stored episodes are skipped (resume) and never deleted or
replaced by a later run; a campaign that cannot be resumed (stored by other code) is refused with
:class:`~uvnav.bench.store.StaleCampaignError`.

``seeds`` and ``start_seed`` (chapters with random scenes, :data:`SEEDED`) choose the random
scenes: ``seeds`` scenes from ``start_seed`` (Ch. 2: the random and baseline campaigns; Ch. 3: the
random-ch3 scenes; Ch. 4: every family — random-ch4, the noise sweep, random-ch4-hard; Ch. 5: the
random-ch5 closed-loop scenes; crowds: CrowdNav's test cases ``start_seed`` ..
``start_seed + seeds - 1`` of each scene; regime: the seeds of every regime).
"""

from __future__ import annotations

import dataclasses
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from uvnav.bench import reproduce as rp
from uvnav.bench.fingerprint import DB_NAME
from uvnav.bench.sections import SECTIONS_DIR, ChapterRenderers, ChapterSection, save_section

#: What ``uvnav reproduce`` accepts (``all`` is ``uvnav run``).
CHAPTERS: tuple[str, ...] = (
    "ch2",
    "ch3",
    "ch4",
    "ch5",
    "ch6",
    "ch7",
    "beyond",
    "crowds",
    "regime",
)
#: Chapters that run random seeds (``seeds`` / ``start_seed`` apply).
SEEDED: frozenset[str] = frozenset({"ch2", "ch3", "ch4", "ch5", "crowds", "regime"})


class ChapterError(ValueError):
    """An unknown chapter, or an option the chapter does not take (one line)."""


@dataclass
class ChapterRun:
    """What :func:`reproduce_chapter` ran and wrote.

    Attributes:
        chapter: the chapter key.
        section: its report section (rows, figures, links, notes).
        summary: the chapter's own summary object (``Ch3Summary``, ...; ``None`` for ``beyond``).
        db_path: the results database.
        section_path: where the section was saved.
        report_path: ``index.html`` when a report renderer was given.
        failures: failed episodes the chapter lists (its summary's ``failures``).
    """

    chapter: str
    section: ChapterSection
    summary: Any
    db_path: Path
    section_path: Path | None = None
    report_path: Path | None = None
    failures: list[Any] = field(default_factory=list)


def _say(chapter: str) -> Callable[[str], None]:
    def say(message: str) -> None:
        print(f"{chapter}: {message}", file=sys.stderr, flush=True)

    return say


# ------------------------------------------------------------------------ one runner per chapter


def run_ch3(
    results_dir: Path,
    report_dir: Path,
    *,
    full: bool,
    workers: int,
    renderers: ChapterRenderers,
    seeds: int | None = None,
    start_seed: int = 0,
    progress: bool = False,
) -> tuple[ChapterSection, Any]:
    """Chapter 3 (:func:`uvnav.bench.reproduce_ch3.reproduce_ch3`) and its section."""
    from uvnav.bench import sections as sec
    from uvnav.bench.reproduce_ch3 import reproduce_ch3

    s3 = reproduce_ch3(
        results_dir,
        report_dir,
        full=full,
        workers=workers,
        n_random=seeds,
        start_seed=start_seed,
        render=renderers.ch3,
        progress=progress,
    )
    return sec.ch3_section(s3, full=full, n_random=seeds, start_seed=start_seed), s3


def run_ch4(
    results_dir: Path,
    report_dir: Path,
    *,
    full: bool,
    workers: int,
    renderers: ChapterRenderers,
    seeds: int | None = None,
    start_seed: int = 0,
) -> tuple[ChapterSection, Any]:
    """Chapter 4 (:func:`uvnav.bench.reproduce_ch4.reproduce_ch4`) and its section."""
    from uvnav.bench import sections as sec
    from uvnav.bench.reproduce_ch4 import reproduce_ch4

    s4 = reproduce_ch4(
        results_dir,
        report_dir,
        full=full,
        workers=workers,
        render=renderers.ch4,
        seeds=seeds,
        noise_seeds=seeds,
        hard_seeds=seeds,
        start_seed=start_seed,
    )
    return sec.ch4_section(s4, full=full, seeds=seeds, start_seed=start_seed), s4


def run_ch5(
    results_dir: Path,
    report_dir: Path,
    *,
    full: bool,
    workers: int,
    renderers: ChapterRenderers,
    seeds: int | None = None,
    start_seed: int = 0,
    progress: bool = True,
) -> tuple[ChapterSection, Any]:
    """Chapter 5 (:func:`uvnav.bench.reproduce_ch5.reproduce_ch5`) and its section."""
    from uvnav.bench import sections as sec
    from uvnav.bench.reproduce_ch5 import reproduce_ch5

    s5 = reproduce_ch5(
        results_dir,
        full=full,
        progress=progress,
        render=renderers.ch5,
        report_dir=report_dir,
        workers=workers,
        n_random=seeds,
        start_seed=start_seed,
    )
    return sec.ch5_section(s5, full=full), s5


def run_ch6(
    results_dir: Path,
    report_dir: Path,
    *,
    full: bool,
    renderers: ChapterRenderers,
    fresh: bool = False,
    progress: bool = True,
) -> tuple[ChapterSection, Any]:
    """Chapter 6 at ``uvnav run``'s size (:data:`uvnav.bench.reproduce_ch6.RUN_QUICK`; the thesis
    size with ``full``) in ``results_dir/ch6-quick`` (``results_dir/ch6``); every pipeline option
    is ``uvnav drive reproduce``'s."""
    from uvnav.bench import sections as sec
    from uvnav.bench.reproduce_ch6 import RUN_QUICK, reproduce_ch6

    s6 = reproduce_ch6(
        Path(results_dir) / ("ch6" if full else "ch6-quick"),
        full=full,
        fresh=fresh,
        progress=_say("ch6") if progress else None,
        **({} if full else RUN_QUICK),
    )
    if renderers.ch6 is not None:
        s6.figures = list(renderers.ch6(s6, Path(report_dir) / "ch6"))
    return sec.ch6_section(s6, full=full), s6


def run_ch7(
    results_dir: Path, report_dir: Path, *, full: bool, renderers: ChapterRenderers
) -> tuple[ChapterSection, Any]:
    """Chapter 7 (:func:`uvnav.bench.reproduce_ch7.reproduce_ch7`, JSON in ``results_dir/ch7``)."""
    from uvnav.bench import sections as sec
    from uvnav.bench.reproduce_ch7 import reproduce_ch7

    draw7 = renderers.ch7
    s7 = reproduce_ch7(
        Path(results_dir) / "ch7",
        full=full,
        render_plan=None
        if draw7 is None
        else (lambda plan, prefix: draw7(plan, Path(report_dir) / "ch7" / Path(prefix).name)),
    )
    return sec.ch7_section(s7, full=full), s7


def run_beyond(
    report_dir: Path,
    *,
    full: bool,
    renderers: ChapterRenderers,
    results_dir: Path | None = None,
) -> tuple[ChapterSection, list[dict[str, str]]]:
    """The experiments beyond the thesis (:mod:`uvnav.bench.reproduce_beyond`; their episodes
    stored in ``results_dir``'s database, a temporary one for ``None``); figures in
    ``report_dir/beyond``."""
    from uvnav.bench import sections as sec
    from uvnav.bench.reproduce_beyond import replan_rows, reproduce_beyond

    rows = reproduce_beyond(results_dir, full=full) + replan_rows()
    figs = renderers.beyond(Path(report_dir) / "beyond") if renderers.beyond is not None else []
    return sec.beyond_section(rows, figs, full=full), rows


def run_crowds(
    results_dir: Path,
    *,
    full: bool,
    workers: int,
    seeds: int | None = None,
    start_seed: int = 0,
    progress: bool = False,
) -> tuple[ChapterSection, Any]:
    """Every 2D law on CrowdNav's crowds (:func:`uvnav.bench.reproduce_crowds.reproduce_crowds`:
    ``seeds`` test cases per scene from ``start_seed``) and its section."""
    from uvnav.bench.reproduce_crowds import crowds_section, reproduce_crowds

    sc = reproduce_crowds(
        results_dir,
        full=full,
        workers=workers,
        cases=seeds,
        start_case=start_seed,
        progress=progress,
    )
    return crowds_section(sc), sc


def run_regime(
    results_dir: Path,
    *,
    full: bool,
    workers: int,
    seeds: int | None = None,
    start_seed: int = 0,
    progress: bool = False,
) -> tuple[ChapterSection, Any]:
    """The regime map (:func:`uvnav.bench.regime.run_regime_map`: ``seeds`` seeds per regime and
    law from ``start_seed``) and its section."""
    from uvnav.bench.regime import regime_section, run_regime_map

    rm = run_regime_map(
        results_dir,
        full=full,
        workers=workers,
        seeds=seeds,
        start_seed=start_seed,
        progress=progress,
    )
    return regime_section(rm, full=full), rm


# ------------------------------------------------------------------------------- uvnav run


def reproduce_all(
    results_dir: Path,
    report_dir: Path,
    *,
    full: bool = False,
    workers: int = 2,
    progress: bool = True,
    fresh: bool = False,
    n_random: int | None = None,
    start_seed: int = 0,
    controllers: Sequence[str] | None = None,
    baselines: Sequence[str] | None = None,
    n_baseline_seeds: int | None = None,
    n_crowd_seeds: int | None = None,
    render: Any = None,
    ch7: bool | None = None,
    ch5: bool = False,
    ch5_render: Callable[..., list[Path]] | None = None,
    renderers: ChapterRenderers | None = None,
    save_sections: bool = True,
    crowds: bool | None = None,
    regime: bool | None = None,
) -> rp.ReproductionSummary:
    """``uvnav run``: Chapter 2 (:func:`uvnav.bench.reproduce.run_ch2`), then the other chapters,
    one report over all of them, every section saved.

    After Chapter 2 come, in a real run (``n_random`` not given), the crowd section (every 2D law
    on CrowdNav's crowds, after Chapter 2's ETH crowds), the regime map (the report's first
    screen), the experiments beyond the thesis, Chapter 6 (the CNN that drives: at
    :data:`uvnav.bench.reproduce_ch6.RUN_QUICK`'s size in quick mode, the thesis size with
    ``full``; in ``results_dir/ch6-quick`` and ``results_dir/ch6``), Chapter 3, Chapter 7 and
    Chapter 4; Chapter 5 with ``ch5``.  The table and the sections keep that order, sections in
    report order (the thesis chapters, then "beyond").

    Args:
        results_dir, report_dir, full, workers, progress, n_random, start_seed, controllers,
            baselines, n_baseline_seeds, n_crowd_seeds, render, save_sections: as
            :func:`uvnav.bench.reproduce.reproduce` (``None``: its defaults).
        fresh: rerun Chapter 6's finished stages (its files; stored episodes are never deleted).
        ch7: also run Chapter 7 (:mod:`uvnav.bench.reproduce_ch7`); ``None`` = in a real run.
        ch5: also run Chapter 5 (:func:`uvnav.bench.reproduce_ch5.reproduce_ch5`); ``ch5_render``
            draws its figures into ``report_dir/ch5`` (default ``renderers.ch5``).
        renderers: the other chapters' figure renderers (the CLI passes
            :func:`uvnav.viz.reproduction.chapter_renderers`); each chapter's figures go to
            ``report_dir/<chapter>`` and into its report section.
        crowds: also run the crowd section; ``None`` = in a real run with baselines.
        regime: also run the regime map; ``None`` = in a real run with baselines.

    Returns:
        The :class:`uvnav.bench.reproduce.ReproductionSummary` of the whole run.

    Raises:
        StaleCampaignError: a stored campaign cannot be resumed (see the module docstring).
    """
    tic = time.perf_counter()
    base = rp.BASELINES if baselines is None else baselines
    ch2 = rp.run_ch2(
        results_dir, full=full, workers=workers, progress=progress, n_random=n_random,
        start_seed=start_seed, controllers=rp.CONTROLLERS if controllers is None else controllers,
        baselines=base, n_baseline_seeds=n_baseline_seeds, n_crowd_seeds=n_crowd_seeds,
    )  # fmt: skip
    table, sections, campaigns = list(ch2.table), [ch2.section], dict(ch2.campaigns)
    rend = renderers or ChapterRenderers()
    real_run = n_random is None  # test-sized runs (n_random given) leave the other chapters out
    later: list[ChapterSection] = []  # what goes beyond the thesis comes after the chapters
    by_key: dict[str, ChapterSection] = {}
    dirs = (Path(results_dir), Path(report_dir))
    kw: dict[str, Any] = {"full": full, "workers": workers}
    if crowds if crowds is not None else (base and real_run):  # after the ETH crowds
        sec_c, _ = run_crowds(dirs[0], **kw, progress=progress)
        table += sec_c.rows
        sections.append(sec_c)
    if regime if regime is not None else (base and real_run):  # "which law, where"
        sec_r, rm = run_regime(dirs[0], **kw, progress=progress)
        campaigns["regime-map"] = rm.campaign
        sections.append(sec_r)
    if base and real_run:  # beyond the thesis (a real run, not a quick look)
        sec_b, rows_b = run_beyond(dirs[1], full=full, renderers=rend, results_dir=dirs[0])
        table += rows_b
        later.append(sec_b)
    if real_run:  # Chapter 6 (CNN driving): the thesis size with --full, else RUN_QUICK's size
        by_key["ch6"], s6 = run_ch6(
            *dirs, full=full, renderers=rend, fresh=fresh, progress=progress
        )
        table += s6.table
    if real_run:  # Chapter 3 (3D): scenes + random campaign rows
        by_key["ch3"], s3 = run_ch3(*dirs, **kw, renderers=rend)
        table += s3.table
    if ch7 if ch7 is not None else real_run:
        by_key["ch7"], s7 = run_ch7(*dirs, full=full, renderers=rend)
        table += s7.table
    if ch5:  # Chapter 5: BPNN experiment and closed-loop runs (needs the learning extra)
        r5 = rend if ch5_render is None else dataclasses.replace(rend, ch5=ch5_render)
        by_key["ch5"], s5 = run_ch5(*dirs, **kw, renderers=r5, progress=progress)
        table += s5.table
    if real_run:  # Chapter 4; tests that shrink the Chapter 2 campaign leave it out
        by_key["ch4"], s4 = run_ch4(*dirs, **kw, renderers=rend)
        table += s4.table
    sections += [by_key[k] for k in ("ch3", "ch4", "ch5", "ch6", "ch7") if k in by_key]
    sections += later
    return rp.finish(
        ch2, dirs[0], dirs[1], table=table, sections=sections, campaigns=campaigns,
        render=render, save_sections=save_sections, started=tic,
    )  # fmt: skip


# ------------------------------------------------------------------------------- the dispatcher


def reproduce_chapter(
    chapter: str,
    results_dir: Path,
    report_dir: Path,
    *,
    full: bool = False,
    workers: int = 2,
    seeds: int | None = None,
    start_seed: int = 0,
    renderers: ChapterRenderers | None = None,
    render: Any = None,
    progress: bool = True,
) -> ChapterRun:
    """Run one chapter's reproduction into the store and save its report section.

    Args:
        chapter: one of :data:`CHAPTERS`.
        results_dir: folder of ``uvnav.sqlite``, the chapter's files and ``sections/``.
        report_dir: folder of the figures (``report_dir/<chapter>``) and of the report.
        full: thesis-size runs.
        workers: worker processes.
        seeds: random scenes to run (chapters in :data:`SEEDED`; default the chapter's quick or
            full size).
        start_seed: first random scene (chapters in :data:`SEEDED`).
        renderers: the chapters' figure renderers (``None``: no figures).
        render: Chapter 2's report renderer (:func:`uvnav.viz.reproduction.render_reproduction`),
            which draws its figures from the database and writes ``index.html``; the other
            chapters' reports are written by the caller from the saved sections.
        progress: progress output on stderr.

    Raises:
        ChapterError: unknown chapter, or ``seeds``/``start_seed`` for a chapter without random
            scenes.
        StaleCampaignError: a stored campaign cannot be resumed (see the module docstring).
    """
    if chapter not in CHAPTERS:
        raise ChapterError(
            f"unknown chapter {chapter!r}; expected one of {', '.join(CHAPTERS)} or all"
        )
    if chapter not in SEEDED and (seeds is not None or start_seed != 0):
        raise ChapterError(
            f"{chapter} runs no random seeds: --seeds/--start-seed apply to "
            f"{', '.join(sorted(SEEDED))}"
        )
    if seeds is not None and seeds < 1:
        raise ChapterError(f"--seeds {seeds}: at least one seed")
    if start_seed < 0:
        raise ChapterError(f"--start-seed {start_seed}: seeds are >= 0")
    results_dir = Path(results_dir)
    report_dir = Path(report_dir)
    results_dir.mkdir(parents=True, exist_ok=True)
    rend = renderers or ChapterRenderers()
    db_path = results_dir / DB_NAME
    summary: Any
    report_path: Path | None = None
    if chapter == "ch2":
        n = seeds if seeds is not None else (rp.FULL_SEEDS if full else rp.QUICK_SEEDS)
        summary = rp.reproduce(
            results_dir, report_dir, full=full, workers=workers, progress=progress, n_random=n,
            start_seed=start_seed, n_baseline_seeds=seeds, render=render, save_sections=False,
        )  # fmt: skip
        section = next(s for s in summary.sections if s.key == "ch2")
        report_path = summary.report_path
    else:
        dirs = (results_dir, report_dir)
        seeded: dict[str, Any] = {"full": full, "workers": workers, "seeds": seeds}
        seeded["start_seed"] = start_seed
        runs: dict[str, Callable[[], tuple[ChapterSection, Any]]] = {
            "ch3": lambda: run_ch3(*dirs, **seeded, renderers=rend, progress=False),
            "ch4": lambda: run_ch4(*dirs, **seeded, renderers=rend),
            "ch5": lambda: run_ch5(*dirs, **seeded, renderers=rend, progress=progress),
            "ch6": lambda: run_ch6(*dirs, full=full, renderers=rend, progress=progress),
            "ch7": lambda: run_ch7(*dirs, full=full, renderers=rend),
            "crowds": lambda: run_crowds(results_dir, **seeded, progress=progress),
            "regime": lambda: run_regime(results_dir, **seeded, progress=progress),
            "beyond": lambda: run_beyond(
                report_dir, full=full, renderers=rend, results_dir=results_dir
            ),
        }
        section, summary = runs[chapter]()
    path = save_section(section, results_dir / SECTIONS_DIR)
    return ChapterRun(
        chapter=chapter,
        section=section,
        summary=summary,
        db_path=db_path,
        section_path=path,
        report_path=report_path,
        failures=list(getattr(summary, "failures", []) or []),
    )


# ------------------------------------------------------------------ sections for ``uvnav report``

#: Chapters whose results are files under the results folder, not store campaigns.
_FILE_CHAPTERS = {"ch6": ("ch6", "ch6-quick"), "ch7": ("ch7",)}


def _rerun_section(key: str, why: str) -> ChapterSection:
    names = {"beyond": "the experiments beyond the thesis", "crowds": "CrowdNav's crowds"}
    name = names.get(key, f"Chapter {key[2:]}")
    return ChapterSection(
        key=key,
        title=f"{name[0].upper()}{name[1:]}",
        intro=why,
        notes=[
            f"Run 'uvnav reproduce {key}' to rebuild this section (stored episodes are reused)."
        ],
    )


def _ch2_from_store(store: Any) -> ChapterSection | None:
    from uvnav.bench.sections import rows_of

    cfg = next((c["config"] for c in store.campaigns() if c["name"] == rp.SCENES_CAMPAIGN), None)
    if cfg is None:
        return None
    scenes, ctrls = list(cfg.get("scenes", [])), list(cfg.get("controllers", []))
    straight = rp.comparison_straight_line(scenes)
    table, _ = rp.build_table(store, scenes, ctrls, straight_line=straight)
    if store.campaign_id(rp.BASELINES_CAMPAIGN) is not None:
        table += rp.comparison_rows(store)
    return ChapterSection(
        key="ch2",
        title="Chapter 2 — a unicycle among moving, deforming obstacles",
        intro="Rebuilt from the episodes stored in the database (thesis scenes, random, baseline "
        "and crowd campaigns).",
        rows=rows_of(table),
        notes=["No figures: they are drawn by 'uvnav reproduce ch2' (or 'uvnav run')."],
    )


def _ch4_from_store(store: Any) -> ChapterSection:
    from uvnav.bench import reproduce_ch4 as r4
    from uvnav.bench.sections import rows_of

    rows = [r for name in r4.CAMPAIGNS for r in r4.stored_rows(store, name)]
    table = r4._table(r4.stored_rows(store, r4.SCENES_CAMPAIGN), r4.summarise(rows))
    return ChapterSection(
        key="ch4",
        title="Chapter 4 — a UUV among shape-changing obstacles",
        intro="Rebuilt from the episodes stored in the database (thesis scenes, random, noise and "
        "hard campaigns).",
        rows=rows_of(table),
        notes=["No figures: they are drawn by 'uvnav reproduce ch4' (or 'uvnav run')."],
    )


def _crowds_from_store(store: Any) -> ChapterSection:
    from uvnav.bench import reproduce_crowds as rc
    from uvnav.bench.sections import rows_of

    return ChapterSection(
        key="crowds",
        title="Beyond the thesis — CrowdNav's crowds, every 2D law",
        intro="Rebuilt from the episodes stored in the database (campaigns "
        f"{', '.join(rc.CAMPAIGNS)}: every stored test case of CrowdNav's circle and square "
        "crossing; success and collision with 95 % Wilson intervals, the paper's ORCA figure, "
        "social metrics in the notes).",
        rows=rows_of(rc.crowd_rows(store)),
    )


def report_sections(db_path: Path) -> list[ChapterSection]:
    """The chapter sections of the report of a results database (``uvnav report DB``).

    A section saved by the last run of its chapter (``DB folder/sections``) is used as it is;
    otherwise Chapters 2 and 4 and the crowd section, whose tables are computed from stored rows
    only, are rebuilt from the database's episodes; a chapter with stored campaigns or result
    files but no saved section gets a section that says to rerun ``uvnav reproduce CH``.  The
    database is only read.
    """
    from uvnav.bench.sections import SECTION_ORDER, load_sections
    from uvnav.bench.store import ResultsStore

    db_path = Path(db_path)
    saved = {s.key: s for s in load_sections(db_path.parent / SECTIONS_DIR)}
    out: list[ChapterSection] = []
    with ResultsStore(db_path, readonly=True) as store:
        names = {str(c["name"]) for c in store.campaigns()}
        for key in SECTION_ORDER:
            if key in saved:
                out.append(saved[key])
                continue
            if key == "crowds":  # its campaigns are CrowdNav's ("crowds-eth" is Chapter 2's)
                from uvnav.bench.reproduce_crowds import CAMPAIGNS

                stored = any(n in CAMPAIGNS for n in names)
            else:
                stored = any(n.startswith(f"{key}-") for n in names)
            files = any((db_path.parent / d).is_dir() for d in _FILE_CHAPTERS.get(key, ()))
            section: ChapterSection | None = None
            if key == "ch2" and stored:
                section = _ch2_from_store(store)
            elif key == "ch4" and stored:
                section = _ch4_from_store(store)
            elif key == "crowds" and stored:
                section = _crowds_from_store(store)
            elif key == "regime" and stored:
                from uvnav.bench.regime import regime_section

                section = regime_section(None, full=False)
            if section is None and (stored or files):
                what = "campaigns are stored" if stored else "result files exist"
                section = _rerun_section(
                    key,
                    f"Its {what} next to this database, but its section (table, figures) is "
                    "computed by the chapter's run and was not saved with it.",
                )
            if section is not None:
                out.append(section)
    return out


__all__ = [
    "CHAPTERS",
    "SEEDED",
    "ChapterError",
    "ChapterRun",
    "report_sections",
    "reproduce_all",
    "reproduce_chapter",
    "run_beyond",
    "run_ch3",
    "run_ch4",
    "run_ch5",
    "run_ch6",
    "run_ch7",
    "run_crowds",
    "run_regime",
]
