"""``uvnav ch4``: the Chapter-4 underwater scenes (planar UUV, shape-changing obstacles, sonar).

Thin: parses, calls :mod:`uvnav.scenarios.uuv2d`, :mod:`uvnav.sim.episode_uuv2d`,
:mod:`uvnav.bench.reproduce_ch4` and :mod:`uvnav.viz.figures_ch4`, prints.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from uvnav.cli.app import _console, _text
from uvnav.cli.errors import uvnav_typer

ch4_app = uvnav_typer(
    help="Chapter 4: a UUV among shape-changing obstacles, sonar only, AMAPS grid.",
)


@ch4_app.command("run")
def run(
    full: Annotated[
        bool, typer.Option("--full", help="Thesis-size runs (200-seed campaign).")
    ] = False,
    workers: Annotated[int, typer.Option(min=1, help="Worker processes.")] = 2,
    results: Annotated[Path, typer.Option(help="Directory of the results.")] = Path("results"),
    report: Annotated[Path, typer.Option(help="Directory of the figures (in REPORT/ch4).")] = Path(
        "report"
    ),
) -> None:
    """Chapter-4 reproduction (thesis scenes, random campaign, noise sweep) with figures."""
    from rich.table import Table

    from uvnav.bench.reproduce_ch4 import reproduce_ch4
    from uvnav.viz.figures_ch4 import render_ch4

    summary = reproduce_ch4(results, report, full=full, workers=workers, render=render_ch4)
    table = Table(title="Chapter 4: thesis reported vs uvnav measured")
    for col in ("quantity", "thesis", "measured", "note"):
        table.add_column(col)
    for row in summary.table:
        table.add_row(*(_text(str(row[c])) for c in ("quantity", "thesis", "measured", "note")))
    _console().print(table)
    for f in summary.failures:
        typer.echo(f"failure: {f}")
    typer.echo(f"wrote {summary.rows_path}, {summary.summary_path}")
    typer.echo(f"wrote {len(summary.figures)} figure file(s) in {report / 'ch4'}")
