"""``uvnav simulate`` for 3D scenes (``dim: 3``, thesis Chapter 3): one episode in the 3D simulator.

The scene's own 3D law (default ``zhang2020-3d-v1``) or ``--controller`` (a 3D law:
``zhang2020-3d-v1``, ``apf3d-v1``, ``vo3d-v1``); the same metrics as the 2D command
(:data:`uvnav.sim.METRIC_NAMES`); ``--plot`` draws Fig. 3.6's two-viewpoint trajectory
(:func:`uvnav.viz.figures3d.trajectory_figure`).
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import Any

import typer

from uvnav.controllers.base import ControllerParamsError
from uvnav.controllers.base3d import make_controller3d
from uvnav.scenarios.schema3d import Scenario3D
from uvnav.sim import METRIC_NAMES, run_rng
from uvnav.sim.episode3d import run_episode3d


def simulate3d(
    sc: Scenario3D,
    controller: str | None,
    params: dict[str, Any],
    seed: int,
    *,
    json_out: bool,
    plot: Path | None,
) -> None:
    """Run and print one 3D episode (see the module docstring)."""
    cli = importlib.import_module("uvnav.cli.app")  # (uvnav.cli.app is also the Typer app's name)

    name = controller or sc.controller.name
    merged = dict(sc.controller.params) if name == sc.controller.name else {}
    merged.update(params)
    try:
        ctrl = make_controller3d(name, **merged)
    except ControllerParamsError as exc:
        raise ControllerParamsError(f"controller {name}: {exc}") from None
    figure = (
        cli._optional("uvnav.viz.figures3d", "trajectory_figure", "plotting (--plot)")
        if plot
        else None
    )
    result, traj = run_episode3d(sc.build(seed), ctrl, run_rng(seed), record=plot is not None)
    metrics = result.metrics.to_dict()
    record: dict[str, Any] = {
        "scenario": sc.name,
        "controller": name,
        "params": merged,
        "seed": seed,
        "status": result.status,
        **{k: metrics[k] for k in METRIC_NAMES},
    }
    if figure is not None and plot is not None and traj is not None:
        fig = figure(traj, f"{sc.name} | {name} | seed {seed}")
        Path(plot).parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(plot, dpi=110)
    if json_out:
        typer.echo(cli._dumps(record))
        if plot is not None:
            typer.echo(f"wrote {plot}", err=True)
        return
    from rich.table import Table

    table = Table(title=f"{sc.name} | {name} | seed {seed} | {result.status} (3D)")
    table.add_column("metric")
    table.add_column("value", justify="right")
    table.add_column("unit")
    for key in METRIC_NAMES:
        table.add_row(key, cli._fmt(metrics[key]), cli._METRIC_UNITS.get(key, ""))
    cli._console().print(table)
    if plot is not None:
        typer.echo(f"wrote {plot}")
