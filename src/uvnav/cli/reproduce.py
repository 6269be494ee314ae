"""``uvnav run``, ``uvnav reproduce NAME`` and ``uvnav forget``: every registered experiment's
reproduction, one experiment's, and the removal of a stored campaign a reproduction refused to mix
with (thin: parse, call the library, print).

``uvnav run`` runs :func:`uvnav.experiments.run_all` (every registered experiment in report order,
the report, the whole "thesis reported vs uvnav measured" table in ``RESULTS/thesis-vs-uvnav.md``).

``uvnav reproduce NAME`` runs :func:`uvnav.experiments.run_experiment` into the results store
(``--results``), draws the experiment's figures (the viz renderers are injected, as ``uvnav run``
does) and rewrites the report (``--report``) with its section beside the sections the earlier runs
saved (``RESULTS/sections``).  ``uvnav reproduce --list`` lists the experiments (the built-ins and
the plug-ins of the ``uvnav.experiments`` entry-point group); ``uvnav reproduce all`` is
``uvnav run``.  ``uvnav reproduce NAME --plan`` prints what the run would run, per campaign
(:func:`uvnav.experiments.plan_summary`), and how much of it the results database holds; it runs
nothing and writes nothing (``--json``: one JSON object).

Chapter 6's pipeline with every option (noise, threads, head, DAgger rounds, ...) stays
``uvnav drive reproduce``; ``uvnav reproduce ch6`` runs the same function at ``uvnav run``'s size
(its stages in ``RESULTS/stages``, ``ch6.json`` in ``RESULTS/ch6-quick``, or ``RESULTS/ch6`` with
``--full``).  ``--fresh`` remakes the stages an experiment reaches.
"""

from __future__ import annotations

import json
import textwrap
from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any

import typer

from uvnav.cli.checks import pool_workers
from uvnav.cli.common import compact_table, console, fmt, optional, text
from uvnav.cli.errors import CliError
from uvnav.validation import one_line

_COLUMNS = ("quantity", "thesis", "measured", "note")
_TITLE = "uvnav — reproduction of the thesis's experiments"


def _context(results: Path, report: Path, **kw: Any) -> Any:
    """The experiments' context with the viz renderers injected."""
    context = optional("uvnav.experiments", "ExperimentContext", "the experiments")
    render = optional("uvnav.viz.reproduction", "render_reproduction", "the report renderer")
    renderers = optional("uvnav.viz.reproduction", "chapter_renderers", "the chapter figures")
    return context(results, report, renderers=renderers(), render=render, progress=True, **kw)


def _user_errors() -> tuple[type[Exception], ...]:
    from uvnav.bench.store import StaleCampaignError
    from uvnav.experiments import ExperimentError

    return ExperimentError, StaleCampaignError


#: the options ``uvnav run`` and ``uvnav reproduce`` share
FullOption = Annotated[
    bool, typer.Option("--full", help="Thesis-size runs instead of the quick mode.")
]
WorkersOption = Annotated[int, typer.Option(min=1, callback=pool_workers, help="Worker processes.")]
ResultsOption = Annotated[Path, typer.Option(help="Directory of the results database.")]
ReportOption = Annotated[Path, typer.Option(help="Directory of the HTML report.")]
FreshOption = Annotated[
    bool,
    typer.Option(
        "--fresh",
        help="Remake the stages (trained networks, planned tours, data sets), even those made "
        "by other code; stored episodes are kept.",
    ),
]


def run_cmd(
    full: FullOption = False,
    workers: WorkersOption = 2,
    results: ResultsOption = Path("results"),
    report: ReportOption = Path("report"),
    fresh: FreshOption = False,
) -> None:
    """Reproduce the thesis's experiments: results database, report, and the comparison table."""
    run_all = optional("uvnav.experiments", "run_all", "the reproduction job (uvnav run)")
    ctx = _context(results, report, full=full, workers=workers, fresh=fresh)
    try:
        summary = run_all(ctx)
    except _user_errors() as exc:
        raise CliError(str(exc)) from None
    rows = list(getattr(summary, "table", []) or [])
    sections = list(getattr(summary, "sections", []) or [])
    if getattr(summary, "report_path", None) is None and sections:  # no run wrote the page
        summary.report_path = _write_report(results / "uvnav.sqlite", report, sections)
    report_path = getattr(summary, "report_path", None) or report / "index.html"
    table_path = results / TABLE_NAME
    screen = run_summary_lines(sections, report_path, table_path, results / "uvnav.sqlite")
    write_comparison_table(rows, results, sections, screen)
    for line in screen:
        typer.echo(line)
    typer.echo(f"wrote {table_path} (the whole table: {len(rows)} rows)")
    written: list[Path] = []
    for attr in ("db_path", "report_path"):
        value = getattr(summary, attr, None)
        if isinstance(value, Path):
            written.append(value)
    for default in (results / "uvnav.sqlite", report / "index.html"):
        if default.exists() and default not in written:
            written.append(default)
    for path in written:
        typer.echo(f"wrote {path}")
    figures = [f for f in getattr(summary, "figures", None) or [] if isinstance(f, Path)]
    if figures:
        folders = sorted({str(f.parent) for f in figures})
        typer.echo(f"wrote {len(figures)} figure file(s) in {', '.join(folders)}")


