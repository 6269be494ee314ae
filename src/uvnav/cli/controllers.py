"""``uvnav controllers``: list the registered navigation laws and show one's parameters.

Thin Typer commands over :mod:`uvnav.controllers`; an unknown law or vehicle is a one-line
``error:`` and exit status 2 (the CLI's one error path, :mod:`uvnav.cli.errors`).
"""

from __future__ import annotations

from typing import Annotated, Any

import typer

from uvnav.cli.common import console as _console
from uvnav.cli.common import dumps as _dumps
from uvnav.cli.common import fmt as _fmt
from uvnav.cli.common import text as _text
from uvnav.cli.errors import CliError, uvnav_typer
from uvnav.controllers import ControllerInfo, available_controllers, controller_info
from uvnav.controllers.describe import param_fields, plain_doc, plain_type
from uvnav.dynamics.vehicles import vehicle_names

controllers_app = uvnav_typer(help="Registered navigation laws.")

#: the widest a parameter's description runs before it wraps [columns]
DESCRIPTION_WIDTH = 56


def _param_rows(info: ControllerInfo) -> list[dict[str, Any]]:
    rows = []
    for f in param_fields(info.params_type):
        ann = f.annotation
        type_name = ann if isinstance(ann, str) else getattr(ann, "__name__", str(ann))
        rows.append(
            {
                "name": f.name,
                "type": plain_type(type_name),
                "default": f.default,
                "doc": plain_doc(f.doc),
            }
        )
    return rows


@controllers_app.command("list")
def controllers_list(
    json_out: Annotated[
        bool, typer.Option("--json", help="Print one JSON array instead of the table.")
    ] = False,
    vehicle: Annotated[
        str | None,
        typer.Option(
            "--vehicle",
            help="Only one vehicle's laws: unicycle (Ch. 2), vehicle3d (Ch. 3/5), uuv2d (Ch. 4).",
        ),
    ] = None,
) -> None:
    """List the registered controllers of every vehicle (or of one)."""
    if vehicle is not None and vehicle not in vehicle_names():
        known = ", ".join(vehicle_names())
        raise CliError(f"--vehicle: unknown vehicle {vehicle!r}; known: {known}")
    infos = available_controllers(vehicle)
    rows = [
        {
            "name": name,
            "vehicle": info.vehicle,
            "sensing": info.sensing,
            "summary": info.summary,
            "reference": info.reference,
            "requires_slower_obstacles": info.requires_slower_obstacles,
        }
        for name, info in infos.items()
    ]
    if json_out:
        typer.echo(_dumps(rows))
        return
    con = _console()
    if con.width < WIDE:
        for line in compact_lines(rows, con.width):
            con.print(_text(line), soft_wrap=True)
        return
    from rich.table import Table

    table = Table(title="controllers")
    table.add_column("name", no_wrap=True)
    table.add_column("vehicle", no_wrap=True)
    table.add_column("sensing", no_wrap=True)
    table.add_column("summary")
    table.add_column("slower obstacles")
    for row in rows:
        table.add_row(
            _text(row["name"]),
            _text(row["vehicle"]),
            _text(row["sensing"]),
            _text(row["summary"]),
            "required" if row["requires_slower_obstacles"] else "",
        )
    con.print(table)


#: a terminal at least this wide [columns] gets the table; a narrower one the compact listing
WIDE = 120


def compact_lines(rows: list[dict[str, Any]], width: int) -> list[str]:
    """``controllers list`` for a narrow terminal: per law one line of name, vehicle and
    sensing (``*``: requires obstacles slower than the robot), its summary wrapped below it,
    indented, every line at most ``width`` characters."""
    import textwrap

    w = max([len(r["name"]) for r in rows] or [4]) + 2
    lines = [f"{'name':<{w}}{'vehicle':<11}sensing", ""]
    for r in rows:
        star = "  *" if r["requires_slower_obstacles"] else ""
        lines.append(f"{r['name']:<{w}}{r['vehicle']:<11}{r['sensing']}{star}"[:width])
        lines += textwrap.wrap(str(r["summary"]), width=max(width, 40) - 4,
                               initial_indent="    ", subsequent_indent="    ")  # fmt: skip
    lines += ["", "* requires obstacles slower than the robot (thesis (2.6))"]
    return lines


@controllers_app.command("show")
def controllers_show(
    name: Annotated[str, typer.Argument(help="Registered controller name, e.g. zhang2019-v1.")],
    json_out: Annotated[
        bool, typer.Option("--json", help="Print one JSON object instead of the table.")
    ] = False,
) -> None:
    """Show a controller: summary, reference and parameters with defaults and units."""
    info = controller_info(name)
    rows = _param_rows(info)
    if json_out:
        typer.echo(
            _dumps(
                {
                    "name": info.name,
                    "summary": info.summary,
                    "reference": info.reference,
                    "requires_slower_obstacles": info.requires_slower_obstacles,
                    "params": rows,
                }
            )
        )
        return
    from rich.table import Table

    con = _console()
    con.print(_text(f"{info.name}: {info.summary}"))
    if info.reference:
        con.print(_text(f"reference: {info.reference}"))
    if info.requires_slower_obstacles:
        con.print(_text("requires obstacles slower than the robot (thesis (2.6))"))
    if not rows:
        con.print(_text("no parameters"))
        return
    table = Table(title="parameters")
    table.add_column("name", no_wrap=True)
    table.add_column("type")
    table.add_column("default", justify="right")
    table.add_column("description", max_width=DESCRIPTION_WIDTH)  # wrapped, in a pipe too
    for row in rows:
        table.add_row(
            _text(row["name"]), _text(row["type"]), _text(_fmt(row["default"])), _text(row["doc"])
        )
    con.print(table)
