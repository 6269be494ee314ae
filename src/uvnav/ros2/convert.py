"""ROS 2 messages to what a uvnav law reads, and a law's command to a ``Twist``.

Frames: the odometry's pose is the robot's pose in the world (``odom``) frame, the goal is a
point of the same frame, and the scanner sits at the robot's centre looking along its heading
(the scan's ``frame_id`` is the robot's frame), so a beam's world angle is the robot's yaw plus
``angle_min + k angle_increment``.  Units: metres, seconds, radians.
"""

from __future__ import annotations

import math

import numpy as np

from uvnav.dynamics.omni import VelocityCommand
from uvnav.dynamics.unicycle import UnicycleCommand
from uvnav.geometry.angles import FloatArray, wrap_to_pi
from uvnav.ros2.msgs import LaserScan, Odometry, PoseStamped, Quaternion, Twist, Vector3
from uvnav.sensors.observation import LidarScan


def yaw_of(q: Quaternion) -> float:
    """The rotation about z [rad, in (-pi, pi]] of a unit quaternion (ZYX Euler yaw)."""
    siny = 2.0 * (q.w * q.z + q.x * q.y)
    cosy = 1.0 - 2.0 * (q.y * q.y + q.z * q.z)
    return math.atan2(siny, cosy)


def quaternion_of(yaw: float) -> Quaternion:
    """The unit quaternion of a rotation by ``yaw`` [rad] about z."""
    return Quaternion(z=math.sin(0.5 * yaw), w=math.cos(0.5 * yaw))


def pose_of(odom: Odometry) -> FloatArray:
    """The robot's ``[x, y, yaw]`` from its odometry."""
    p = odom.pose.pose
    return np.array((p.position.x, p.position.y, yaw_of(p.orientation)))


def speed_of(odom: Odometry) -> float:
    """The robot's planar speed [m/s] from its odometry's twist."""
    v = odom.twist.twist.linear
    return math.hypot(v.x, v.y)


def goal_of(msg: PoseStamped) -> FloatArray:
    """The goal point ``(x, y)`` [m] of a goal pose."""
    return np.array((msg.pose.position.x, msg.pose.position.y))


def _increment(msg: LaserScan) -> float:
    """The beam spacing [rad]; a full turn the float32 fields miss by rounding is made exact
    (so the perception sees the first and the last beam as neighbours)."""
    n, inc = len(msg.ranges), float(msg.angle_increment)
    if n > 1 and abs(abs(inc) * n - 2.0 * math.pi) < 1e-4:
        return math.copysign(2.0 * math.pi / n, inc)
    return inc


def lidar_of(msg: LaserScan, yaw: float) -> LidarScan:
    """The scan as uvnav's :class:`~uvnav.sensors.observation.LidarScan` from a robot at
    heading ``yaw`` [rad]: world-frame beam angles, and ``range_max`` (no return) for every
    range that is not finite or lies outside ``[range_min, range_max]``."""
    ranges = np.asarray(msg.ranges, dtype=float)
    rmax = float(msg.range_max)
    k = np.arange(len(ranges), dtype=float)
    angles = wrap_to_pi(yaw + float(msg.angle_min) + k * _increment(msg))
    valid = np.isfinite(ranges) & (ranges >= float(msg.range_min)) & (ranges <= rmax)
    return LidarScan(angles=angles, ranges=np.where(valid, ranges, rmax), max_range=rmax)


def twist_of(command: UnicycleCommand | VelocityCommand, yaw: float) -> Twist:
    """The ``Twist`` of a law's command for a robot at heading ``yaw`` [rad]: a unicycle's
    ``(v, u)`` as ``linear.x`` and ``angular.z``; a holonomic robot's world-frame velocity
    ``(vx, vy)`` as ``linear.x, linear.y`` in the robot's frame."""
    if isinstance(command, UnicycleCommand):
        return Twist(linear=Vector3(x=float(command.v)), angular=Vector3(z=float(command.u)))
    c, s = math.cos(yaw), math.sin(yaw)
    vx, vy = float(command.vx), float(command.vy)
    return Twist(linear=Vector3(x=c * vx + s * vy, y=-s * vx + c * vy))
