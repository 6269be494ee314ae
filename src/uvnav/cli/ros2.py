"""``uvnav ros2``: a law as a ROS 2 node over DDS, with no ROS installation (the ``ros2`` extra).

Commands (thin: they parse, call :mod:`uvnav.ros2`, print):

* ``run LAW`` — subscribe to ``/scan``, ``/odom`` and ``/goal_pose`` and publish ``/cmd_vel`` at
  the decision rate, with a safe stop (:mod:`uvnav.ros2.node`, :mod:`uvnav.ros2.navigator`);
* ``params LAW`` — the law's parameters as ROS 2 parameters (name, type, default, description),
  or ``--yaml``: a parameter file in ``ros2 param dump``'s layout that ``run --params-file``
  reads.

Bad input prints ONE line ``error: ...`` and exits with status 2; so does a missing
``cyclonedds`` package (naming the extra that installs it).
"""

from __future__ import annotations

import contextlib
import math
import signal
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Annotated, Any

import typer
import yaml

from uvnav.cli.checks import finite
from uvnav.cli.common import ParamOption, parse_params
from uvnav.cli.errors import CliError, uvnav_typer

#: the name of the node in a parameter file
NODE_NAME = "uvnav"

ros2_app = uvnav_typer(
    help="A law as a ROS 2 node over DDS (Cyclone DDS; no ROS installation needed).",
)


def _require_cyclonedds() -> None:
    """A one-line error (status 2) when the ``cyclonedds`` package cannot be imported."""
    try:
        import cyclonedds.domain  # noqa: F401
    except ImportError as exc:
        raise CliError(
            "uvnav ros2 needs the 'ros2' extra (pip install 'uvnav[ros2]'): "
            f"cannot import cyclonedds ({exc})"
        ) from None


def _positive(option: str, value: float) -> float:
    if not value > 0:
        raise CliError(f"{option}: must be positive (got {value:g})")
    return value


def _law_params(law: str, params_file: Path | None, items: list[str] | None) -> dict[str, Any]:
    """The law's parameters: the file's, then ``--param`` values over them (arrays as the
    law's tuples)."""
    from uvnav.ros2.params import file_parameters, law_arguments
    from uvnav.scenarios.parse import yaml_value

    params: dict[str, Any] = {}
    if params_file is not None:
        try:
            params = file_parameters(yaml_value(params_file.read_text(encoding="utf-8")))
        except (yaml.YAMLError, ValueError, UnicodeDecodeError) as exc:
            first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            raise CliError(f"{params_file}: {first}") from None
    return law_arguments(law, {**params, **parse_params(items)})


