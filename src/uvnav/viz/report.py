"""The HTML report of a results database (DESIGN §5–6: ``uvnav report DB`` and ``uvnav run``).

:func:`write_report` renders ``out_dir/index.html`` from the Jinja2 template
``uvnav/viz/templates/report.html``, a decision tool first and a record second:

* **first screen, "which law, where"** (:func:`uvnav.viz.regime.decision_view`, read from the
  store): the regime map's heat maps of success and of robot-driven collisions per law, a
  recommendation per regime generated from the numbers, and the law x scene-family table at equal
  seeds with 95 % intervals; rates on fewer than ``SMALL_SAMPLE`` episodes carry a ⚠ marker;
* one section per chapter (:class:`uvnav.experiments.sections.ChapterSection`): heading, what was
  run, that chapter's rows of the "thesis reported vs uvnav measured" table (folded in a
  ``<details>`` when longer than 12 rows), its figures as a grid of thumbnails each linking to the
  full-size file, links to its other files — every file linked relatively: a file already inside
  ``out_dir`` is linked where it is, one outside is copied into ``out_dir/<section key>/``;
  rows of ``table`` that no section shows get a table of their own;
* a metric summary per campaign, scenario family and controller computed from the ``episodes``
  table (folded, in horizontal scroll containers), the other figures, the episodes that raised
  errors, and the campaigns with their configs;
* animated trajectory views whose frames are side files ``anim/anim-<id>.js``
  (:func:`uvnav.viz.interactive.write_animation_file`) loaded when the reader presses a button, so
  the page carries none of them.

Every table fits the text column (fixed layout with wrapping, or a scroll container).  The page
works offline: inline CSS, no external URL; the first screen (the regime map's heat maps are
coloured tables) needs no script, and ``plotly.min.js``, written next to ``index.html`` when the
page has animations, is loaded with the first animation the reader asks for.
"""

from __future__ import annotations

import math
import shutil
import sys
from collections.abc import Mapping, Sequence
from datetime import UTC, datetime
from importlib.resources import files
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from uvnav.bench.summary import wilson_interval
from uvnav.experiments.verdict import count_text, counts, row_verdict, summary_lines

if TYPE_CHECKING:
    import pandas as pd

    from uvnav.experiments.sections import ChapterSection

SIMULATION_NOTE = (
    "In this chapter (thesis Ch. 2) the obstacles are simulated: their shapes and motions come "
    "from the scenario definitions (random turns, constant velocities), and the robot senses them "
    "as each scenario's sensing block says (in the thesis scenes: exact distance, nearest boundary "
    "point, velocity and rotation rate). No recorded sensor data is used."
)

_TABLE_ORDER = ("quantity", "thesis", "measured", "verdict", "note")
_TEXT_COLUMNS = ("family", "controller")
_MAX_ERRORS = 50

FigureSpec = Path | str | tuple[Path | str, str]


def _fmt(x: float | None, digits: int = 3) -> str:
    if x is None or not np.isfinite(x):
        return "–"
    return f"{x:.{digits}f}"


def _mean_median(values: pd.Series, digits: int = 3) -> str:
    """``"mean [95 % CI] / median"`` of the finite values (Student-t interval of the mean)."""
    v = values.to_numpy(dtype=float, na_value=np.nan)
    v = v[np.isfinite(v)]
    if not len(v):
        return "–"
    mean, median = float(np.mean(v)), float(np.median(v))
    if len(v) < 2:
        return f"{_fmt(mean, digits)} / {_fmt(median, digits)}"
    from scipy import stats

    half = float(stats.t.ppf(0.975, len(v) - 1) * np.std(v, ddof=1) / np.sqrt(len(v)))
    ci = f"[{_fmt(mean - half, digits)}, {_fmt(mean + half, digits)}]"
    return f"{_fmt(mean, digits)} {ci} / {_fmt(median, digits)}"


def _rate(hits: pd.Series) -> str:
    """``"87.0% [80.1%, 91.8%]"``, flagged ``⚠`` when on fewer than SMALL_SAMPLE episodes."""
    from uvnav.experiments.regime import SMALL_SAMPLE

    k, n = int(hits.sum()), len(hits)
    lo, hi = wilson_interval(k, n)
    flag = f" ⚠ n={n}" if n < SMALL_SAMPLE else ""
    return f"{k / n:.1%} [{lo:.1%}, {hi:.1%}]{flag}" if n else "–"


