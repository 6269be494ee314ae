"""A ROS 2 node without a ROS installation: a uvnav law on DDS (Cyclone DDS's Python binding).

The node joins DDS domain ``domain`` as a ROS 2 node would (``rmw_cyclonedds``'s names: a ROS 2
topic ``/name`` is the DDS topic ``rt/name``, a message ``pkg/msg/Name`` the DDS type
``pkg::msg::dds_::Name_``, :mod:`uvnav.ros2.msgs`) and

* reads ``rt/scan`` (``sensor_msgs/LaserScan``) with ROS 2's sensor-data QoS (best effort, keep
  last 5, volatile), ``rt/odom`` (``nav_msgs/Odometry``) and ``rt/goal_pose``
  (``geometry_msgs/PoseStamped``) with ROS 2's default QoS (reliable, keep last 10, volatile);
* writes ``rt/cmd_vel`` (``geometry_msgs/Twist``, default QoS) at every decision, ``rate``
  times a second: the :class:`~uvnav.ros2.navigator.Navigator`'s command, a zero ``Twist`` on a
  safe stop, and a zero ``Twist`` when it stops.

One thread: each period the node takes what arrived, decides, writes, and sleeps to the next
decision time.  A change of status (waiting, driving, stopped and why) is one line to ``log``.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.internal import InvalidSample
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

from uvnav.ros2.msgs import LaserScan, Odometry, PoseStamped, Twist
from uvnav.ros2.navigator import Navigator

#: ROS 2's ``rmw_qos_profile_sensor_data``
SENSOR_QOS = Qos(
    Policy.Reliability.BestEffort, Policy.History.KeepLast(5), Policy.Durability.Volatile
)
#: ROS 2's ``rmw_qos_profile_default``
DEFAULT_QOS = Qos(
    Policy.Reliability.Reliable(duration(milliseconds=100)),
    Policy.History.KeepLast(10),
    Policy.Durability.Volatile,
)
#: DDS topic names of the ROS 2 topics ``/scan``, ``/odom``, ``/goal_pose``, ``/cmd_vel``
SCAN_TOPIC, ODOM_TOPIC, GOAL_TOPIC, CMD_TOPIC = "rt/scan", "rt/odom", "rt/goal_pose", "rt/cmd_vel"


class Ros2Node:
    """The DDS side of the node (module docstring): readers, a writer and the decision loop.

    Args:
        navigator: what decides.
        domain: the DDS domain id (ROS 2's ``ROS_DOMAIN_ID``).
        rate: decisions per second [Hz].
        log: where a change of status is written (one line each).
    """

    def __init__(
        self, navigator: Navigator, domain: int, rate: float, log: Callable[[str], None]
    ) -> None:
        self.navigator = navigator
        self.period = 1.0 / rate
        self.log = log
        self.participant = DomainParticipant(domain)
        dp = self.participant
        self.scan_reader: DataReader[Any] = DataReader(
            dp, Topic(dp, SCAN_TOPIC, LaserScan), qos=SENSOR_QOS
        )
        self.odom_reader: DataReader[Any] = DataReader(
            dp, Topic(dp, ODOM_TOPIC, Odometry), qos=DEFAULT_QOS
        )
        self.goal_reader: DataReader[Any] = DataReader(
            dp, Topic(dp, GOAL_TOPIC, PoseStamped), qos=DEFAULT_QOS
        )
        self.cmd_writer: DataWriter[Any] = DataWriter(
            dp, Topic(dp, CMD_TOPIC, Twist), qos=DEFAULT_QOS
        )
        self._t0 = time.monotonic()
        self._status = ""

    def now(self) -> float:
        """Seconds since the node started (a monotonic clock)."""
        return time.monotonic() - self._t0

    def step(self) -> Twist:
        """Take what arrived, decide, write the command; returns it."""
        nav, now = self.navigator, self.now()
        for msg in _take_all(self.goal_reader):
            nav.on_goal(msg, now)
        for msg in _take_all(self.odom_reader):
            nav.on_odom(msg, now)
        scans = _take_all(self.scan_reader)
        if scans:
            nav.on_scan(scans[-1], now)
        twist = nav.decide(now)
        self.cmd_writer.write(twist)
        if nav.status != self._status:
            self._status = nav.status
            self.log(nav.status)
        return twist

    def spin(self, should_stop: Callable[[], bool], duration_s: float = 0.0) -> None:
        """Decide every period until ``should_stop()`` (or for ``duration_s`` [s] when it is
        positive); a zero ``Twist`` is the last command written, however the loop ends, and
        the node waits up to a second for the readers to acknowledge it."""
        next_t = self.now()
        try:
            while not should_stop() and (duration_s <= 0 or self.now() < duration_s):
                self.step()
                next_t += self.period
                time.sleep(max(0.0, next_t - self.now()))
                next_t = max(next_t, self.now() - self.period)  # never catch up in a burst
        finally:
            self.cmd_writer.write(Twist())
            self.cmd_writer.wait_for_acks(duration(seconds=1))


def _take_all(reader: DataReader[Any]) -> list[Any]:
    """Every sample waiting in ``reader`` (valid data only), oldest first."""
    return [s for s in reader.take(N=100) if not isinstance(s, InvalidSample)]
