"""``uvnav report DB``: the HTML report of a results database (the database is only read).

The sections come from :func:`uvnav.experiments.report_sections`; the report writer
(:mod:`uvnav.viz.report`) is imported on demand, so a missing plotting extra is a one-line error.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from uvnav.cli.common import optional as _optional
from uvnav.cli.errors import CliError


def report_cmd(
    db: Annotated[
        Path, typer.Argument(help="Results database (SQLite) written by uvnav run / bench.")
    ],
    out: Annotated[Path, typer.Option("--out", help="Output directory.")] = Path("report"),
    bench: Annotated[
        Path | None,
        typer.Option(
            "--bench",
            help="Folder of benchmark JSON (make bench, benchmarks/peers/) to add as a section.",
        ),
    ] = None,
) -> None:
    """Turn a results database into the HTML report (the database is only read)."""
    if not db.exists():
        raise CliError(f"{db}: no such database file")
    if not db.is_file():
        raise CliError(f"{db}: not a file")
    if bench is not None and not bench.is_dir():
        raise CliError(f"{bench}: --bench must be a folder of benchmark JSON files")
    from uvnav.bench.store import NotAStoreError, ResultsStore

    try:  # before anything is written: a foreign or empty file is refused as it is
        ResultsStore(db, readonly=True).close()
    except NotAStoreError as exc:
        raise CliError(str(exc)) from None
    write_report = _optional("uvnav.viz.report", "write_report", "the report (uvnav report)")
    from uvnav.experiments import report_sections

    sections = report_sections(db)  # saved by the experiments' runs, or rebuilt from stored rows
    try:
        path = write_report(
            db,
            out,
            bench_dir=bench,
            sections=sections,
            table=[r for s in sections for r in s.rows],
        )
    except ValueError as exc:
        raise CliError(str(exc)) from None
    typer.echo(f"wrote {path}")
