"""``uvnav replay BAG -c LAW --goal X Y``: a recorded run (scans and odometry) replayed through a
2D law offline (:mod:`uvnav.bags.replay`), what it would have commanded written beside what the
robot did (CSV, JSON, a figure)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated

import numpy as np
import typer

from uvnav.cli.common import ParamOption, parse_params
from uvnav.cli.errors import CliError
from uvnav.validation import coordinate_problem


def _positive(option: str, value: float) -> float:
    if not (math.isfinite(value) and value > 0):
        raise CliError(f"{option}: must be a finite number > 0 (got {value})")
    return value


def replay_cmd(
    bag: Annotated[
        Path,
        typer.Argument(
            help="A rosbag2 folder, or one .mcap or .db3 file, with sensor_msgs/LaserScan and "
            "nav_msgs/Odometry messages (an episode written by 'uvnav simulate --mcap' too)."
        ),
    ],
    controller: Annotated[
        str, typer.Option("--controller", "-c", help="Law name (a 2D unicycle or holonomic law).")
    ],
    goal: Annotated[
        tuple[float, float],
        typer.Option(metavar="X Y", help="The goal [m] in the odometry frame."),
    ],
    param: ParamOption = None,
    out: Annotated[
        Path | None,
        typer.Option(
            help="Folder for replay.csv, replay.json and replay.png (default: "
            "BAGNAME-replay in the current folder)."
        ),
    ] = None,
    scan_topic: Annotated[str, typer.Option(help="The LaserScan topic.")] = "/scan",
    odom_topic: Annotated[str, typer.Option(help="The Odometry topic.")] = "/odom",
    sensing_range: Annotated[
        float | None,
        typer.Option(
            help="Bodies farther than this [m] are not reported (default: the scanner's range_max)."
        ),
    ] = None,
    v_max: Annotated[float, typer.Option(help="The robot's V_max [m/s].")] = 1.0,
    u_max: Annotated[float, typer.Option(help="The robot's U_max [rad/s] (unicycle laws).")] = 2.0,
    radius: Annotated[float, typer.Option(help="The robot's radius [m].")] = 0.3,
) -> None:
    """Replay BAG through a law: at each scan, what the law would have commanded (from the scan
    and the latest odometry) beside what the robot did.

    The scanner is taken to sit at the robot's centre facing its heading; the scan's bodies are
    found, tracked and their velocities estimated as for a simulated robot with lidar bodies.
    Writes replay.csv (one row per scan), replay.json (a summary) and replay.png.
    """
    for i, value in enumerate(goal):
        problem = coordinate_problem(value)
        if problem is not None:
            raise CliError(f"--goal: {'XY'[i]}: {problem}")
    _positive("--v-max", v_max)
    _positive("--u-max", u_max)
    if not (math.isfinite(radius) and radius >= 0):
        raise CliError(f"--radius: must be a finite number >= 0 (got {radius})")
    if sensing_range is not None:
        _positive("--sensing-range", sensing_range)
    params = parse_params(param)
    from uvnav.bags import MissingExtraError
    from uvnav.bags.replay import BagError, check_law, read_bag, replay, write_outputs
    from uvnav.dynamics.unicycle import UnicycleSpec

    try:
        check_law(controller)
        scans = read_bag(bag, scan_topic, odom_topic)
        robot = UnicycleSpec(v_max=v_max, u_max=u_max, radius=radius)
        result = replay(scans, controller, params, np.asarray(goal), robot, sensing_range)
    except MissingExtraError as exc:
        raise CliError(str(exc), code=1) from None
    except BagError as exc:
        raise CliError(str(exc)) from None
    folder = out if out is not None else Path(f"{bag.name.split('.')[0] or 'bag'}-replay")
    if folder.exists() and not folder.is_dir():
        raise CliError(f"--out {folder}: is a file, not a folder")
    csv_path, json_path = write_outputs(result, scans, bag, folder)
    from uvnav.viz.replay import plot_replay

    png = plot_replay(result, folder / "replay.png", title=f"{bag.name} | {controller}")
    a, b = result.keys()
    diff = abs(result.law_commands - result.robot_commands).mean(axis=0)
    typer.echo(
        f"{len(result.times)} scans over {result.times[-1]:.2f} s"
        + (f" ({scans.skipped} before the first odometry skipped)" if scans.skipped else "")
        + f"; mean |law - robot|: {a} {diff[0]:.4g}, {b} {diff[1]:.4g}"
    )
    for path in (csv_path, json_path, png):
        typer.echo(f"wrote {path}")
