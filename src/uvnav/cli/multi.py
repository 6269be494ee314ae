"""``uvnav multi``: run a multi-robot scenario (issue 9); thin — the work is in
:mod:`uvnav.scenarios.multi` and :mod:`uvnav.sim.multi`."""

from __future__ import annotations

import json
from typing import Annotated

import typer

multi_app = typer.Typer(
    help="Multi-robot scenarios: N robots, each sensing the others (antipodal:N, crossing:N, "
    "thesis-ch2-multi:N or a YAML file).",
    no_args_is_help=True,
)


@multi_app.command("run")
def run(
    scenario: Annotated[
        str, typer.Argument(help="antipodal:N, crossing:N, thesis-ch2-multi:N or a YAML file.")
    ],
    controller: Annotated[
        str | None,
        typer.Option("--controller", "-c", help="Law for every robot (default: the scenario's)."),
    ] = None,
    param: Annotated[
        list[str] | None,
        typer.Option("--param", "-p", help="Controller parameter KEY=VALUE (repeatable)."),
    ] = None,
    seed: Annotated[int, typer.Option("--seed", help="Episode seed.")] = 0,
    json_out: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Run one episode; print the group metrics and each robot's outcome."""
    from uvnav.cli.app import parse_params
    from uvnav.scenarios.multi import build_multi, load_multi_scenario
    from uvnav.sim.multi import run_multi
    from uvnav.sim.seeding import run_rng

    sc = load_multi_scenario(scenario)
    params = parse_params(param)
    if params and controller is None:
        controller = sc.controller.name
        params = {**sc.controller.params, **params}
    setup = build_multi(sc, seed, controller=controller, params=params)
    res = run_multi(setup, run_rng(seed), record=False)
    robots = [
        {"name": r.name, "status": s, **m.to_dict()}
        for r, s, m in zip(setup.robots, res.statuses, res.robots, strict=True)
    ]
    data = {"scenario": sc.name, "seed": seed, "group": res.group.to_dict(), "robots": robots}
    if json_out:
        typer.echo(json.dumps(data))
        return
    g = res.group
    typer.echo(
        f"{sc.name}: {g.arrived}/{len(res.robots)} arrived, {g.robot_collisions} robot-robot "
        f"collisions, {g.obstacle_collisions} obstacle collisions, {g.deadlocks} deadlocked, "
        f"makespan {g.makespan if g.makespan is not None else 'n/a'} s"
    )
    for row in robots:
        t = row["time_to_goal"]
        typer.echo(
            f"  {row['name']:>12}  {row['status']:<9}  path {row['path_length']:.2f} m"
            + (f"  arrived {t:.1f} s" if t is not None else "")
        )
