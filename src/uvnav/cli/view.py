"""``uvnav view SCENE``: one episode served live to Foxglove over its WebSocket protocol
(:mod:`uvnav.bags.live`), the topics ``uvnav simulate --mcap`` writes, at ``--speed`` times
real time; the server stays up after the episode until Ctrl-C (or exits with ``--once``)."""

from __future__ import annotations

import math
import time
from typing import Annotated, Any

import typer

from uvnav.cli.common import (
    ControllerOption,
    GenParamOption,
    ParamOption,
    parse_params,
    resolve_scene,
)
from uvnav.cli.errors import CliError
from uvnav.cli.mcap import KINDS

#: seconds the server stays up after the episode with ``--once``, for clients to read the end
DRAIN_S = 1.0


def view_cmd(
    scenario: Annotated[
        str,
        typer.Argument(help="Built-in name, YAML file, or GENERATOR:SEED (a 2D scene)."),
    ],
    controller: ControllerOption = None,
    param: ParamOption = None,
    seed: Annotated[
        int | None, typer.Option(min=0, help="Episode seed (as 'uvnav simulate --seed').")
    ] = None,
    gen_param: GenParamOption = None,
    host: Annotated[
        str, typer.Option(help="Address to listen on (0.0.0.0: every interface).")
    ] = "127.0.0.1",
    port: Annotated[
        int, typer.Option(min=0, max=65535, help="Port to listen on (0: a free one).")
    ] = 8765,
    speed: Annotated[
        float, typer.Option(help="Simulation seconds per wall-clock second (> 0).")
    ] = 1.0,
    once: Annotated[
        bool,
        typer.Option("--once", help="Exit when the episode ends instead of serving until Ctrl-C."),
    ] = False,
) -> None:
    """Serve one episode of SCENARIO live to Foxglove over its WebSocket protocol.

    Foxglove connects to ws://HOST:PORT (default ws://127.0.0.1:8765) and receives the topics
    'uvnav simulate --mcap' writes, as ROS 2 messages: /tf, /bodies, /odom, /cmd_vel, /mode,
    /scan (/NAME/odom and so on for robot NAME of a multi-robot scene).  The episode starts
    when a client subscribes and runs at --speed times real time; the server then stays up
    until Ctrl-C (--once: exits).  2D scenes; needs the 'ros' extra.
    """
    from uvnav.scenarios.episodes import run_scene

    if not (math.isfinite(speed) and speed > 0):
        raise CliError(f"--speed: must be a finite number > 0 (got {speed})")
    if controller is not None and not controller.strip():
        raise CliError("--controller '': empty law name ('uvnav controllers list' names them)")
    resolved = resolve_scene(scenario, gen_param)
    if resolved.kind.name not in KINDS:
        raise CliError(
            f"{scenario}: {resolved.kind.name} scenes are not served yet "
            f"({' and '.join(KINDS)} are)"
        )
    params = parse_params(param)
    probe = _probe(host, port, speed)
    try:
        out = run_scene(resolved, controller, params, seed, probes=[probe])
        typer.echo(f"episode over: {out.status} at t = {probe.last_t:.2f} s ({out.law})")
        if once:
            time.sleep(DRAIN_S)
            return
        typer.echo("serving until Ctrl-C")
        _serve_forever()
    except RuntimeError as exc:
        if probe.server is None:  # foxglove-sdk's error: the server did not start
            raise CliError(f"--host/--port {host}:{port}: cannot listen: {exc}") from None
        raise
    finally:
        probe.stop()


def _probe(host: str, port: int, speed: float) -> Any:
    """A :class:`uvnav.bags.live.FoxgloveEpisode` that prints its address once it listens.

    Raises:
        CliError: the ``ros`` extra missing (status 1).
    """
    from uvnav.bags import MissingExtraError
    from uvnav.bags.live import FoxgloveEpisode

    def ready(url: str) -> None:
        typer.echo(f"serving on {url}; waiting for a Foxglove client")

    try:
        return FoxgloveEpisode(host, port, speed, on_ready=ready)
    except MissingExtraError as exc:
        raise CliError(str(exc), code=1) from None


def _serve_forever() -> None:
    """Sleep until Ctrl-C, which ends the command normally."""
    try:
        while True:
            time.sleep(3600.0)
    except KeyboardInterrupt:
        return
