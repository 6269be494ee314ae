"""The verdict of each table row and the one screen ``uvnav run`` ends with
(:mod:`uvnav.experiments.verdict`)."""

from __future__ import annotations

import pytest

from uvnav.experiments.sections import ChapterSection
from uvnav.experiments.verdict import (
    MAX_LINES,
    WIDTH,
    counts,
    headline,
    row_verdict,
    summary_lines,
    table_lines,
)


@pytest.mark.parametrize(
    ("thesis", "measured", "verdict"),
    [
        ("success, no collision (Fig. 2.10(b))", "success, no collision", "reproduced"),
        ("14.9 m", "14.46 m", "reproduced"),  # 3 %
        ("15.7 m", "14.83 m", "differs"),  # 5.5 %
        ("1.054 (15.7 / 14.9)", "1.026", "reproduced"),
        ("[0.06, 0.21]", "median [0.08, 0.12]", "reproduced"),
        ("[0.06, 0.21]", "median [0.08, 0.42]", "differs"),
        ("> 0 (no collision, Fig. 2.8(b))", "0.181 m", "reproduced"),
        ("> 0", "-0.02 m", "differs"),
        ("[0.1, 0.4]: a failure", "median [0.02, 0.05]", "differs"),
        ("not reported (beyond the thesis)", "75.0% (6/8)", "beyond"),
        ("", "0.95", "beyond"),
        ("—", "success, path 25.3 m", "beyond"),
        ("path shown (Fig. 2.9), outcome not stated: a guess", "success", "-"),
        ("17592", "750", "differs"),
    ],
)
def test_a_rows_verdict_follows_the_stated_rule(thesis: str, measured: str, verdict: str) -> None:
    assert row_verdict({"thesis": thesis, "measured": measured}) == verdict


def test_an_experiments_own_verdict_is_kept() -> None:
    row = {"thesis": "15.7 m", "measured": "14.83 m", "verdict": "reproduced"}
    assert row_verdict(row) == "reproduced"
    assert row_verdict({**row, "verdict": "maybe"}) == "differs"  # not a verdict: the rule's


def _rows(k: int) -> list[dict[str, str]]:
    base = [
        {"quantity": "a long quantity " * 6, "thesis": "not reported", "measured": "1.0"},
        {"quantity": "a second quantity " * 6, "thesis": "0.93 (Table 4.2)", "measured": "0.91"},
    ]
    return (base * k)[:k]


def test_the_summary_is_one_screen_with_a_headline_per_experiment() -> None:
    titles = [
        f"Chapter {k} — a very long title of an experiment that goes on and on" for k in range(9)
    ]
    sections = [ChapterSection(f"ch{k}", t, "", rows=_rows(k + 2)) for k, t in enumerate(titles)]
    laws = ["which law, where:"] + [f"  panel {k}: zhang2019-holonomic-v2 (9/9)" for k in range(5)]
    lines = summary_lines(sections, report="report/index.html", table="results/t.md", laws=laws)
    assert len(lines) <= MAX_LINES and max(len(line) for line in lines) <= WIDTH
    every = [r for s in sections for r in s.rows]
    assert lines[0] == f"uvnav run: 9 experiments, {counts(every)['reproduced']} reproduced, " + (
        f"{counts(every)['beyond']} beyond"
    )
    heads = [line for line in lines if line.endswith("-> reproduced")]
    assert len(heads) == 9 and all("thesis 0.93 | uvnav 0.91" in h for h in heads)
    assert lines[-5:] == laws[-5:]


def test_the_table_opens_with_the_counts_and_carries_the_verdicts() -> None:
    sec = ChapterSection("ch4", "Chapter 4", "", rows=_rows(3))
    text = "\n".join(table_lines([sec], sec.rows))
    head, body = text.split("| quantity |")
    assert "**Chapter 4**: 1 reproduced, 2 beyond" in head and "within 5%" in head
    assert body.startswith(" thesis | measured | verdict | note |")
    assert "| 0.93 (Table 4.2) | 0.91 | reproduced |" in body
    assert headline(sec.rows) is sec.rows[1]  # the first judged row
