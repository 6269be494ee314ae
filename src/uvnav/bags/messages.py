"""ROS 2 messages of uvnav's values, as the dictionaries ``mcap-ros2-support`` encodes, and back.

Frames: ``map`` is the world frame of the scene (x east, y north, metres); ``base_link`` is the
robot's body frame (x forward along the heading, y to the left).  Poses are planar (z = 0, a yaw
quaternion); a twist is given in the body frame, as ``cmd_vel`` and ``Odometry.twist`` are in
ROS.  Times are simulation times [s] as ``builtin_interfaces/Time`` (seconds since the epoch, so
an episode starts at 1970-01-01T00:00:00).

The message definitions are ROS 2 Jazzy's (``rosbags``' type store), the text a rosbag2 MCAP
file carries as its ``ros2msg`` schemas.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from uvnav.geometry.angles import FloatArray, wrap_scalar
from uvnav.obstacles.obstacle import ObstacleField
from uvnav.sensors.observation import LidarScan

#: the ROS 2 distribution whose message definitions are written
DISTRO = "ROS2_JAZZY"

#: ROS 2 type names of the messages uvnav writes or reads
POSE_T = "geometry_msgs/msg/PoseStamped"
TF_T = "tf2_msgs/msg/TFMessage"
ODOM_T = "nav_msgs/msg/Odometry"
MARKERS_T = "visualization_msgs/msg/MarkerArray"
TWIST_T = "geometry_msgs/msg/Twist"
STRING_T = "std_msgs/msg/String"
SCAN_T = "sensor_msgs/msg/LaserScan"

# visualization_msgs/Marker types and actions
CYLINDER, SPHERE, LINE_STRIP = 3, 2, 4
ADD, DELETEALL = 0, 3

#: body height drawn in the 3D views [m]
HEIGHT = 0.5
#: width of a polygon's outline [m]
LINE_WIDTH = 0.04

COLOURS = {
    "body": {"r": 0.85, "g": 0.3, "b": 0.25, "a": 0.8},
    "robot": {"r": 0.2, "g": 0.45, "b": 0.9, "a": 0.9},
    "goal": {"r": 0.2, "g": 0.75, "b": 0.3, "a": 0.9},
}


@functools.cache
def typestore() -> Any:
    """``rosbags``' type store of :data:`DISTRO`."""
    from rosbags.typesys import Stores, get_typestore

    return get_typestore(getattr(Stores, DISTRO))


def msgdef(type_name: str) -> str:
    """The ``ros2msg`` definition of ``type_name`` with its dependencies (the text rosbag2
    writes as an MCAP schema)."""
    text, _ = typestore().generate_msgdef(type_name, ros_version=2)
    return str(text)