#: social metric columns of the summary: (label, episodes column, digits)
_SOCIAL_COLUMNS = (
    ("min_separation [m]", "min_separation", 3),
    ("too_close_frequency", "too_close_frequency", 3),
    ("intrusion_time [s]", "intrusion_time", 2),
    ("intrusion_ratio", "intrusion_ratio", 3),
    ("personal_space_time [s]", "personal_space_time", 2),
    ("min_time_to_collision [s]", "min_time_to_collision", 2),
    ("path_irregularity [rad/m]", "path_irregularity", 3),
    ("heading_irregularity [rad]", "heading_irregularity", 3),
    ("jerk [m/s³]", "jerk", 2),
)


def summary_table(df: pd.DataFrame) -> list[dict[str, Any]]:
    """Per (family, controller) summary rows of an episodes frame, formatted for display.

    Args:
        df: from :meth:`uvnav.bench.store.ResultsStore.episodes_frame` or ``pandas.read_sql``.

    Returns:
        One dict per group, keys in display order: ``family``, ``controller``, ``episodes``,
        ``success rate`` and ``collision rate`` (with 95 % Wilson intervals), ``timeout rate``,
        ``errors``, and "mean [95 % CI] / median" strings of ``min_clearance [m]``,
        ``path_length [m]``, ``detour_ratio``, ``time_ratio``, ``control_effort``, then the
        social and comfort metrics (:mod:`uvnav.sim.social`, :mod:`uvnav.sim.comfort`) the
        frame has values of — ``min_separation [m]``, ``too_close_frequency``, ``intrusion_time
        [s]``, ``intrusion_ratio``, ``personal_space_time [s]``, ``min_time_to_collision [s]``
        when some episode had a pedestrian, ``path_irregularity [rad/m]``, ``heading_irregularity
        [rad]`` and ``jerk [m/s³]`` when some 2D episode moved — and ``decision_us_median [µs]``
        and ``decision_us_p99 [µs]``.
    """
    if df.empty:
        return []
    frame = df.copy()
    if "family" not in frame.columns:
        frame["family"] = frame["scenario"]
    social = [
        (label, name, digits)
        for label, name, digits in _SOCIAL_COLUMNS
        if name in frame.columns and frame[name].notna().any()
    ]
    rows: list[dict[str, Any]] = []
    for (family, controller), g in frame.groupby(["family", "controller"], sort=True):
        n = len(g)
        status = g["status"].astype(str)
        ok = status == "success"
        rows.append(
            {
                "family": family,
                "controller": controller,
                "episodes": n,
                "success rate": _rate(ok),
                "collision rate": _rate(status == "collision"),
                "timeout rate": f"{(status == 'timeout').mean():.1%}",
                "errors": int((status == "error").sum()),
                "min_clearance [m]": _mean_median(g["min_clearance"]),
                "path_length [m]": _mean_median(g["path_length"], 2),
                "detour_ratio": _mean_median(g.loc[ok, "detour_ratio"]),
                "time_ratio": _mean_median(g.loc[ok, "time_ratio"]),
                "control_effort": _mean_median(g["control_effort"], 2),
                **{label: _mean_median(g[name], digits) for label, name, digits in social},
                "decision_us_median [µs]": _mean_median(g["decision_us_median"], 1),
                "decision_us_p99 [µs]": _mean_median(g["decision_us_p99"], 1),
            }
        )
    return rows


def campaign_summaries(df: pd.DataFrame) -> list[dict[str, Any]]:
    """One :func:`summary_table` per campaign, in campaign order.

    Returns:
        ``[{"id": int, "campaign": name, "rows": [...], "columns": [...]}, ...]``; campaigns
        without episodes are left out.
    """
    if df.empty:
        return []
    out: list[dict[str, Any]] = []
    for _, g in df.groupby("campaign_id", sort=True):
        rows = summary_table(g)
        name = str(g["campaign"].iloc[0]) if "campaign" in g.columns else ""
        cid_int = int(g["campaign_id"].iloc[0])
        out.append({"id": cid_int, "campaign": name, "rows": rows, "columns": list(rows[0])})
    return out


def _num(x: Any, digits: int = 1) -> str:
    return f"{x:,.{digits}f}" if isinstance(x, int | float) and math.isfinite(x) else "–"


