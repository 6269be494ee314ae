"""``uvnav ch4``: the Chapter-4 underwater scenes (planar UUV, shape-changing obstacles, sonar).

Thin: parses, calls :mod:`uvnav.scenarios.uuv2d`, :mod:`uvnav.sim.episode_uuv2d`,
:mod:`uvnav.bench.reproduce_ch4` and :mod:`uvnav.viz.figures_ch4`, prints.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from uvnav.cli.app import CliError, UvnavGroup, _console, _fmt, _text

ch4_app = typer.Typer(
    cls=UvnavGroup,
    no_args_is_help=True,
    help="Chapter 4: a UUV among shape-changing obstacles, sonar only, AMAPS grid.",
)


@ch4_app.command("scenes")
def scenes() -> None:
    """List the Chapter-4 built-in scenes and generators."""
    from uvnav.scenarios.uuv2d import UUV2D_GENERATORS, list_uuv2d_builtin, load_uuv2d_scenario

    for name in list_uuv2d_builtin():
        typer.echo(f"{name}: {load_uuv2d_scenario(name).description}")
    for gen, fn in UUV2D_GENERATORS.items():
        first = (fn.__doc__ or "seeded random scene").strip().splitlines()[0]
        typer.echo(f"{gen}:<seed>: {first}")


@ch4_app.command("simulate")
def simulate(
    scene: Annotated[str, typer.Argument(help="built-in, random-ch4[-hard]:<seed> or YAML")],
    controller: Annotated[str | None, typer.Option(help="law (default: the scene's)")] = None,
    seed: Annotated[int, typer.Option(min=0, help="episode seed")] = 0,
    as_json: Annotated[bool, typer.Option("--json", help="print the metrics as JSON")] = False,
) -> None:
    """Run one Chapter-4 episode and print its metrics."""
    from uvnav.controllers.zhang2022_uuv2d import make_uuv2d_controller
    from uvnav.scenarios.uuv2d import load_uuv2d_scenario
    from uvnav.sim.episode_uuv2d import run_uuv2d_episode

    sc = load_uuv2d_scenario(scene)
    name = controller or sc.controller.name
    try:
        law = make_uuv2d_controller(name, **(sc.controller.params if controller is None else {}))
    except KeyError as exc:
        raise CliError(str(exc.args[0])) from None
    res = run_uuv2d_episode(sc.to_setup(), law, np.random.default_rng(seed), record=False)
    out = {"status": res.status, "entered_forbidden": res.entered_forbidden}
    out.update(res.metrics.to_dict())
    if as_json:
        typer.echo(json.dumps(out))
        return
    for k, v in out.items():
        typer.echo(f"{k}: {_fmt(v)}")


@ch4_app.command("run")
def run(
    full: Annotated[bool, typer.Option("--full", help="200-seed campaign")] = False,
    workers: Annotated[int, typer.Option(min=1, help="worker processes")] = 2,
    results: Annotated[Path, typer.Option(help="results directory")] = Path("results"),
    report: Annotated[Path, typer.Option(help="figures go to REPORT/ch4")] = Path("report"),
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