def run_summary_lines(
    sections: list[Any], report_path: Path, table_path: Path, db_path: Path
) -> list[str]:
    """The one screen ``uvnav run`` ends with (:func:`uvnav.experiments.verdict.summary_lines`):
    the report and the table, per experiment its verdicts and headline row, and "which law,
    where" from the stored regime map."""
    from uvnav.experiments.verdict import summary_lines

    return summary_lines(
        sections, report=str(report_path), table=str(table_path), laws=_law_lines(db_path)
    )


def _law_lines(db_path: Path) -> list[str]:
    """ "Which law, where" from the regime map stored in ``db_path`` (none when it is not)."""
    from uvnav.bench.store import ResultsStore
    from uvnav.experiments.regime import cell_stats, law_lines

    if not db_path.is_file():
        return []
    with ResultsStore(db_path, readonly=True) as store:
        return law_lines(cell_stats(store))


#: the whole "thesis reported vs uvnav measured" table, in the results folder
TABLE_NAME = "thesis-vs-uvnav.md"


def write_comparison_table(
    rows: list[dict[str, Any]],
    results: Path,
    sections: Sequence[Any] = (),
    screen: Sequence[str] = (),
) -> Path:
    """The whole "thesis reported vs uvnav measured" table as Markdown in ``results``: the one
    screen ``uvnav run`` prints (``screen``, as a text block), the per-experiment verdict counts
    and the rule, then every row with its verdict
    (:func:`uvnav.experiments.verdict.table_lines`)."""
    from uvnav.experiments.verdict import table_lines

    path = results / TABLE_NAME
    path.parent.mkdir(parents=True, exist_ok=True)
    lines = table_lines(list(sections), rows)
    if screen:
        lines[1:1] = ["", "```text", *screen, "```"]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def experiment_lines(known: dict[str, Any], width: int = 80) -> list[str]:
    """``uvnav reproduce --list``: a header, then per experiment its name, whether it runs random
    seeds and its title, and under it what each declared size runs (``quick``, ``full``), each
    line at most ``width`` characters."""
    w = max([len("name"), *(len(n) for n in known)]) + 2
    lines = [f"{'name':<{w}}seeded  title"]
    for name, exp in known.items():
        found = [f"{name:<{w}}{'yes' if exp.seeded else 'no':<8}{one_line(str(exp.title))}"]
        for size, declared in (getattr(exp, "sizes", None) or {}).items():
            runs = one_line(str(declared.runs))
            found.append(f"{'':<{w + 2}}{size + ':':<7}{runs}")
        lines += [line if len(line) <= width else line[: width - 1] + "…" for line in found]
    return lines