def benchmark_tables(bench_dir: Path) -> list[dict[str, Any]]:
    """Tables of the benchmark JSON files found in ``bench_dir`` (missing files are skipped).

    * ``summary.json`` (``make bench``): each target, its limit and the measured value;
    * ``peers.json`` (``benchmarks/peers/irsim_steps.py``): world steps/s, uvnav vs ir-sim;
    * ``peers_navground.json`` (``benchmarks/peers/navground_crowd.py``): µs per step and decision
      cost on crowd crossings, uvnav vs navground, with each run's outcome (skipped when it
      records ``"available": false``: navground was not installed).

    Raises:
        ValueError: a file is not the JSON its writer makes (names the file and the key).
    """
    import json

    bench_dir = Path(bench_dir)
    tables: list[dict[str, Any]] = []

    def load(name: str) -> dict[str, Any] | None:
        path = bench_dir / name
        if not path.is_file():
            return None
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except json.JSONDecodeError as exc:
            raise ValueError(f"{path}: not JSON ({exc.msg}, line {exc.lineno})") from None
        if not isinstance(data, dict):
            raise ValueError(f"{path}: expected a JSON object")
        return data

    def machine(data: dict[str, Any]) -> str:
        m = data.get("machine", {})
        return (
            f"measured {m.get('timestamp', '?')} on {m.get('cpu_count', '?')} CPUs "
            f"(1-min load {_num(m.get('load_average_1m'), 2)}), Python {m.get('python', '?')}"
        )

    try:
        if (data := load("summary.json")) is not None:
            rows = [
                {
                    "target": key,
                    "what": t["what"],
                    "limit": f"{t['direction']} {_num(t['limit'])}",
                    "measured": _num(t["measured"]),
                    "met": "yes" if t["pass"] else "NO",
                }
                for key, t in data["targets"].items()
            ]
            tables.append({"title": "Targets (make bench)", "note": machine(data), "rows": rows})
        if (data := load("peers.json")) is not None:
            rows = []
            for n, r in data["results"].items():
                ir, uv = r["irsim"], r["uvnav"]
                rows.append(
                    {
                        "obstacles": n,
                        "ir-sim steps/s": _num(ir.get("steps_per_s")),
                        "uvnav steps/s": _num(uv.get("steps_per_s")),
                        "uvnav / ir-sim": _num(r.get("ratio_uvnav_over_irsim")) + "×",
                    }
                )
            tables.append(
                {"title": "World stepping: uvnav vs ir-sim", "note": machine(data), "rows": rows}
            )
        if (data := load("peers_navground.json")) is not None and data.get("available", True):
            rows = []
            for scene, r in data["scenes"].items():
                for run, v in r["runs"].items():
                    dec = v.get("decision_us_median", v.get("decision_us_estimate"))
                    outcome = v.get("status") or ("reached" if v.get("reached_goal") else "no")
                    gap = v.get("min_clearance_m", v.get("min_gap_m"))
                    rows.append(
                        {
                            "scene": scene,
                            "simulator:law": run,
                            "steps": v["steps"],
                            "µs/step": _num(v["us_per_step"]),
                            "decision µs": _num(dec),
                            "outcome": f"{outcome}, min gap {_num(gap, 2)} m",
                        }
                    )
            tables.append(
                {
                    "title": "Crowd crossings: uvnav vs navground",
                    "note": machine(data) + "; navground's decision cost is estimated as µs/step "
                    "with the behaviour minus µs/step with Dummy, uvnav's is its own median",
                    "rows": rows,
                }
            )
    except (KeyError, TypeError) as exc:
        raise ValueError(f"{bench_dir}: benchmark file without the expected field {exc}") from None
    for t in tables:
        t["columns"] = list(t["rows"][0]) if t["rows"] else []
    return tables


def _copy_figures(figures: Sequence[FigureSpec], out_dir: Path) -> list[dict[str, str]]:
    out: list[dict[str, str]] = []
    used: set[str] = set()
    for i, spec in enumerate(figures):
        src, caption = (Path(spec[0]), spec[1]) if isinstance(spec, tuple) else (Path(spec), "")
        if not src.is_file():
            raise FileNotFoundError(f"figure {src} does not exist")
        name = src.name
        if name in used:
            name = f"{i:02d}-{name}"
        used.add(name)
        dest = out_dir / name
        if src.resolve() != dest.resolve():
            shutil.copyfile(src, dest)
        out.append(
            {"src": name, "caption": caption or src.stem.replace("-", " ").replace("_", " ")}
        )
    return out


