"""A recorded run replayed through a 2D law offline (``uvnav replay``).

A rosbag2 (a folder with ``metadata.yaml``, or one ``.mcap`` or ``.db3`` file; read with
``rosbags``) holding ``sensor_msgs/msg/LaserScan`` and ``nav_msgs/msg/Odometry`` messages is
read in the order it was recorded.  At each scan the law is asked what it would command:

* the robot's pose and speed are those of the latest odometry message before the scan (the
  odometry frame is the world frame, where the goal is given; scans before the first odometry
  message are skipped);
* the scanner is taken to sit at the robot's centre, facing its heading: beam ``i`` points at
  ``yaw + angle_min + i angle_increment``; a range outside ``[range_min, range_max)`` is no hit;
* the scan becomes the law's readings as a simulated lidar robot's does
  (:class:`~uvnav.sensors.suite2d.Sensors2D` with ``bodies: lidar``): the bodies the scan shows
  (:class:`~uvnav.sensors.scan_bodies.ScanBodies`) within the sensing range, their velocities
  by finite differences of the tracked centres
  (:class:`~uvnav.prediction.FiniteDifferenceEstimator`, no added noise);
* the time is the scan's header stamp (the bag's receive time when the stamp is zero), counted
  from the first scan replayed.

The law's command is set beside what the robot did, in the law's terms: a unicycle law's
``(V_R, u_R)`` beside the odometry's forward speed and turn rate; a holonomic law's world-frame
``(v_x, v_y)`` beside the odometry's velocity turned into the odometry frame.
"""

from __future__ import annotations

import csv
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from uvnav.bags import messages as m
from uvnav.bags import require
from uvnav.sensors.observation import LidarScan, Observation

#: the planar vehicles whose laws replay reads odometry for
VEHICLES = ("unicycle", "holonomic")


class BagError(ValueError):
    """The bag cannot be replayed (one line naming the bag or option and the problem)."""


@dataclass(frozen=True)
class ScanRecord:
    """One scan of the bag with the robot's state at it.

    Attributes:
        time: the scan's time [s] (header stamp, or the bag's receive time when it is zero).
        pose: ``[x, y, yaw]`` of the latest odometry [m, m, rad].
        twist: ``(linear.x, linear.y, angular.z)`` of that odometry (body frame) [m/s, rad/s].
        scan: the scan with world-frame angles.
    """

    time: float
    pose: np.ndarray
    twist: tuple[float, float, float]
    scan: LidarScan


@dataclass
class BagScans:
    """What :func:`read_bag` found: the replayable scans and how many came before any
    odometry."""

    records: list[ScanRecord]
    skipped: int
    scan_topic: str
    odom_topic: str


def _connection(reader: Any, bag: Path, topic: str, want: str) -> Any:
    conns = [c for c in reader.connections if c.topic == topic]
    if not conns:
        have = ", ".join(sorted({c.topic for c in reader.connections})) or "none"
        raise BagError(f"{bag}: no topic {topic} (topics: {have})")
    types = {c.msgtype for c in conns}
    if types != {want}:
        raise BagError(f"{bag}: topic {topic} is {', '.join(sorted(types))}, not {want}")
    return conns


def read_bag(bag: Path, scan_topic: str = "/scan", odom_topic: str = "/odom") -> BagScans:
    """The scans of ``bag`` on ``scan_topic`` with the robot's odometry on ``odom_topic``.

    Raises:
        MissingExtraError: the ``ros`` extra is not installed.
        BagError: no such file, not a bag, a topic missing or of another type, no scan after
            the first odometry message.
    """
    require("replaying a bag")
    from rosbags.highlevel import AnyReader

    bag = Path(bag)
    if not bag.exists():
        raise BagError(f"{bag}: no such file or directory")
    try:
        reader = AnyReader([bag], default_typestore=m.typestore())
        reader.open()
    except Exception as exc:  # rosbags raises its own errors and OSError, ValueError, KeyError
        raise BagError(f"{bag}: not a readable rosbag2 or MCAP file ({exc})") from None
    try:
        scans = _connection(reader, bag, scan_topic, m.SCAN_T)
        odoms = _connection(reader, bag, odom_topic, m.ODOM_T)
        out = _records(reader, [*scans, *odoms], scan_topic)
    finally:
        reader.close()
    records, skipped = out
    if not records:
        raise BagError(
            f"{bag}: no LaserScan on {scan_topic} after the first Odometry on {odom_topic}"
            + (f" ({skipped} before it)" if skipped else "")
        )
    return BagScans(records, skipped, scan_topic, odom_topic)


