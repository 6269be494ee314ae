"""What the ROS 2 node decides, without DDS: the latest messages in, a ``Twist`` out.

A :class:`Navigator` holds one 2D law (a unicycle or a holonomic law of the registry), the
robot's limits and the latest scan, odometry and goal.  At each decision it builds the
:class:`~uvnav.sensors.observation.Observation` the law reads, from the scan alone: the scan's
bodies (:mod:`uvnav.sensors.scan_bodies`) with velocities estimated by finite differences,
through the same :class:`~uvnav.sensors.suite2d.Sensors2D` the simulated worlds use with
``bodies: lidar``.  A scan is perceived once, at the time it arrived (the association and the
finite differences run on arrival times); a decision between two scans reads the bodies of the
last one with the robot's pose and speed now.

The safe stop: the command is a zero ``Twist`` while there is no goal, no odometry or no scan
newer than ``scan_timeout``, once the robot is within ``goal_tolerance`` of the goal, and at a
decision where the law raises.  :attr:`Navigator.status` says which, in one line.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from uvnav.controllers.base import make_law
from uvnav.dynamics.unicycle import UnicycleSpec
from uvnav.dynamics.vehicles import Vehicle2D, make_vehicle
from uvnav.geometry.angles import FloatArray
from uvnav.obstacles.obstacle import ObstacleField
from uvnav.ros2.convert import goal_of, lidar_of, pose_of, speed_of, twist_of
from uvnav.ros2.msgs import LaserScan, Odometry, PoseStamped, Twist
from uvnav.ros2.params import law_vehicle
from uvnav.sensors.config import LidarConfig, SensingConfig
from uvnav.sensors.observation import LidarScan, Observation
from uvnav.sensors.suite2d import Sensors2D


@dataclass(frozen=True)
class RobotConfig:
    """The robot the node drives and when it stops.

    Attributes:
        v_max: largest speed [m/s].
        u_max: largest turn rate [rad/s] (a unicycle's).
        radius: radius of the robot's disc [m].
        goal_tolerance: the goal is reached within this distance [m].
        sensing_range: bodies farther than this are not given to the law [m].
        scan_timeout: stop when the newest scan is older than this [s].
        seed: seed of the law's and the sensors' generators.
    """

    v_max: float = 1.0
    u_max: float = 1.0
    radius: float = 0.3
    goal_tolerance: float = 0.2
    sensing_range: float = 5.0
    scan_timeout: float = 0.5
    seed: int = 0


class _ReceivedScan(Sensors2D):
    """:class:`Sensors2D` whose lidar is the robot's own: :meth:`scan` is the scan received."""

    received: LidarScan | None = None

    def scan(self, pose: FloatArray, field: ObstacleField) -> LidarScan:
        assert self.received is not None
        return self.received


class Navigator:
    """One law on one robot, fed with ROS 2 messages (module docstring).

    Args:
        law: a registered unicycle or holonomic law.
        params: the law's parameters.
        robot: the robot's limits and the stop conditions.
    """

    def __init__(self, law: str, params: dict[str, Any], robot: RobotConfig) -> None:
        kind = law_vehicle(law)
        self.law = make_law(law, **params)
        self.robot = robot
        spec = UnicycleSpec(v_max=robot.v_max, u_max=robot.u_max, radius=robot.radius)
        self.vehicle: Vehicle2D = make_vehicle(kind, spec)
        self.holonomic = kind == "holonomic"
        rng = np.random.default_rng(robot.seed)
        self._law_rng, sense_rng = rng.spawn(2)
        sensing = SensingConfig(
            sensing_range=robot.sensing_range, velocities="estimated",
            lidar=LidarConfig(max_range=robot.sensing_range), bodies="lidar",
        )  # fmt: skip
        self.sensors = _ReceivedScan(sensing, sense_rng)
        self.goal: FloatArray | None = None
        self.odom: Odometry | None = None
        self.scan: LaserScan | None = None
        self.scan_time = -math.inf
        self._perceived = -math.inf
        self._obs: Observation | None = None
        self._heading: float | None = None
        self.status = "waiting for a goal"

    def on_scan(self, msg: LaserScan, now: float) -> None:
        """A scan arrived at ``now`` [s]."""
        self.scan, self.scan_time = msg, now

    def on_odom(self, msg: Odometry, now: float) -> None:
        """Odometry arrived at ``now`` [s]."""
        self.odom = msg

    def on_goal(self, msg: PoseStamped, now: float) -> None:
        """A goal arrived: a new goal point resets the law and the perception (a new run)."""
        goal = goal_of(msg)
        if not np.all(np.isfinite(goal)):
            return
        if self.goal is not None and np.array_equal(goal, self.goal):
            return
        self.goal = goal
        self.law.reset(self.vehicle.spec, goal, self._law_rng)
        self.sensors.reset(False)
        self._perceived, self._obs = -math.inf, None

    def decide(self, now: float) -> Twist:
        """The command at ``now`` [s]; :attr:`status` says why it is what it is."""
        why = self._stop_reason(now)
        if why is not None:
            self.status = why
            return Twist()
        assert self.odom is not None and self.goal is not None
        pose = pose_of(self.odom)
        obs = self._observe(now, pose)
        try:
            command, _ = self.vehicle.saturate(self.law.act(obs), float(obs.pose[2]))
            twist = twist_of(command, float(pose[2]))
        except Exception as exc:  # the law's failure stops the robot, never the node
            self.status = f"stopped: the law raised {type(exc).__name__}: {exc}"
            return Twist()
        self.status = "driving"
        return twist

    def _stop_reason(self, now: float) -> str | None:
        """Why the robot must stand still now, or ``None``."""
        if self.goal is None:
            return "waiting for a goal"
        if self.odom is None:
            return "stopped: no odometry yet"
        if now - self.scan_time > self.robot.scan_timeout:
            return f"stopped: no scan for {self.robot.scan_timeout:g} s"
        pose = pose_of(self.odom)
        if not np.all(np.isfinite(pose)):
            return "stopped: odometry pose is not finite"
        if math.dist(pose[:2], self.goal) <= self.robot.goal_tolerance:
            return "goal reached"
        return None

    def _observe(self, now: float, pose: FloatArray) -> Observation:
        """The law's observation at ``now``: the newest scan perceived once, at its arrival."""
        assert self.odom is not None and self.scan is not None and self.goal is not None
        speed = speed_of(self.odom)
        heading = self._law_heading(pose)
        law_pose = np.array((pose[0], pose[1], heading))
        if self._obs is None or self.scan_time > self._perceived:
            self.sensors.received = lidar_of(self.scan, float(pose[2]))
            self._obs = self.sensors.observe(
                self.scan_time, law_pose, speed, self.goal, exact=tuple, field=_no_field
            )
            self._perceived = self.scan_time
        return dataclasses.replace(self._obs, time=now, pose=law_pose, speed=speed)

    def _law_heading(self, pose: FloatArray) -> float:
        """The heading the law reads [rad]: a unicycle's yaw; for a holonomic robot the
        direction it moves in (its last one while it stands), as uvnav's holonomic vehicle
        reports it."""
        if not self.holonomic:
            return float(pose[2])
        assert self.odom is not None
        v = self.odom.twist.twist.linear
        if math.hypot(v.x, v.y) > 1e-6 or self._heading is None:
            self._heading = float(pose[2]) + math.atan2(v.y, v.x)
        return self._heading


def _no_field() -> ObstacleField:
    """No simulated bodies: the node's lidar is the robot's."""
    return ObstacleField.from_obstacles([])
