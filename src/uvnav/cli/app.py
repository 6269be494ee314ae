"""The ``uvnav`` command line (layer 8): thin Typer commands over the library.

This module holds the root app, its ``--version`` / ``--debug`` options and ``uvnav simulate``;
every other command lives in its own module (:mod:`uvnav.cli.scenarios`,
:mod:`uvnav.cli.controllers`, :mod:`uvnav.cli.bench`, :mod:`uvnav.cli.report`,
:mod:`uvnav.cli.reproduce`, :mod:`uvnav.cli.recon`, :mod:`uvnav.cli.drive`,
:mod:`uvnav.cli.sonar`, :mod:`uvnav.cli.crowd`) and is registered here, in the order ``uvnav
--help`` lists them.  Helpers several command modules share are in :mod:`uvnav.cli.common`, which
imports no command module.

Commands parse their arguments, call the library and print with rich (or plain JSON/YAML where the
output is meant for machines).  Errors take one path, :class:`~uvnav.cli.errors.UvnavGroup`: a
user error — a bad scenario file, an unknown controller or parameter, a missing file, a malformed
``--param`` — is ONE line ``error: <message>`` on stderr and exit status 2; a bug is ONE line
``internal error: ...`` naming the crash log that holds its traceback, exit status 70
(``uvnav --debug`` shows the traceback instead).

Heavy or optional parts (the reproduction job, figures, the report) are imported inside the
command that needs them, so ``uvnav scenarios list`` stays fast and works without them.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Any

import typer

from uvnav.cli.bench import bench_cmd
from uvnav.cli.common import (
    ControllerOption,
    GenParamOption,
    ParamOption,
    parse_params,
    resolve_scene,
)
from uvnav.cli.common import console as _console
from uvnav.cli.common import dumps as _dumps
from uvnav.cli.common import fmt as _fmt
from uvnav.cli.common import optional as _optional
from uvnav.cli.common import text as _text
from uvnav.cli.controllers import controllers_app
from uvnav.cli.crowd import crowd_app
from uvnav.cli.drive import drive_app
from uvnav.cli.errors import DEBUG_KEY, CliError, uvnav_typer
from uvnav.cli.mcap import close_episode, open_episode
from uvnav.cli.recon import recon_app
from uvnav.cli.replay import replay_cmd
from uvnav.cli.report import report_cmd
from uvnav.cli.reproduce import forget_cmd, reproduce_cmd, run_cmd
from uvnav.cli.ros2 import ros2_app
from uvnav.cli.scenarios import scenarios_app
from uvnav.cli.sonar import sonar_app
from uvnav.cli.view import view_cmd
from uvnav.sim import METRIC_NAMES
from uvnav.sim.metrics import SOCIAL_METRIC_NAMES

app = uvnav_typer(
    name="uvnav",
    help="Real-time navigation of unmanned vehicles: simulate, benchmark and report.",
)
app.add_typer(scenarios_app, name="scenarios")
app.add_typer(controllers_app, name="controllers")
app.add_typer(recon_app, name="recon")
app.add_typer(drive_app, name="drive")
app.add_typer(sonar_app, name="sonar")
app.add_typer(crowd_app, name="crowd")
app.add_typer(ros2_app, name="ros2")


def _version(value: bool) -> None:
    if value:
        from uvnav import __version__

        typer.echo(f"uvnav {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    ctx: typer.Context,
    version: Annotated[
        bool,
        typer.Option(
            "--version", callback=_version, is_eager=True, help="Print the version and exit."
        ),
    ] = False,
    debug: Annotated[
        bool,
        typer.Option(
            "--debug",
            help="On an internal error, show the Python traceback instead of writing it to a "
            "crash log (also: UVNAV_DEBUG=1).",
        ),
    ] = False,
) -> None:
    """Real-time navigation of unmanned vehicles: simulate, benchmark and report."""
    if debug:
        ctx.meta[DEBUG_KEY] = True


# ---------------------------------------------------------------------------------------- simulate

_METRIC_UNITS = {
    "min_clearance": "m",
    "path_length": "m",
    "time_to_goal": "s",
    "control_effort": "rad²/s + m²/s³",
    "decision_us_median": "µs",
    "decision_us_p99": "µs",
    "min_separation": "m",
    "too_close_time": "s",
    "intrusion_time": "s",
    "personal_space_time": "s",
    "min_time_to_collision": "s",
    "path_irregularity": "rad/m",
    "heading_irregularity": "rad",
    "jerk": "m/s³",
    "contact_time": "s",
}


@app.command()
def simulate(
    scenario: Annotated[
        str,
        typer.Argument(
            help="Built-in name, YAML file, or GENERATOR:SEED (random-ch2:3, random-ch4:1, "
            "antipodal:8 = 8 robots; see 'uvnav scenarios list')."
        ),
    ],
    controller: ControllerOption = None,
    param: ParamOption = None,
    seed: Annotated[
        int | None,
        typer.Option(
            min=0,
            help="Episode seed (obstacle motion, sensing noise); default 0, or the generator's "
            "seed for GENERATOR:SEED.",
        ),
    ] = None,
    json_out: Annotated[
        bool, typer.Option("--json", help="Print one JSON object instead of the table.")
    ] = False,
    plot: Annotated[
        Path | None, typer.Option(help="Also draw the episode into this image file.")
    ] = None,
    gen_param: GenParamOption = None,
    beyond_assumptions: Annotated[
        bool,
        typer.Option(
            "--beyond-assumptions",
            help="Run the law even where the scene breaks an assumption it declares (a "
            "deliberate experiment, as a campaign's beyond_assumptions: true).",
        ),
    ] = False,
    mcap: Annotated[
        Path | None,
        typer.Option(
            help="Also write the episode into this MCAP file, as ROS 2 messages (Foxglove, "
            "ros2 bag); 2D scenes; needs the 'ros' extra."
        ),
    ] = None,
) -> None:
    """Run one episode of SCENARIO (any vehicle) and print its metrics.

    The scenario's law parameters are used when the law is the scenario's own; --param values
    override them.  With another --controller only --param values apply.  A law that drives
    another vehicle or reads another sensor than the scene's is refused, and so is one whose
    declared assumption the scene breaks, unless --beyond-assumptions.
    """
    from uvnav.scenarios.episodes import limits_note, run_scene

    if controller is not None and not controller.strip():
        raise CliError("--controller '': empty law name ('uvnav controllers list' names them)")
    resolved = resolve_scene(scenario, gen_param)
    plot_outcome = (
        _optional("uvnav.viz.episode", "plot_outcome", "plotting (--plot)") if plot else None
    )
    if plot is not None:
        _check_image_path(plot)
    params = parse_params(param)
    episode = open_episode(mcap, resolved, controller, seed) if mcap is not None else None
    try:
        out = run_scene(
            resolved,
            controller,
            params,
            seed,
            record=plot is not None,
            beyond_assumptions=beyond_assumptions,
            probes=[episode] if episode is not None else (),
        )
    except BaseException:
        if episode is not None:
            close_episode(episode, ok=False)
        raise
    if episode is not None:
        close_episode(episode, ok=True)
    note = limits_note(resolved, out.law)
    if note is not None:
        typer.echo(note, err=True)
    record: dict[str, Any] = {
        "scenario": out.scene,
        "kind": out.kind,
        "controller": out.law,
        "params": out.params,
        "seed": out.seed,
        "status": out.status,
        **{k: out.metrics[k] for k in METRIC_NAMES},
        **out.extra,
    }
    if plot_outcome is not None and plot is not None:
        try:
            plot_outcome(out, plot)
        except ValueError as exc:
            raise CliError(str(exc)) from None
        except ImportError as exc:
            raise CliError(f"plotting (--plot) is not available: {exc}", code=1) from None
    if json_out:
        typer.echo(_dumps(record))
        if plot is not None:
            typer.echo(f"wrote {plot}", err=True)
        if mcap is not None:
            typer.echo(f"wrote {mcap}", err=True)
        return
    from rich.table import Table

    table = Table(title=f"{out.scene} | {out.law} | seed {out.seed} | {out.status}")
    table.add_column("metric")
    table.add_column("value", justify="right")
    table.add_column("unit")
    for key in METRIC_NAMES:
        if key in SOCIAL_METRIC_NAMES and out.kind != "nav2d":
            continue  # only the 2D worlds have them (uvnav.sim.social); JSON keeps them as null
        table.add_row(key, _fmt(out.metrics[key]), _METRIC_UNITS.get(key, ""))
    for key, value in out.extra.items():
        if not isinstance(value, dict | list):
            table.add_row(key, _fmt(value), _METRIC_UNITS.get(key, ""))
    con = _console()
    con.print(table)
    robots = out.extra.get("robots")
    if robots:
        for row in robots:
            t = row["time_to_goal"]
            con.print(
                _text(
                    f"  {row['name']:>12}  {row['status']:<9}  path {row['path_length']:.2f} m"
                    + (f"  arrived {t:.1f} s" if t is not None else "")
                )
            )
    if plot is not None:
        typer.echo(f"wrote {plot}")
    if mcap is not None:
        typer.echo(f"wrote {mcap}")


def _check_image_path(path: Path) -> None:
    """Refuse, before any work, an image path matplotlib would not write as given: a folder, or
    a name without a format suffix it knows (it would write ``NAME.png`` beside it instead).

    Raises:
        CliError: one line naming the path and the formats.
    """
    from matplotlib.backend_bases import FigureCanvasBase

    formats = FigureCanvasBase.get_supported_filetypes()
    if path.is_dir():
        raise CliError(f"--plot {path}: is a directory; give an image file such as run.png")
    if path.suffix.lower().lstrip(".") not in formats:
        raise CliError(
            f"--plot {path}: unknown image format {path.suffix or '(no suffix)'}; "
            f"use one of {', '.join('.' + f for f in sorted(formats))}"
        )


def main() -> None:
    """Console-script entry point (``uvnav``)."""
    app(prog_name="uvnav")


app.command("run")(run_cmd)
app.command("report")(report_cmd)
app.command("bench")(bench_cmd)
app.command("reproduce")(reproduce_cmd)
app.command("forget")(forget_cmd)
app.command("replay")(replay_cmd)
app.command("view")(view_cmd)