def _records(reader: Any, conns: list[Any], scan_topic: str) -> tuple[list[ScanRecord], int]:
    """The scans with the latest odometry before each, in the bag's order; and the number of
    scans before any odometry."""
    odom: Any = None
    records: list[ScanRecord] = []
    skipped = 0
    for conn, logged, raw in reader.messages(connections=conns):
        msg = reader.deserialize(raw, conn.msgtype)
        if conn.topic != scan_topic:
            odom = msg
            continue
        if odom is None:
            skipped += 1
            continue
        p, tw = odom.pose.pose, odom.twist.twist
        yaw = m.yaw_of(p.orientation)
        t = m.stamp_seconds(msg.header.stamp) or logged * 1e-9
        records.append(ScanRecord(
            time=t, pose=np.array((float(p.position.x), float(p.position.y), yaw)),
            twist=(float(tw.linear.x), float(tw.linear.y), float(tw.angular.z)),
            scan=m.scan_of(msg, yaw),
        ))  # fmt: skip
    return records, skipped


@dataclass
class ScanObserver:
    """The observation a lidar robot's law reads, made from recorded scans (module docstring).

    Args:
        sensing_range: bodies farther than this [m] are not reported.
        goal: the goal [m] in the odometry frame.
    """

    sensing_range: float
    goal: np.ndarray
    _bodies: Any = None
    _estimator: Any = None

    def __post_init__(self) -> None:
        from uvnav.prediction.finite_difference import FiniteDifferenceEstimator
        from uvnav.sensors.scan_bodies import ScanBodies

        self._bodies = ScanBodies()
        self._estimator = FiniteDifferenceEstimator(np.random.default_rng(0), 0.0)

    def observe(self, time: float, pose: np.ndarray, speed: float, scan: LidarScan) -> Observation:
        """The observation at ``time`` [s] from ``pose`` at ``speed`` [m/s] with ``scan``."""
        readings = self._bodies.readings(time, pose, scan, self.sensing_range)
        readings = self._estimator.update(time, readings)
        return Observation(time=time, pose=pose, speed=speed, goal=self.goal,
                           obstacles=readings, lidar=scan)  # fmt: skip


@dataclass
class Replay:
    """A bag replayed through a law: per scan, what the law commanded beside what the robot did.

    Attributes:
        law, params, goal: the law, its parameters, the goal [m].
        command_names: the two command components with units (the law's vehicle's).
        times: (n,) [s] from the first scan; poses: (n, 3) ``[x, y, yaw]``.
        law_commands, robot_commands: (n, 2) in :attr:`command_names`' terms.
        modes: the law's mode at each scan; bodies: (n,) bodies the law saw.
    """

    law: str
    params: dict[str, Any]
    goal: np.ndarray
    command_names: tuple[str, str]
    times: np.ndarray
    poses: np.ndarray
    law_commands: np.ndarray
    robot_commands: np.ndarray
    modes: list[str] = field(default_factory=list)
    bodies: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))

    def keys(self) -> tuple[str, str]:
        """Column stems of the two command components (``v_r``, ``u_r``; ``v_x``, ``v_y``)."""
        a, b = (n.split()[0].lower() for n in self.command_names)
        return a, b

    def rows(self) -> list[dict[str, Any]]:
        """One row per scan, the CSV's."""
        a, b = self.keys()
        rows = []
        for t, p, lc, rc, mode, nb in zip(
            self.times, self.poses, self.law_commands, self.robot_commands, self.modes,
            self.bodies, strict=True,
        ):  # fmt: skip
            rows.append({
                "time": float(t), "x": float(p[0]), "y": float(p[1]), "yaw": float(p[2]),
                f"law_{a}": float(lc[0]), f"law_{b}": float(lc[1]),
                f"robot_{a}": float(rc[0]), f"robot_{b}": float(rc[1]),
                "mode": mode, "bodies": int(nb),
            })  # fmt: skip
        return rows


