"""The answer on one screen: a verdict on each row of the "thesis reported vs uvnav measured"
table, and the summary ``uvnav run`` ends with (and ``RESULTS/thesis-vs-uvnav.md`` opens with).

A row's verdict is decided by one stated rule, never by hand, so a reader can check it:

* an experiment that knows better sets the row's ``verdict`` itself, and it is kept;
* ``beyond``: the thesis gives nothing to compare (its cell is empty, ``-``, "not reported",
  "no numbers", or the row is uvnav's own measurement);
* ``reproduced``: the two cells say the same, the thesis's remarks in parentheses aside (same
  words, or the same numbers within :data:`REL_TOL` relative, or every measured number inside
  the thesis's ``[lo, hi]`` range, or the measured number on the right side of the thesis's
  bound ``> x``);
* ``differs``: both give numbers and they disagree by that rule, or the thesis calls its own
  figure a failure and uvnav's is not one;
* ``-`` (not judged): anything else (words against numbers, figures described in prose).

Pure functions on the rows; printing is the CLI's.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from typing import Any

#: two figures agree within this relative difference
REL_TOL = 0.05
#: the verdicts, in the order the summary counts them
VERDICTS: tuple[str, ...] = ("reproduced", "differs", "beyond", "-")
#: a thesis cell that gives nothing to compare
_NOTHING = re.compile(
    r"^\s*(?:(?:-+|–|—|n/?a|none|\.\.\.)?\s*$|(?:not reported|not given|not shown|no numbers?)\b)",
    re.IGNORECASE,
)
#: a bound: ``> 0``, ``>= 0.9``, ``< 1 s``
_BOUND = re.compile(r"^\s*(>=|<=|>|<|≥|≤)\s*([-+]?\d+(?:\.\d+)?)")
_NUMBER = re.compile(r"[-+]?\d+(?:[.,]\d+)?(?:e[-+]?\d+)?%?", re.IGNORECASE)
_RANGE = re.compile(r"\[\s*([-+]?[\d.]+)\s*,\s*([-+]?[\d.]+)\s*\]")

#: width of the one-screen summary [columns] and its most lines
WIDTH, MAX_LINES = 80, 40


def _numbers(text: str) -> list[float]:
    out = []
    for m in _NUMBER.findall(text):
        v = float(m.rstrip("%").replace(",", ""))
        out.append(v / 100.0 if m.endswith("%") else v)
    return out


def _without_remarks(text: str) -> str:
    """``text`` without its parenthesised remarks, nested ones included (figure, page)."""
    while True:
        plain = re.sub(r"\([^()]*\)", " ", text)
        if plain == text:
            return plain.strip()
        text = plain


def _words(text: str) -> str:
    return " ".join(re.sub(r"[^\w\s]", " ", text.lower()).split())


def row_verdict(row: Mapping[str, Any]) -> str:
    """A row's verdict (module docstring: the rule).

    >>> row_verdict({"thesis": "success", "measured": "success"})
    'reproduced'
    >>> row_verdict({"thesis": "14.46 m", "measured": "14.52 m"})
    'reproduced'
    >>> row_verdict({"thesis": "[0.1, 0.3]", "measured": "0.25"})
    'reproduced'
    >>> row_verdict({"thesis": "17592", "measured": "750"})
    'differs'
    >>> row_verdict({"thesis": "-", "measured": "0.95"})
    'beyond'
    >>> row_verdict({"thesis": "not reported (beyond the thesis)", "measured": "0.95"})
    'beyond'
    >>> row_verdict({"thesis": "success (Fig. 2.7)", "measured": "success"})
    'reproduced'
    >>> row_verdict({"thesis": "> 0 (never reaches 0)", "measured": "0.249 m"})
    'reproduced'
    >>> row_verdict({"thesis": "reaches E, no collision (figure only)", "measured": "success"})
    '-'
    """
    given = row.get("verdict")
    if isinstance(given, str) and given in VERDICTS:
        return given
    thesis = "" if row.get("thesis") is None else str(row.get("thesis"))
    measured = "" if row.get("measured") is None else str(row.get("measured"))
    if _NOTHING.match(thesis):
        return "beyond"
    thesis = _without_remarks(thesis)
    if _words(thesis) and _words(thesis) == _words(measured):
        return "reproduced"
    bound, got = _BOUND.match(thesis), _numbers(measured)
    if bound is not None and len(got) == 1 and len(_numbers(thesis)) == 1:
        op, x, v = bound.group(1), float(bound.group(2)), got[0]
        holds = {">": v > x, ">=": v >= x, "≥": v >= x, "<": v < x, "<=": v <= x, "≤": v <= x}
        return "reproduced" if holds[op] else "differs"
    if "failure" in thesis.lower():
        return "differs" if "failure" not in measured.lower() else "reproduced"
    rng = _RANGE.search(thesis)
    if rng is not None and got and len(_numbers(thesis)) == 2:
        lo, hi = sorted((float(rng.group(1)), float(rng.group(2))))
        return "reproduced" if all(lo <= v <= hi for v in got) else "differs"
    want = _numbers(thesis)
    if want and got and len(want) == len(got) and not re.search(r"[a-z]{3,}", thesis.lower()):
        close = all(
            math.isclose(w, g, rel_tol=REL_TOL, abs_tol=1e-12)
            for w, g in zip(want, got, strict=True)
        )
        return "reproduced" if close else "differs"
    return "-"


def counts(rows: Sequence[Mapping[str, Any]]) -> dict[str, int]:
    """How many rows have each verdict (every verdict present, zeros included)."""
    out = dict.fromkeys(VERDICTS, 0)
    for row in rows:
        out[row_verdict(row)] += 1
    return out


def count_text(c: Mapping[str, int]) -> str:
    """``"12 reproduced, 1 differs, 4 beyond, 3 not judged"`` (zero counts left out)."""
    names = {"-": "not judged"}
    parts = [f"{c[v]} {names.get(v, v)}" for v in VERDICTS if c.get(v)]
    return ", ".join(parts) if parts else "no rows"


def headline(rows: Sequence[Mapping[str, Any]]) -> Mapping[str, Any] | None:
    """The row a section is summed up by: its first judged row (reproduced or differs), else its
    first row."""
    judged = [r for r in rows if row_verdict(r) in ("reproduced", "differs")]
    return judged[0] if judged else (rows[0] if rows else None)


def _cut(text: str, width: int) -> str:
    """``text`` on one line (its indentation kept), cut to ``width`` with an ellipsis."""
    text = str(text)
    indent = text[: len(text) - len(text.lstrip(" "))]
    text = indent + " ".join(text.split())
    return text if len(text) <= width else text[: width - 1] + "…"


def summary_lines(
    sections: Sequence[Any],
    *,
    report: str | None,
    table: str | None,
    laws: Sequence[str] = (),
) -> list[str]:
    """The one screen: the report and the table's paths, per section its title, verdict counts
    and headline row (thesis | uvnav, verdict), then ``laws`` ("which law, where" lines); at
    most :data:`MAX_LINES` lines of at most :data:`WIDTH` characters."""
    all_rows = [r for s in sections for r in (getattr(s, "rows", None) or [])]
    lines = [_cut(f"uvnav run: {len(sections)} experiments, {count_text(counts(all_rows))}", WIDTH)]
    if report:
        lines.append(_cut(f"report: {report}", WIDTH))
    if table:
        lines.append(_cut(f"table:  {table} ({len(all_rows)} rows, verdict column)", WIDTH))
    lines.append("")
    for sec in sections:
        rows = list(getattr(sec, "rows", None) or [])
        lines.append(_cut(f"{sec.title}", WIDTH))
        lines.append(_cut(f"  {count_text(counts(rows))}", WIDTH))
        head = headline(rows)
        if head is not None and len(lines) < MAX_LINES - len(laws) - 2:
            lines.append(_headline_line(head))
    if laws:
        lines.append("")
        lines += [_cut(line, WIDTH) for line in laws]
    return lines[:MAX_LINES]


def _headline_line(row: Mapping[str, Any]) -> str:
    """``  quantity: thesis X | uvnav Y -> verdict`` in :data:`WIDTH` columns, the quantity cut
    first so that the figures and the verdict stay whole."""
    thesis = " ".join(str(row.get("thesis") or "-").split())
    measured = " ".join(str(row.get("measured") or "-").split())
    values = f"thesis {_without_remarks(thesis) or thesis} | uvnav {measured} -> {row_verdict(row)}"
    room = WIDTH - 4 - len(values)
    if room < 12:  # long figures: they get the line
        return _cut(f"  {values}", WIDTH)
    return f"  {_cut(str(row.get('quantity', '')), room)}: {values}"


def table_lines(sections: Sequence[Any], rows: Sequence[Mapping[str, Any]]) -> list[str]:
    """``thesis-vs-uvnav.md``: the per-experiment verdict counts, the rule, then every row with
    its verdict (Markdown)."""
    out = ["# Thesis reported vs uvnav measured", ""]
    for sec in sections:
        sec_rows = list(getattr(sec, "rows", None) or [])
        out.append(f"- **{sec.title}**: {count_text(counts(sec_rows))}")
    out += [
        "",
        "Verdict: `reproduced` when both cells say the same (words, or numbers within "
        f"{REL_TOL:.0%}, or inside the thesis's range), `differs` when their numbers disagree, "
        "`beyond` where the thesis gives nothing to compare, `-` where no rule applies (see the "
        "note).",
        "",
    ]
    cols = ("quantity", "thesis", "measured", "verdict", "note")
    out += ["| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for row in rows:
        cells = {**row, "verdict": row_verdict(row)}
        vals = [_md(cells.get(c)) for c in cols]
        out.append("| " + " | ".join(vals) + " |")
    return out


def _md(value: Any) -> str:
    text = "-" if value is None else " ".join(str(value).split())
    return text.replace("|", "\\|")
