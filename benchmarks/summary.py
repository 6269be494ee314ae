"""Issue 20's targets in one table: target, measured, ratio, pass/fail (the end of ``make bench``).

Run: ``.venv/bin/python benchmarks/summary.py [--results benchmarks/results]``.  It only reads
the JSON files the benchmarks wrote there; it measures nothing:

* ``peers.json`` (``benchmarks/peers/irsim_steps.py``): the world step with 100 and 10 moving
  polygons [CPU µs, median] and its speed over ir-sim's;
* ``peers_orca.json`` (``benchmarks/peers/navground_orca.py``): multi-robot ORCA (the packed
  ``orca-shared-v1`` swarm) on ``antipodal:10`` / ``antipodal:100``, its CPU time per step over
  navground's (within 2x = at most 2);
* ``campaign.json`` (``benchmarks/bench_campaign.py``): 10,000 episodes in <= 120 s wall;
* ``ray.json`` (``benchmarks/bench_ray.py``): the CPU the Ray engine adds per episode, at most
  10 % of the episode's own, over the issue's 10,000-episode campaign (a smaller run, whose
  per-episode share of the workers' fixed warm-up is larger, is marked as a smoke run);
* ``vector_env.json`` (``benchmarks/bench_vector_env.py``): the vector env's target,
  env steps per CPU second ("not measured" until a benchmark writes it);
* ``summary.json`` (``benchmarks/run_benchmarks.py``): a closing line with how many of its own
  targets pass;
* ``peers.json`` again: a last line with ir-sim's step time in the sitting (:func:`machine_line`),
  how fast the machine ran.

A missing file reads "not run", a peer that was not installed "no peer", a quick (smoke) run is
marked with ``*``.  ``ratio`` is measured / limit (the target's direction says which side of 1
passes).  Exit status 0 whatever the verdicts: the table is a report.
"""

from __future__ import annotations

import argparse
import json
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

WIDTH = 80
#: Ray's added CPU per episode, at most this share of the episode's own (``bench_ray.py``)
TARGET_RAY_SHARE = 0.10
#: the issue's campaign, whose line the Ray target is part of: a smaller Ray run is a smoke run
RAY_EPISODES = 10_000


@dataclass(frozen=True)
class Row:
    """One line of the table."""

    name: str
    target: str
    measured: str = ""
    ratio: str = ""
    result: str = "not run"


#: (file, key in its "targets", row name, target text, unit of the measured value)
PEER_ROWS: tuple[tuple[str, str, str, str, str], ...] = (
    ("peers.json", "world_step_us_100", "world step, 100 polygons", "<= 15 µs CPU", " µs"),
    ("peers.json", "vs_irsim_100", "  steps/s over ir-sim's", ">= 1,000x", "x"),
    ("peers.json", "world_step_us_10", "world step, 10 polygons", "<= 3 µs CPU", " µs"),
    (
        "peers_orca.json",
        "orca_vs_navground_10",
        "ORCA antipodal:10 vs navground",
        "<= 2x ng time",
        "x",
    ),
    (
        "peers_orca.json",
        "orca_vs_navground_100",
        "ORCA antipodal:100 vs navground",
        "<= 2x ng time",
        "x",
    ),
)


def load(results: Path, name: str) -> dict[str, Any] | None:
    """``results/name`` as a dict, or ``None`` when it is missing or not a JSON object."""
    path = results / name
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def number(x: Any, unit: str = "") -> str:
    """A measured value, 3-4 significant figures, with its unit; ``-`` when missing."""
    if not isinstance(x, int | float) or isinstance(x, bool) or not math.isfinite(x):
        return "-"
    if abs(x) >= 1000:
        text = f"{x:,.0f}"
    elif abs(x) >= 100:
        text = f"{x:.0f}"
    elif abs(x) >= 10:
        text = f"{x:.1f}"
    else:
        text = f"{x:.2f}"
    return text + unit


def verdict(passed: Any, quick: bool) -> str:
    """PASS / FAIL (``*``: from a quick run) or ``not measured``."""
    if passed is None:
        return "not measured"
    return ("PASS" if passed else "FAIL") + ("*" if quick else "")


def judged_row(name: str, target: str, record: dict[str, Any], unit: str, quick: bool) -> Row:
    """A row from a target record (``measured``, ``limit``, ``pass``, optional ``ratio``)."""
    measured, limit = record.get("measured"), record.get("limit")
    ratio = record.get("ratio")
    if ratio is None and isinstance(measured, int | float) and isinstance(limit, int | float):
        ratio = measured / limit if limit else None
    return Row(
        name, target, number(measured, unit), number(ratio), verdict(record.get("pass"), quick)
    )


def peer_rows(results: Path) -> list[Row]:
    """The world-step and ORCA rows from the peer benchmarks' files."""
    rows = []
    for file, key, name, target, unit in PEER_ROWS:
        data = load(results, file)
        if data is None:
            rows.append(Row(name, target))
            continue
        record = data.get("targets", {}).get(key)
        if not isinstance(record, dict):
            rows.append(Row(name, target, result="not run"))
        elif record.get("measured") is None and data.get("available") is False:
            rows.append(Row(name, target, "-", "-", "no peer"))
        else:
            rows.append(judged_row(name, target, record, unit, bool(data.get("quick"))))
    return rows