def reproduce_cmd(
    name: Annotated[
        str | None,
        typer.Argument(
            help="The experiment to run (see --list: ch2 ... ch7, beyond, crowds, regime and any "
            "plug-in), or all (= uvnav run)."
        ),
    ] = None,
    list_: Annotated[
        bool,
        typer.Option("--list", help="List the experiments (name, seeded, title, sizes) and exit."),
    ] = False,
    full: FullOption = False,
    workers: WorkersOption = 2,
    results: ResultsOption = Path("results"),
    report: ReportOption = Path("report"),
    seeds: Annotated[
        int | None,
        typer.Option(
            min=1,
            help="Random scenes to run (seeded experiments, see --list; crowds: CrowdNav test "
            "cases per scene; regime: seeds per regime; default: the experiment's quick or full "
            "size).",
        ),
    ] = None,
    start_seed: Annotated[
        int,
        typer.Option(
            "--start-seed",
            min=0,
            help="First random scene (seeded experiments): seeds S .. S+N-1.",
        ),
    ] = 0,
    fresh: FreshOption = False,
    plan: Annotated[
        bool,
        typer.Option(
            "--plan",
            help="Print what the run would run (per campaign: jobs, laws, scene families, "
            "how many are stored in the results database; the stages) and exit; runs nothing.",
        ),
    ] = False,
    json_: Annotated[
        bool,
        typer.Option(
            "--json",
            help="Print one JSON object (the plan; with --plan only) instead of the table.",
        ),
    ] = False,
) -> None:
    """Reproduce one experiment into the results store and its report section.

    Adds to the store: stored episodes are skipped, no other run's episodes are deleted or
    replaced; a campaign stored by other code is refused (remove it with 'uvnav forget'), and so
    is a stage made by other code (remake it with --fresh).
    """
    if json_ and not plan:
        raise CliError("reproduce --json: only with --plan")
    if plan:
        _print_plan(name, results, full=full, seeds=seeds, start_seed=start_seed, as_json=json_)
        return
    if list_:
        if name is not None:
            raise CliError(f"reproduce --list takes no experiment name (got {name!r})")
        experiments = optional("uvnav.experiments", "experiments", "the experiments")
        try:
            known = experiments()
        except _user_errors() as exc:
            raise CliError(str(exc)) from None
        for line in experiment_lines(known):
            typer.echo(line)
        return
    if name is None:
        raise CliError("reproduce: name an experiment ('uvnav reproduce --list' shows them) or all")
    name = name.strip().lower()
    if name == "all":
        if seeds is not None or start_seed:
            raise CliError(
                "reproduce all: --seeds/--start-seed apply to one seeded experiment "
                "(see 'uvnav reproduce --list')"
            )
        run_cmd(full=full, workers=workers, results=results, report=report, fresh=fresh)
        return
    run_experiment = optional("uvnav.experiments", "run_experiment", "the reproduction job")
    ctx = _context(
        results, report, full=full, workers=workers, seeds=seeds, start_seed=start_seed, fresh=fresh
    )
    try:
        out = run_experiment(name, ctx)
    except _user_errors() as exc:
        raise CliError(str(exc)) from None
    report_path = out.report_path
    if report_path is None:
        from uvnav.experiments import saved_sections

        report_path = _write_report(out.db_path, report, saved_sections(results))
    _print_rows(out.sections)
    if name == "regime":
        _print_regime_leaders(out.db_path)
    for f in out.failures[:20]:
        typer.echo(f"failure: {f}")
    if len(out.failures) > 20:
        typer.echo(f"... and {len(out.failures) - 20} more failure(s) (see the report)")
    n_files = sum(len(s.figures) + len(s.links) for s in out.sections)
    typer.echo(f"wrote {out.db_path}")
    typer.echo(f"wrote {report_path} ({n_files} file(s) in the {name} section)")


def _print_plan(
    name: str | None, results: Path, *, full: bool, seeds: int | None, start_seed: int,
    as_json: bool,
) -> None:  # fmt: skip
    """``--plan``: the experiment's plan as text (80 columns) or one JSON object."""
    if name is None or name.strip().lower() == "all":
        raise CliError("reproduce --plan: name one experiment ('uvnav reproduce --list')")
    from uvnav.bench.store import NotAStoreError

    context = optional("uvnav.experiments", "ExperimentContext", "the experiments")
    plan_summary = optional("uvnav.experiments", "plan_summary", "the experiments' plans")
    ctx = context(results, Path("report"), full=full, seeds=seeds, start_seed=start_seed)
    refused: tuple[type[Exception], ...] = (*_user_errors(), NotAStoreError)
    try:
        summary = plan_summary(name.strip().lower(), ctx)
    except refused as exc:
        raise CliError(str(exc)) from None
    if as_json:
        typer.echo(json.dumps(summary, indent=1))
        return
    for line in plan_lines(summary):
        typer.echo(line)


def _wrapped(label: str, items: Sequence[str], width: int) -> list[str]:
    """``label: a, b, c`` wrapped at ``width``, continued lines indented."""
    text = f"{label}: {', '.join(items)}"
    return textwrap.wrap(
        text, width, initial_indent="  ", subsequent_indent="    ", break_on_hyphens=False
    )


