"""Test helpers: ROS 2 messages of a robot and the discs around it (uvnav's own exact lidar)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from uvnav.obstacles.obstacle import Obstacle, ObstacleField
from uvnav.ros2.convert import quaternion_of
from uvnav.ros2.msgs import LaserScan, Odometry, Point, PoseStamped, Vector3
from uvnav.sensors.exact import lidar_scan

#: Cyclone DDS on the loopback interface only, peers found by unicast
LOOPBACK = (
    '<CycloneDDS xmlns="https://cdds.io/config"><Domain Id="any"><General>'
    '<Interfaces><NetworkInterface name="lo"/></Interfaces>'
    "<AllowMulticast>false</AllowMulticast></General>"
    "<Discovery><ParticipantIndex>auto</ParticipantIndex><MaxAutoParticipantIndex>20"
    '</MaxAutoParticipantIndex><Peers><Peer address="127.0.0.1"/></Peers></Discovery>'
    "</Domain></CycloneDDS>"
)

N_BEAMS = 360
MAX_RANGE = 5.0


def laser_scan(pose: Sequence[float], discs: Sequence[tuple[float, float, float]]) -> LaserScan:
    """The scan of ``discs`` ``(x, y, radius)`` from ``pose`` ``[x, y, yaw]`` as a 360-beam
    ``LaserScan`` in the robot's frame (no return: ``inf``, as ROS 2 drivers report it)."""
    field = ObstacleField.from_obstacles([Obstacle.moving_disc((x, y), r) for x, y, r in discs])
    scan = lidar_scan(np.asarray(pose, dtype=float), field, n_rays=N_BEAMS, max_range=MAX_RANGE)
    ranges = np.where(scan.ranges >= MAX_RANGE, math.inf, scan.ranges)
    inc = 2.0 * math.pi / N_BEAMS
    return LaserScan(
        angle_min=-math.pi, angle_max=math.pi - inc, angle_increment=inc, scan_time=0.1,
        range_min=0.05, range_max=MAX_RANGE, ranges=[float(r) for r in ranges],
    )  # fmt: skip


def odometry(pose: Sequence[float], body_velocity: Sequence[float] = (0.0, 0.0)) -> Odometry:
    """Odometry at ``pose`` ``[x, y, yaw]`` moving at ``body_velocity`` (robot frame) [m/s]."""
    odom = Odometry(child_frame_id="base_link")
    odom.header.frame_id = "odom"
    odom.pose.pose.position = Point(x=float(pose[0]), y=float(pose[1]))
    odom.pose.pose.orientation = quaternion_of(float(pose[2]))
    odom.twist.twist.linear = Vector3(x=float(body_velocity[0]), y=float(body_velocity[1]))
    return odom


def goal_pose(x: float, y: float) -> PoseStamped:
    """A goal at ``(x, y)`` in the odometry's frame."""
    msg = PoseStamped()
    msg.header.frame_id = "odom"
    msg.pose.position = Point(x=x, y=y)
    return msg