def check_law(name: str) -> Any:
    """The registry entry of ``name`` if replay can run it: a 2D law of a unicycle or the
    holonomic robot that reads the bodies (exact sensing's observation).

    Raises:
        UnknownControllerError: no such law.
        BagError: another vehicle or another sensor.
    """
    from uvnav.controllers.base import controller_info

    info = controller_info(name)
    if info.vehicle not in VEHICLES or info.sensing != "exact":
        raise BagError(
            f"-c {name}: drives a {info.vehicle} with {info.sensing} sensing; replay runs "
            f"{' and '.join(VEHICLES)} laws that read bodies (exact sensing)"
        )
    return info


def replay(
    scans: BagScans,
    law_name: str,
    params: dict[str, Any],
    goal: np.ndarray,
    robot: Any,
    sensing_range: float | None = None,
) -> Replay:
    """Run ``law_name`` with ``params`` on every scan of ``scans`` toward ``goal`` [m].

    Args:
        robot: the robot block's limits (:class:`~uvnav.dynamics.unicycle.UnicycleSpec`: its
            ``v_max``, ``u_max``, ``radius``), which the law is reset with.
        sensing_range: bodies farther than this [m] are not reported (default: the first
            scan's ``range_max``).

    Raises:
        UnknownControllerError, ControllerParamsError: no such law, bad parameters.
        BagError: a law replay cannot run (:func:`check_law`), or one that reads ground truth.
    """
    from uvnav.controllers.base import make_law
    from uvnav.dynamics.vehicles import make_vehicle

    info = check_law(law_name)
    law = make_law(law_name, **params)
    if getattr(law, "oracle", False):
        raise BagError(f"-c {law_name}: reads ground truth no recording holds (an oracle law)")
    vehicle = make_vehicle(info.vehicle, robot)
    goal = np.asarray(goal, dtype=float)
    law.reset(vehicle.spec, goal, np.random.default_rng(0))
    records = scans.records
    reach = float(records[0].scan.max_range) if sensing_range is None else sensing_range
    observer = ScanObserver(reach, goal)
    t0 = records[0].time
    n = len(records)
    law_cmds, robot_cmds = np.zeros((n, 2)), np.zeros((n, 2))
    modes, bodies = [], np.zeros(n, dtype=int)
    for k, rec in enumerate(records):
        speed = math.hypot(rec.twist[0], rec.twist[1])
        obs = observer.observe(rec.time - t0, rec.pose, speed, rec.scan)
        law_cmds[k] = vehicle.pair(law.act(obs))
        robot_cmds[k] = _robot_pair(info.vehicle, rec)
        modes.append(str(law.mode))
        bodies[k] = len(obs.obstacles)
    return Replay(
        law=law_name, params=dict(params), goal=goal, command_names=vehicle.command_names,
        times=np.array([r.time - t0 for r in records]),
        poses=np.array([r.pose for r in records]).reshape(n, 3),
        law_commands=law_cmds, robot_commands=robot_cmds, modes=modes, bodies=bodies,
    )  # fmt: skip


def _robot_pair(vehicle: str, rec: ScanRecord) -> tuple[float, float]:
    """What the robot did, in the law's command terms (module docstring)."""
    lx, ly, wz = rec.twist
    if vehicle == "unicycle":
        return lx, wz
    return m.to_world(lx, ly, float(rec.pose[2]))


def write_outputs(result: Replay, scans: BagScans, bag: Path, out: Path) -> tuple[Path, Path]:
    """``replay.csv`` (one row per scan) and ``replay.json`` (what was replayed and the mean
    absolute difference of each command component) in the folder ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    rows = result.rows()
    csv_path, json_path = out / "replay.csv", out / "replay.json"
    with csv_path.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    diff = np.abs(result.law_commands - result.robot_commands).mean(axis=0)
    summary = {
        "bag": str(bag), "law": result.law, "params": result.params,
        "goal": [float(v) for v in result.goal], "scan_topic": scans.scan_topic,
        "odom_topic": scans.odom_topic, "scans": len(rows),
        "skipped_before_odometry": scans.skipped, "command_names": list(result.command_names),
        "mean_abs_difference": dict(zip(result.keys(), map(float, diff), strict=True)),
        "duration": float(result.times[-1]),
    }  # fmt: skip
    json_path.write_text(json.dumps(summary, indent=2, default=str) + "\n")
    return csv_path, json_path