def stamp(t: float) -> dict[str, int]:
    """``builtin_interfaces/Time`` of time ``t`` [s] (``t`` >= 0)."""
    ns = nanoseconds(t)
    return {"sec": ns // 1_000_000_000, "nanosec": ns % 1_000_000_000}


def nanoseconds(t: float) -> int:
    """Time ``t`` [s] in whole nanoseconds (the MCAP log time)."""
    return round(t * 1e9)


def stamp_seconds(msg_stamp: Any) -> float:
    """Seconds of a decoded ``builtin_interfaces/Time``."""
    return float(msg_stamp.sec) + 1e-9 * float(msg_stamp.nanosec)


def header(t: float, frame: str) -> dict[str, Any]:
    """``std_msgs/Header`` at time ``t`` [s] in ``frame``."""
    return {"stamp": stamp(t), "frame_id": frame}


def quaternion(yaw: float) -> dict[str, float]:
    """The rotation by ``yaw`` [rad] about z."""
    return {"x": 0.0, "y": 0.0, "z": math.sin(0.5 * yaw), "w": math.cos(0.5 * yaw)}


def yaw_of(q: Any) -> float:
    """The yaw [rad] of a decoded ``geometry_msgs/Quaternion`` (its rotation about z)."""
    x, y, z, w = float(q.x), float(q.y), float(q.z), float(q.w)
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def pose(x: float, y: float, yaw: float) -> dict[str, Any]:
    """``geometry_msgs/Pose`` of a planar pose."""
    return {"position": {"x": x, "y": y, "z": 0.0}, "orientation": quaternion(yaw)}


def to_body(vx: float, vy: float, yaw: float) -> tuple[float, float]:
    """The world-frame vector ``(vx, vy)`` in the body frame of heading ``yaw`` [rad]."""
    c, s = math.cos(yaw), math.sin(yaw)
    return c * vx + s * vy, -s * vx + c * vy


def to_world(bx: float, by: float, yaw: float) -> tuple[float, float]:
    """The body-frame vector ``(bx, by)`` of heading ``yaw`` [rad] in the world frame."""
    c, s = math.cos(yaw), math.sin(yaw)
    return c * bx - s * by, s * bx + c * by


def twist(linear: tuple[float, float], angular: float) -> dict[str, Any]:
    """``geometry_msgs/Twist`` of a planar body-frame velocity [m/s] and turn rate [rad/s]."""
    return {
        "linear": {"x": linear[0], "y": linear[1], "z": 0.0},
        "angular": {"x": 0.0, "y": 0.0, "z": angular},
    }


def command_twist(cmd: Any, yaw: float) -> dict[str, Any]:
    """The ``cmd_vel`` of a law's command at heading ``yaw`` [rad]: a unicycle's ``(v, u)`` is
    ``linear.x = v``, ``angular.z = u``; a velocity command ``(vx, vy)`` (world frame, the
    holonomic robot's) is turned into the body frame, ``angular.z = 0``.

    Raises:
        TypeError: a command of neither kind.
    """
    if hasattr(cmd, "v") and hasattr(cmd, "u"):
        return twist((float(cmd.v), 0.0), float(cmd.u))
    if hasattr(cmd, "vx") and hasattr(cmd, "vy"):
        return twist(to_body(float(cmd.vx), float(cmd.vy), yaw), 0.0)
    raise TypeError(f"no Twist for a {type(cmd).__name__} command")


def laser_scan(scan: LidarScan, heading: float, t: float, frame: str) -> dict[str, Any]:
    """``sensor_msgs/LaserScan`` of ``scan`` (world-frame beam angles) taken at heading
    ``heading`` [rad] at time ``t`` [s]: angles relative to the body frame ``frame``, evenly
    spaced from the first beam (``angle_min`` in [-pi, pi)); a beam that saw nothing reads
    ``range_max``, a dropped one NaN (both invalid to a ROS reader, as ``range_max`` is
    exclusive there)."""
    angles = np.asarray(scan.angles, dtype=float)
    n = len(angles)
    first = math.remainder(float(angles[0]) - heading, 2.0 * math.pi) if n else 0.0
    if first >= math.pi - 1e-9:  # in [-pi, pi): a full turn runs from -pi
        first -= 2.0 * math.pi
    step = math.remainder(float(angles[1] - angles[0]), 2.0 * math.pi) if n > 1 else 0.0
    return {
        "header": header(t, frame),
        "angle_min": first,
        "angle_max": first + step * (n - 1),
        "angle_increment": step,
        "time_increment": 0.0,
        "scan_time": 0.0,
        "range_min": 0.0,
        "range_max": float(scan.max_range),
        "ranges": np.asarray(scan.ranges, dtype=np.float32).tolist(),
        "intensities": [],
    }


def scan_of(msg: Any, yaw: float) -> LidarScan:
    """The :class:`~uvnav.sensors.observation.LidarScan` of a decoded ``LaserScan`` taken at
    heading ``yaw`` [rad] (the scanner at the robot's centre, facing its heading): world-frame
    angles; a range outside ``[range_min, range_max)`` or not finite is no hit (``range_max``)."""
    r = np.asarray(msg.ranges, dtype=float)
    n = len(r)
    rel = float(msg.angle_min) + float(msg.angle_increment) * np.arange(n)
    angles = np.array([wrap_scalar(yaw + a) for a in rel.tolist()]).reshape(n)
    top = float(msg.range_max)
    valid = np.isfinite(r) & (r >= float(msg.range_min)) & (r < top)
    return LidarScan(angles=angles, ranges=np.where(valid, r, top), max_range=top)


def marker(ns: str, ident: int, kind: int, t: float, colour: str, **fields: Any) -> dict[str, Any]:
    """One ``visualization_msgs/Marker`` in ``map`` (added, lasting until replaced)."""
    return {
        "header": header(t, "map"),
        "ns": ns,
        "id": ident,
        "type": kind,
        "action": ADD,
        "pose": pose(0.0, 0.0, 0.0),
        "color": COLOURS[colour],
        "frame_locked": False,
        **fields,
    }


def disc_marker(ns: str, ident: int, centre: FloatArray, radius: float, t: float,
                colour: str) -> dict[str, Any]:  # fmt: skip
    """A disc of ``radius`` [m] at ``centre`` as an upright cylinder."""
    d = 2.0 * float(radius)
    at = pose(float(centre[0]), float(centre[1]), 0.0)
    at["position"]["z"] = 0.5 * HEIGHT
    return marker(ns, ident, CYLINDER, t, colour, pose=at, scale={"x": d, "y": d, "z": HEIGHT})


def polygon_marker(ns: str, ident: int, outline: FloatArray, t: float) -> dict[str, Any]:
    """A polygon's world outline (m, 2) as a closed line strip."""
    pts = [{"x": float(p[0]), "y": float(p[1]), "z": 0.0} for p in outline]
    return marker(
        ns, ident, LINE_STRIP, t, "body", points=[*pts, pts[0]] if pts else [],
        scale={"x": LINE_WIDTH, "y": 0.0, "z": 0.0},
    )  # fmt: skip


def body_markers(field: ObstacleField, t: float, count: int | None = None) -> list[dict[str, Any]]:
    """The present bodies of ``field`` (its first ``count``, default all) in namespace
    ``bodies``, each with its index as id: discs as cylinders, polygons as line strips."""
    k = len(field) if count is None else count
    radii = np.asarray(field.radii, dtype=float)
    present = field.present
    polygons = field.polygons
    out = []
    for j in range(k):
        if present is not None and not present[j]:
            continue
        outline = polygons[j]
        if outline is None:
            out.append(disc_marker("bodies", j, field.centres[j], float(radii[j]), t, "body"))
        else:
            out.append(polygon_marker("bodies", j, np.asarray(outline, dtype=float), t))
    return out


def marker_array(t: float, markers: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """A ``MarkerArray`` that first deletes every marker shown, then adds ``markers`` (bodies
    that left the scene disappear)."""
    clear = {"header": header(t, "map"), "ns": "", "id": 0, "type": 0, "action": DELETEALL}
    return {"markers": [clear, *markers]}