def _relative_file(src: Path, out_dir: Path, folder: str) -> str:
    """Relative POSIX link from ``out_dir/index.html`` to ``src``; a file outside ``out_dir`` is
    first copied to ``out_dir/folder/`` (a different file of the same name gets a numbered name)."""
    src = Path(src)
    if not src.is_file():
        raise FileNotFoundError(f"figure {src} does not exist")
    root = out_dir.resolve()
    real = src.resolve()
    if real.is_relative_to(root):
        return real.relative_to(root).as_posix()
    dest_dir = out_dir / folder
    dest_dir.mkdir(parents=True, exist_ok=True)
    dest = dest_dir / src.name
    k = 1
    while dest.exists() and dest.read_bytes() != src.read_bytes():
        dest = dest_dir / f"{src.stem}-{k}{src.suffix}"
        k += 1
    if not dest.exists():
        shutil.copyfile(src, dest)
    return dest.resolve().relative_to(root).as_posix()


def section_rows(sections: Sequence[ChapterSection], out_dir: Path) -> list[dict[str, Any]]:
    """Template rows of the chapter sections, their files linked relatively to ``out_dir``."""
    out: list[dict[str, Any]] = []
    for sec in sections:
        rows = [{**r, "verdict": row_verdict(r)} for r in sec.rows]
        columns = list(_TABLE_ORDER) if rows else []
        for r in rows:
            columns += [k for k in r if k not in columns]
        out.append(
            {
                "key": sec.key,
                "title": sec.title,
                "intro": sec.intro,
                "rows": rows,
                "verdicts": count_text(counts(sec.rows)),
                "columns": columns,
                "figures": [
                    {"src": _relative_file(f.path, out_dir, sec.key), "caption": f.caption}
                    for f in sec.figures
                ],
                "links": [
                    {"href": _relative_file(f.path, out_dir, sec.key), "caption": f.caption}
                    for f in sec.links
                ],
                "notes": list(sec.notes),
            }
        )
    return out


