"""A small rosbag2 of a lidar robot passing a moving disc, written with ``rosbags`` (test helper).

The robot (a disc of radius 0.3 m) drives along a fixed path while a disc of radius 0.4 m
crosses it; at each decision a :class:`~uvnav.sensors.suite2d.Sensors2D` with lidar bodies
observes the scene, and the observation and its scan are kept: the scan is written as a
``sensor_msgs/msg/LaserScan`` (angles relative to the heading) beside the robot's
``nav_msgs/msg/Odometry``.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from uvnav.obstacles.bodies import DiscBody
from uvnav.obstacles.obstacle import FieldTemplate
from uvnav.sensors.config import LidarConfig, SensingConfig
from uvnav.sensors.observation import Observation
from uvnav.sensors.suite2d import Sensors2D

DT = 0.1
GOAL = np.array([6.0, 0.0])
N_RAYS = 180


def robot_state(t: float) -> tuple[np.ndarray, tuple[float, float, float]]:
    """The robot's pose and body-frame twist ``(vx, vy, wz)`` at ``t`` [s]: along x at
    0.8 m/s, weaving gently (heading and turn rate consistent)."""
    yaw = 0.2 * math.sin(0.5 * t)
    return np.array((0.8 * t, 0.0, yaw)), (0.8, 0.0, 0.1 * math.cos(0.5 * t))


def disc_at(t: float) -> tuple[np.ndarray, np.ndarray]:
    """The crossing disc's centre and velocity at ``t`` [s]."""
    v = np.array((-0.1, 0.6))
    return np.array((3.0, -2.0)) + v * t, v


def observations(steps: int) -> list[Observation]:
    """What a robot with lidar bodies observes at each of ``steps`` decisions."""
    config = SensingConfig(
        sensing_range=5.0, velocities="estimated",
        lidar=LidarConfig(n_rays=N_RAYS, max_range=5.0), bodies="lidar",
    )  # fmt: skip
    sensors = Sensors2D(config, np.random.default_rng(1))
    sensors.reset(oracle=False)
    template = FieldTemplate.from_bodies([DiscBody(0.4)])
    out = []
    for k in range(steps):
        t = k * DT
        pose, twist = robot_state(t)
        centre, vel = disc_at(t)
        field = template.field(centre[None, :], np.zeros(1), vel[None, :], np.zeros(1))
        out.append(sensors.observe(t, pose, math.hypot(twist[0], twist[1]), GOAL,
                                   lambda: (), lambda f=field: f))  # fmt: skip
    return out


def _stamp(ts: Any, t: float) -> Any:
    ns = round(t * 1e9)
    return ts.types["builtin_interfaces/msg/Time"](sec=ns // 10**9, nanosec=ns % 10**9)


def write_bag(path: Path, obs: list[Observation], storage: str = "sqlite3",
              scans: bool = True, odometry: bool = True) -> Path:  # fmt: skip
    """A rosbag2 at ``path`` with the odometry and the scans of ``obs`` (each odometry message
    just before its scan); ``scans``/``odometry`` False leave that topic's messages out (the
    topic is still declared)."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_JAZZY)
    T = ts.types
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    with Writer(path, version=9, storage_plugin=plugin) as writer:
        c_scan = writer.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        c_odom = writer.add_connection("/odom", "nav_msgs/msg/Odometry", typestore=ts)
        for o in obs:
            t = float(o.time)
            stamp = _stamp(ts, t)
            pose, (vx, vy, wz) = robot_state(t)
            header = T["std_msgs/msg/Header"](stamp=stamp, frame_id="odom")
            q = T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=math.sin(pose[2] / 2),
                                                  w=math.cos(pose[2] / 2))  # fmt: skip
            p = T["geometry_msgs/msg/Pose"](
                position=T["geometry_msgs/msg/Point"](x=pose[0], y=pose[1], z=0.0),
                orientation=q,
            )
            V3 = T["geometry_msgs/msg/Vector3"]
            tw = T["geometry_msgs/msg/Twist"](linear=V3(x=vx, y=vy, z=0.0),
                                              angular=V3(x=0.0, y=0.0, z=wz))  # fmt: skip
            odom = T["nav_msgs/msg/Odometry"](
                header=header, child_frame_id="base_link",
                pose=T["geometry_msgs/msg/PoseWithCovariance"](pose=p, covariance=np.zeros(36)),
                twist=T["geometry_msgs/msg/TwistWithCovariance"](twist=tw,
                                                                 covariance=np.zeros(36)),
            )  # fmt: skip
            ns = round(t * 1e9)
            if odometry:
                writer.write(c_odom, ns, ts.serialize_cdr(odom, "nav_msgs/msg/Odometry"))
            if scans:
                assert o.lidar is not None
                step = 2 * math.pi / N_RAYS
                scan = T["sensor_msgs/msg/LaserScan"](
                    header=T["std_msgs/msg/Header"](stamp=stamp, frame_id="base_link"),
                    angle_min=-math.pi, angle_max=-math.pi + step * (N_RAYS - 1),
                    angle_increment=step, time_increment=0.0, scan_time=0.0, range_min=0.0,
                    range_max=5.0, ranges=np.asarray(o.lidar.ranges, dtype=np.float32),
                    intensities=np.zeros(0, dtype=np.float32),
                )  # fmt: skip
                writer.write(c_scan, ns + 1, ts.serialize_cdr(scan, "sensor_msgs/msg/LaserScan"))
    return path