def plan_lines(summary: dict[str, Any], width: int = 80) -> list[str]:
    """``uvnav reproduce NAME --plan`` as text: the experiment and its size, the database and
    how much of the plan it holds, per campaign its jobs and stored jobs, laws and scene
    families, then the stages; every line at most ``width`` characters."""
    head = f"{summary['experiment']} ({summary['size']}): {one_line(summary['runs'])}"
    lines = textwrap.wrap(head, width, subsequent_indent="  ")
    camps = summary["campaigns"]
    jobs, stored = sum(c["jobs"] for c in camps), sum(c["stored"] for c in camps)
    db = summary["database"]
    held = f"{stored} of {jobs} jobs stored" if summary["database_exists"] else "none yet"
    lines += textwrap.wrap(f"database {db}: {held}", width, subsequent_indent="  ")
    if not summary["planned"]:
        lines.append("it declares no plan: 'uvnav reproduce' runs it as a whole")
    w = max([len("campaign"), *(len(c["name"]) for c in camps)]) + 2
    if camps:
        lines.append(f"{'campaign':<{w}}{'jobs':>8}{'stored':>8}")
    elif summary["planned"]:
        lines.append("no campaign: it runs stages only")
    for c in camps:
        lines.append(f"{c['name']:<{w}}{c['jobs']:>8}{c['stored']:>8}")
        if c["stale"]:
            lines += _wrapped("stale", ["stored by other code; a run refuses it"], width)
        lines += _wrapped("laws", c["laws"], width)
        lines += _wrapped("scenes", c["families"], width)
    if summary["stages"]:
        lines += textwrap.wrap(
            f"stages: {', '.join(summary['stages'])}", width, subsequent_indent="  "
        )
    return [line if len(line) <= width else line[: width - 1] + "…" for line in lines]


def _print_rows(sections: list[Any]) -> None:
    """Each section's rows of the table "thesis reported vs uvnav measured"."""
    from rich.table import Table

    for section in sections:
        if not section.rows:
            continue
        table = Table(title=f"{section.title}: thesis reported vs uvnav measured")
        for col in _COLUMNS:
            table.add_column(col, justify="right" if col in ("thesis", "measured") else "left")
        for row in section.rows:
            table.add_row(*(text(fmt(row.get(col))) for col in _COLUMNS))
        console().print(table)


def _print_regime_leaders(db: Path) -> None:
    """The regime map on one screen: per regime the law that succeeds most often."""
    from uvnav.bench.store import ResultsStore
    from uvnav.experiments.regime import cell_stats, leaders

    with ResultsStore(db, readonly=True) as store:
        rows = leaders(cell_stats(store))
    table = compact_table(
        "Where each law wins: the best success per regime (95 % interval)",
        "tied: other laws whose interval overlaps the best one's; "
        "the report gives each regime's paragraph and heat maps",
    )
    table.add_column("humans × speed, robot, sensing", overflow="fold", ratio=1)
    table.add_column("best law", overflow="fold")
    table.add_column("success", no_wrap=True, justify="right")
    table.add_column("robot-\ndriven", justify="right")
    table.add_column("tied", justify="right")
    for r in rows:
        cells = (r["regime"], r["best"], r["success"], r["robot_driven"], r["tied"])
        table.add_row(*(text(c) for c in cells))
    console().print(table)


def _write_report(db: Path, report: Path, sections: list[Any]) -> Path:
    """The report page from ``sections`` (the database is created empty if the experiments
    stored no episodes, as Chapters 6 and 7)."""
    from uvnav.bench.store import ResultsStore

    if not db.exists():
        ResultsStore(db).close()
    write_report = optional("uvnav.viz.report", "write_report", "the report")
    path: Path = write_report(
        db,
        report,
        sections=sections,
        table=[r for s in sections for r in s.rows],
        title=_TITLE,
        summary_figure=False,
    )
    return path


def forget_cmd(
    db: Annotated[Path, typer.Argument(help="Results database (SQLite).")],
    campaigns: Annotated[list[str], typer.Argument(help="Campaign name(s) to remove.")],
) -> None:
    """Remove stored campaigns (their episodes and trajectories) from a results database.

    The only command that deletes results: a reproduction never does; when it cannot resume a
    campaign it names it, and this removes it.
    """
    from uvnav.bench.store import NotAStoreError, ResultsStore, StoreInUseError

    if not db.is_file():
        raise CliError(f"{db}: no such database file")
    try:
        ResultsStore(db, readonly=True).close()
    except NotAStoreError as exc:
        raise CliError(str(exc)) from None
    with ResultsStore(db) as store:
        known = {c["name"] for c in store.campaigns()}
        unknown = [c for c in campaigns if c not in known]
        if unknown:
            raise CliError(
                f"{db}: no campaign {', '.join(map(repr, unknown))}; stored: "
                f"{', '.join(sorted(known)) or 'none'}"
            )
        try:
            with store.writer_lease():
                for name in campaigns:
                    n = store.count(name)
                    store.delete_campaign(name)
                    typer.echo(f"removed campaign {name!r} ({n} episode(s)) from {db}")
        except StoreInUseError as exc:
            raise CliError(str(exc)) from None