def campaign_row(results: Path) -> Row:
    """10,000 episodes of random-ch2 x 2 laws in <= 120 s wall (``campaign.json``)."""
    name, target = "campaign, 10,000 episodes", "<= 120 s wall"
    data = load(results, "campaign.json")
    if data is None:
        return Row(name, target)
    record = {"measured": data.get("wall_s_per_10000"), "limit": 120.0, "pass": data.get("pass")}
    return judged_row(name, target, record, " s", bool(data.get("quick")))


def ray_row(results: Path) -> Row:
    """Ray's added CPU per episode, in % of the episode's own CPU, <= 10 (``ray.json``)."""
    name, target = "Ray overhead, % episode CPU", "<= 10 %"
    data = load(results, "ray.json")
    record = data.get("target") if data is not None else None
    if data is None or not isinstance(record, dict):
        return Row(name, target)
    share = record.get("measured")
    if isinstance(share, int | float) and not isinstance(share, bool):
        record = {**record, "measured": 100.0 * share, "limit": 100.0 * TARGET_RAY_SHARE}
    episodes = (data.get("ray_engine") or {}).get("episodes")
    small = not isinstance(episodes, int) or episodes < RAY_EPISODES
    return judged_row(name, target, record, " %", bool(data.get("quick")) or small)


def vector_env_rows(results: Path) -> list[Row]:
    """The vector env's targets from ``vector_env.json`` (``bench_vector_env.py``: rows named
    ``vector env...``); one "not measured" row without them."""
    data = load(results, "vector_env.json")
    targets = data.get("targets") if data else None
    found = [
        t
        for t in (targets if isinstance(targets, list) else [])
        if isinstance(t, dict) and str(t.get("name", "")).startswith("vector env")
    ]
    if not found:
        return [Row("vector env", "issue 20", "-", "-", "not measured")]
    quick = bool(data.get("quick")) if data else False
    return [
        Row(
            str(t["name"]),
            str(t.get("target", "")),
            str(t.get("measured", "-")),
            number(t.get("ratio")),
            verdict(t.get("pass"), quick),
        )
        for t in found
    ]


def summary_line(results: Path) -> str | None:
    """How many of ``summary.json``'s own targets pass, or ``None`` without the file."""
    data = load(results, "summary.json")
    targets = data.get("targets") if data else None
    if not isinstance(targets, dict):
        return None
    passed = sum(1 for t in targets.values() if isinstance(t, dict) and t.get("pass"))
    return f"run_benchmarks.py targets (summary.json): {passed} of {len(targets)} pass"


def machine_line(results: Path) -> str | None:
    """ir-sim's median step time in this sitting (``peers.json``), or ``None`` without it.

    The same pure-Python code every time, it shows how fast the machine ran: the targets with
    absolute limits (µs, s, steps/s) move with it, the ratios against peers measured in the
    same run do not, so sittings are compared through this line.
    """
    data = load(results, "peers.json")
    res = data.get("results") if data else None
    if not isinstance(res, dict):
        return None
    parts = []
    for n in ("10", "100"):
        row = res.get(n)
        irsim = row.get("irsim") if isinstance(row, dict) else None
        us = number(irsim.get("median_us_per_step") if isinstance(irsim, dict) else None, " µs")
        if us != "-":
            parts.append(f"{us} ({n} polygons)")
    return "machine: ir-sim's step here " + ", ".join(parts) if parts else None


def build_rows(results: Path) -> list[Row]:
    """Every issue-20 row, in the issue's order."""
    return [
        *peer_rows(results),
        campaign_row(results),
        ray_row(results),
        *vector_env_rows(results),
    ]


def render(rows: Sequence[Row], footer: Sequence[str] = ()) -> str:
    """The table as text, at most :data:`WIDTH` columns wide."""
    head = Row("issue 20 target", "limit", "measured", "ratio", "result")
    lines = []
    for r in [head, *rows]:
        line = (
            f"{r.name:31.31} {r.target:13.13} {r.measured:>11.11} {r.ratio:>7.7}  {r.result:12.12}"
        )
        lines.append(line.rstrip())
        if r is head:
            lines.append("-" * min(WIDTH, max(len(x) for x in lines)))
    if any(r.result.endswith("*") for r in rows):
        lines.append("* quick (smoke) run: indicative only")
    lines.extend(footer)
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", type=Path, default=Path(__file__).resolve().parent / "results")
    args = ap.parse_args(argv)
    footer = [
        "ratio = measured / limit; not run: no result file; no peer: peer not installed",
    ]
    for line in (summary_line(args.results), machine_line(args.results)):
        if line is not None:
            footer.append(line)
    print(render(build_rows(args.results), footer))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