def write_report(
    db_path: Path,
    out_dir: Path,
    *,
    figures: Sequence[FigureSpec] | None = None,
    sections: Sequence[ChapterSection] | None = None,
    table: Sequence[Mapping[str, Any]] | None = None,
    title: str = "uvnav results",
    summary_figure: bool = True,
    animations: int = 12,
    bench_dir: Path | None = None,
) -> Path:
    """Render the HTML report of a results database.

    Args:
        db_path: SQLite results database (must exist).
        out_dir: output folder (created); receives ``index.html`` and the PNG figures.
        figures: PNG files to include, optionally as ``(path, caption)`` pairs; they are copied into
            ``out_dir`` (a file already there is used in place).
        sections: chapter sections (:mod:`uvnav.experiments.sections`), shown after the table in
            this order, each with its rows, figures and links.
        table: rows of the "thesis reported vs uvnav measured" table, dicts with keys ``quantity``,
            ``thesis``, ``measured``, ``note`` (further keys become further columns).
        title: page title.
        summary_figure: add a campaign summary figure (outcomes, clearance and detour distributions)
            of all episodes, written as ``out_dir/campaign-summary.png``.
        animations: at most this many animated trajectory views (plotly, one per recorded
            episode; ``plotly.min.js`` is written next to ``index.html``); 0 for none.
        bench_dir: a folder of benchmark JSON files (``make bench`` and ``benchmarks/peers/``
            write ``benchmarks/results/``); their targets and peer comparisons become a section.

    Returns:
        The path of ``index.html``.

    Raises:
        FileNotFoundError: ``db_path`` or a figure does not exist.
    """
    import jinja2

    from uvnav import __version__
    from uvnav.bench.store import ResultsStore
    from uvnav.experiments.regime import SMALL_SAMPLE

    db_path = Path(db_path)
    if not db_path.is_file():
        raise FileNotFoundError(f"results database {db_path} does not exist")
    for spec in figures or []:
        src = Path(spec[0] if isinstance(spec, tuple) else spec)
        if not src.is_file():
            raise FileNotFoundError(f"figure {src} does not exist")
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    with ResultsStore(db_path, readonly=True) as store:  # a report never writes its input
        df = store.episodes_frame()
        campaigns = store.campaigns()
    counts = df["campaign_id"].value_counts().to_dict() if not df.empty else {}
    campaign_rows = [
        {**c, "n": int(counts.get(c["id"], 0)), "config": _short_json(c["config"])}
        for c in campaigns
    ]

    figure_specs: list[FigureSpec] = list(figures or [])
    if summary_figure and not df.empty:
        from uvnav.viz.figures import plot_campaign_summary

        summary_png = plot_campaign_summary(
            df, out_dir / "campaign-summary.png", title="All episodes in the database"
        )
        figure_specs.append(
            (
                summary_png,
                "Outcomes, minimum clearance and detour ratio per "
                "controller over all episodes in the database.",
            )
        )
    figure_rows = _copy_figures(figure_specs, out_dir)
    chapter_rows = section_rows(list(sections or []), out_dir)

    in_sections = [dict(r) for sec in sections or [] for r in sec.rows]
    # a row a section shows is not repeated in the global table (which keeps the others)
    table_rows = [
        {**r, "verdict": row_verdict(r)} for r in (table or []) if dict(r) not in in_sections
    ]
    table_columns = list(_TABLE_ORDER) if table_rows else []
    for r in table_rows:
        table_columns += [k for k in r if k not in table_columns]

    from uvnav.experiments.regime import CAMPAIGN as REGIME_CAMPAIGN

    # the regime map's cells (36 families x every law) are tabulated, with intervals, on the
    # first screen: not again here
    summaries = [c for c in campaign_summaries(df) if c["campaign"] != REGIME_CAMPAIGN]
    errors_df = df[df["status"] == "error"] if not df.empty else df
    errors = [
        {
            "campaign": r.campaign,
            "scenario": r.scenario,
            "controller": r.controller,
            "seed": r.seed,
            "error": r.error,
        }
        for r in errors_df.head(_MAX_ERRORS).itertuples()
    ]

    from uvnav.viz.interactive import ANIMATIONS_GLOBAL, PLOTLY_JS, write_plotly_js

    anim_sections: list[dict[str, str]] = []
    if animations > 0:
        from uvnav.viz.interactive import animation_sections

        anim_sections = animation_sections(db_path, limit=animations, out_dir=out_dir)
    from uvnav.viz.regime import SMALL_MARK, decision_view

    decision = decision_view(db_path)
    # the one screen `uvnav run` ends with (and thesis-vs-uvnav.md opens with) opens the page
    screen = (
        summary_lines(sections, report=None, table=None, laws=decision["law_lines"])
        if sections
        else []
    )
    if anim_sections:  # loaded by the page only when an animation is asked for
        write_plotly_js(out_dir)

    template_text = files("uvnav.viz").joinpath("templates/report.html").read_text(encoding="utf-8")
    env = jinja2.Environment(
        autoescape=True, undefined=jinja2.StrictUndefined, trim_blocks=True, lstrip_blocks=True
    )
    html = env.from_string(template_text).render(
        title=title,
        generated=datetime.now(UTC).strftime("%Y-%m-%d %H:%M UTC"),
        version=f"{__version__} (Python {sys.version.split()[0]})",
        db_name=db_path.name,
        n_episodes=len(df),
        campaigns=campaign_rows,
        simulation_note=SIMULATION_NOTE,
        table=table_rows,
        table_columns=table_columns,
        summaries=summaries,
        benchmarks=benchmark_tables(Path(bench_dir)) if bench_dir is not None else [],
        text_columns=_TEXT_COLUMNS,
        figures=figure_rows,
        sections=chapter_rows,
        errors=errors,
        animations=anim_sections,
        animations_global=ANIMATIONS_GLOBAL,
        decision=decision,
        screen=screen,
        small_mark=SMALL_MARK,
        small_sample=SMALL_SAMPLE,
        plotly_js=PLOTLY_JS,
        errors_truncated=max(0, len(errors_df) - _MAX_ERRORS),
    )
    index = out_dir / "index.html"
    index.write_text(html, encoding="utf-8")
    return index


def _short_json(config: Any, limit: int = 300) -> str:
    import json

    text = json.dumps(config, sort_keys=True)
    return text if len(text) <= limit else text[: limit - 1] + "…"
