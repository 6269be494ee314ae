"""One runner per chapter: ``run_ch3`` … ``run_ch7``, ``run_beyond``, ``run_crowds`` and
``run_regime`` each run one reproduction into the results store ``results_dir/uvnav.sqlite`` (and
the chapter's own files under ``results_dir``), draw its figures with the injected renderers
(:class:`~uvnav.bench.sections.ChapterRenderers`) into ``report_dir/<chapter>``, and return its
report section with the chapter's summary object.  Chapter 2's runner is
:func:`uvnav.bench.reproduce.run_ch2`.  The experiments of ``uvnav reproduce NAME`` and ``uvnav
run`` are registered over these runners in :mod:`uvnav.experiments`, which this module never
imports.

:func:`report_sections` gives the sections of ``uvnav report DB``: saved ones as they are, others
rebuilt from the stored rows where a chapter's table is computed from them alone.

Every chapter adds to the store: stored episodes are skipped (resume) and never deleted or
replaced by a later run; a campaign that cannot be resumed (stored by other code) is refused with
:class:`~uvnav.bench.store.StaleCampaignError`.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from uvnav.bench import reproduce as rp
from uvnav.bench.sections import SECTIONS_DIR, ChapterRenderers, ChapterSection


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
    "report_sections",
    "run_beyond",
    "run_ch3",
    "run_ch4",
    "run_ch5",
    "run_ch6",
    "run_ch7",
    "run_crowds",
    "run_regime",
]
