"""The built-in experiments' sections of ``uvnav report DB``, from a results database alone.

:func:`report_sections` uses a section saved next to the database as it is; otherwise it rebuilds
the sections whose tables are computed from stored rows only (``ch2``, ``ch4``, ``crowds``,
``regime``) from the stored episodes, and gives an experiment whose campaigns or result files are
there but whose section was not saved a section saying to rerun ``uvnav reproduce NAME``.  The
database is only read.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import uvnav.experiments.ch2 as rp
from uvnav.experiments.sections import SECTIONS_DIR, TITLES, ChapterSection, rows_of

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


def _rebuilt(
    key: str, what: str, table: list[dict[str, Any]], figures: bool = True
) -> ChapterSection:
    """A section rebuilt from the stored episodes of ``what`` (its campaigns)."""
    notes = [f"No figures: they are drawn by 'uvnav reproduce {key}' (or 'uvnav run')."]
    intro = f"Rebuilt from the episodes stored in the database ({what})."
    return ChapterSection(key, TITLES[key], intro, rows_of(table), notes=notes if figures else [])


def _ch2_from_store(store: Any) -> ChapterSection | None:
    cfg = next((c["config"] for c in store.campaigns() if c["name"] == rp.SCENES_CAMPAIGN), None)
    if cfg is None:
        return None
    scenes, ctrls = list(cfg.get("scenes", [])), list(cfg.get("controllers", []))
    straight = rp.comparison_straight_line(scenes)
    table, _ = rp.build_table(store, scenes, ctrls, straight_line=straight)
    if store.campaign_id(rp.BASELINES_CAMPAIGN) is not None:
        table += rp.comparison_rows(store)
    return _rebuilt("ch2", "thesis scenes, random, baseline and crowd campaigns", table)


def _ch4_from_store(store: Any) -> ChapterSection:
    import uvnav.experiments.ch4 as r4

    rows = [r for name in r4.CAMPAIGNS for r in r4.stored_rows(store, name)]
    table = r4._table(r4.stored_rows(store, r4.SCENES_CAMPAIGN), r4.summarise(rows))
    return _rebuilt("ch4", "thesis scenes, random, noise and hard campaigns", table)


def _crowds_from_store(store: Any) -> ChapterSection:
    import uvnav.experiments.crowds as rc

    what = (
        f"campaigns {', '.join(rc.CAMPAIGNS)}: every stored test case of CrowdNav's circle and "
        "square crossing; success and collision with 95 % Wilson intervals, the paper's ORCA "
        "figure, social metrics in the notes"
    )
    return _rebuilt("crowds", what, rc.crowd_rows(store), figures=False)


def report_sections(db_path: Path) -> list[ChapterSection]:
    """The chapter sections of the report of a results database (``uvnav report DB``).

    A section saved by the last run of its chapter (``DB folder/sections``) is used as it is;
    otherwise Chapters 2 and 4 and the crowd section, whose tables are computed from stored rows
    only, are rebuilt from the database's episodes; a chapter with stored campaigns or result
    files but no saved section gets a section that says to rerun ``uvnav reproduce CH``.  The
    database is only read.
    """
    from uvnav.bench.store import ResultsStore
    from uvnav.experiments.sections import SECTION_ORDER, load_sections

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
                from uvnav.experiments.crowds import CAMPAIGNS

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
                from uvnav.experiments.regime import regime_section

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