@ros2_app.command("run")
def run_cmd(
    law: Annotated[str, typer.Argument(help="A unicycle or holonomic law of the registry.")],
    param: ParamOption = None,
    params_file: Annotated[
        Path | None,
        typer.Option(help="ROS 2 parameter file (NODE: ros__parameters: ...); --param wins."),
    ] = None,
    domain: Annotated[
        int, typer.Option(min=0, max=232, envvar="ROS_DOMAIN_ID", help="DDS domain id.")
    ] = 0,
    rate: Annotated[float, typer.Option(callback=finite, help="Decisions per second [Hz].")] = 10.0,
    scan_timeout: Annotated[
        float, typer.Option(callback=finite, help="Stop when no scan came for this long [s].")
    ] = 0.5,
    v_max: Annotated[float, typer.Option(callback=finite, help="Robot's top speed [m/s].")] = 1.0,
    u_max: Annotated[
        float, typer.Option(callback=finite, help="Robot's top turn rate [rad/s].")
    ] = 1.0,
    radius: Annotated[float, typer.Option(callback=finite, help="Robot's radius [m].")] = 0.3,
    goal_tolerance: Annotated[
        float, typer.Option(callback=finite, help="Goal reached within this distance [m].")
    ] = 0.2,
    sensing_range: Annotated[
        float, typer.Option(callback=finite, help="Bodies the law is given, within [m].")
    ] = 5.0,
    seed: Annotated[
        int, typer.Option(min=0, help="Seed of the law's and the perception's generators.")
    ] = 0,
    duration: Annotated[
        float, typer.Option(callback=finite, help="Stop after this long [s]; 0: on Ctrl-C.")
    ] = 0.0,
) -> None:
    """Run LAW as a ROS 2 node: /scan, /odom, /goal_pose in; /cmd_vel out."""
    for option, value in (("--rate", rate), ("--scan-timeout", scan_timeout),
                          ("--v-max", v_max), ("--u-max", u_max),
                          ("--goal-tolerance", goal_tolerance),
                          ("--sensing-range", sensing_range)):  # fmt: skip
        _positive(option, value)
    if radius < 0 or duration < 0:
        raise CliError(f"{'--radius' if radius < 0 else '--duration'}: must not be negative")
    from uvnav.controllers.base import build_params, controller_info
    from uvnav.ros2.params import law_vehicle

    try:
        law_vehicle(law)
    except ValueError as exc:
        raise CliError(str(exc)) from None
    params = _law_params(law, params_file, param)
    build_params(controller_info(law).params_type, params)  # bad parameters: one line
    _require_cyclonedds()
    from uvnav.ros2.navigator import Navigator, RobotConfig
    from uvnav.ros2.node import Ros2Node

    robot = RobotConfig(
        v_max=v_max, u_max=u_max, radius=radius, goal_tolerance=goal_tolerance,
        sensing_range=sensing_range, scan_timeout=scan_timeout, seed=seed,
    )  # fmt: skip
    navigator = Navigator(law, params, robot)
    node = Ros2Node(navigator, domain, rate, log=_log)
    _log(f"{law} on DDS domain {domain}: rt/scan, rt/odom, rt/goal_pose -> rt/cmd_vel "
         f"at {rate:g} Hz")  # fmt: skip
    with _stop_on_sigterm() as stop, contextlib.suppress(KeyboardInterrupt):
        node.spin(lambda: stop[0], duration_s=duration)
    _log("stopped (zero Twist sent)")


def _log(line: str) -> None:
    print(f"uvnav ros2: {line}", file=sys.stderr, flush=True)


@contextlib.contextmanager
def _stop_on_sigterm() -> Iterator[list[bool]]:
    """A flag set when the process is asked to terminate (the loop then ends with a stop);
    the previous SIGTERM handler is restored on exit."""
    flag = [False]

    def handler(signum: int, frame: Any) -> None:
        flag[0] = True

    previous = signal.signal(signal.SIGTERM, handler)
    try:
        yield flag
    finally:
        signal.signal(signal.SIGTERM, previous)


@ros2_app.command("params")
def params_cmd(
    law: Annotated[str, typer.Argument(help="A law of the registry.")],
    as_yaml: Annotated[
        bool, typer.Option("--yaml", help="A ROS 2 parameter file of the defaults.")
    ] = False,
) -> None:
    """List LAW's parameters as ROS 2 parameters (name, type, default, description)."""
    from uvnav.ros2.params import describe, parameter_file

    params = describe(law)
    if as_yaml:
        typer.echo(yaml.safe_dump(parameter_file(NODE_NAME, params), sort_keys=False), nl=False)
        return
    if not params:
        typer.echo(f"{law} takes no parameters")
        return
    for p in params:
        typer.echo(f"Parameter name: {p.name}\n  Type: {p.type}")
        if p.description:
            typer.echo(f"  Description: {p.description}")
        typer.echo(f"  Default: {_shown(p.default)}")


def _shown(value: Any) -> str:
    """A default as a ROS 2 user writes it (YAML flow style)."""
    if isinstance(value, float) and not math.isfinite(value):
        return ".inf" if value > 0 else "-.inf" if value < 0 else ".nan"
    from uvnav.ros2.params import plain

    text = yaml.safe_dump(plain(value), default_flow_style=True)
    return text.strip().removesuffix("...").strip()
