"""The ROS 2 messages the node speaks, as Cyclone DDS types (``cyclonedds.idl.IdlStruct``).

ROS 2 maps a message ``pkg/msg/Name`` to the DDS type ``pkg::msg::dds_::Name_`` and a topic
``/name`` to the DDS topic ``rt/name`` (the ``rmw_cyclonedds`` naming); the fields below follow
the ``.msg`` definitions member for member, in their order and with their IDL types, so the
plain CDR (XCDR1, little-endian) a ROS 2 node writes is what these types read and write:

* ``builtin_interfaces/Time``: ``int32 sec``, ``uint32 nanosec``;
* ``std_msgs/Header``: ``Time stamp``, ``string frame_id``;
* ``sensor_msgs/LaserScan``: ``Header header``, ``float32 angle_min, angle_max,
  angle_increment, time_increment, scan_time, range_min, range_max``, ``float32[] ranges,
  intensities``;
* ``geometry_msgs``: ``Vector3`` / ``Point`` (``float64 x, y, z``), ``Quaternion``
  (``float64 x, y, z, w``), ``Pose`` (``Point position``, ``Quaternion orientation``),
  ``PoseWithCovariance`` (``Pose pose``, ``float64[36] covariance``), ``Twist`` (``Vector3
  linear, angular``), ``TwistWithCovariance`` (``Twist twist``, ``float64[36] covariance``),
  ``PoseStamped`` (``Header header``, ``Pose pose``);
* ``nav_msgs/Odometry``: ``Header header``, ``string child_frame_id``, ``PoseWithCovariance
  pose``, ``TwistWithCovariance twist``.

Importing this module needs the ``cyclonedds`` package (the ``ros2`` extra).
"""

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import array, float32, float64, int32, sequence, uint32

if TYPE_CHECKING:  # the type checker sees the Python values the IDL types hold
    Float32Seq = list[float]
    Float64x36 = list[float]
else:
    Float32Seq = sequence[float32]
    Float64x36 = array[float64, 36]


def _zeros36() -> list[float]:
    return [0.0] * 36


@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    """``builtin_interfaces/msg/Time``: seconds and nanoseconds."""

    sec: int32 = 0
    nanosec: uint32 = 0


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    """``std_msgs/msg/Header``: the stamp and the frame of a message."""

    stamp: Time = field(default_factory=Time)
    frame_id: str = ""


@dataclass
class LaserScan(IdlStruct, typename="sensor_msgs::msg::dds_::LaserScan_"):
    """``sensor_msgs/msg/LaserScan``: ranges [m] of beams ``angle_min + k angle_increment``
    [rad] in the scanner's frame."""

    header: Header = field(default_factory=Header)
    angle_min: float32 = 0.0
    angle_max: float32 = 0.0
    angle_increment: float32 = 0.0
    time_increment: float32 = 0.0
    scan_time: float32 = 0.0
    range_min: float32 = 0.0
    range_max: float32 = 0.0
    ranges: Float32Seq = field(default_factory=list)
    intensities: Float32Seq = field(default_factory=list)


@dataclass
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    """``geometry_msgs/msg/Vector3``."""

    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


@dataclass
class Point(IdlStruct, typename="geometry_msgs::msg::dds_::Point_"):
    """``geometry_msgs/msg/Point``."""

    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


@dataclass
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    """``geometry_msgs/msg/Quaternion`` (the identity by default, as in ROS 2)."""

    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0
    w: float64 = 1.0


@dataclass
class Pose(IdlStruct, typename="geometry_msgs::msg::dds_::Pose_"):
    """``geometry_msgs/msg/Pose``."""

    position: Point = field(default_factory=Point)
    orientation: Quaternion = field(default_factory=Quaternion)


@dataclass
class PoseWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovariance_"):
    """``geometry_msgs/msg/PoseWithCovariance``."""

    pose: Pose = field(default_factory=Pose)
    covariance: Float64x36 = field(default_factory=_zeros36)


@dataclass
class Twist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    """``geometry_msgs/msg/Twist``: linear [m/s] and angular [rad/s] velocity."""

    linear: Vector3 = field(default_factory=Vector3)
    angular: Vector3 = field(default_factory=Vector3)


@dataclass
class TwistWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::TwistWithCovariance_"):
    """``geometry_msgs/msg/TwistWithCovariance``."""

    twist: Twist = field(default_factory=Twist)
    covariance: Float64x36 = field(default_factory=_zeros36)


@dataclass
class PoseStamped(IdlStruct, typename="geometry_msgs::msg::dds_::PoseStamped_"):
    """``geometry_msgs/msg/PoseStamped``."""

    header: Header = field(default_factory=Header)
    pose: Pose = field(default_factory=Pose)


@dataclass
class Odometry(IdlStruct, typename="nav_msgs::msg::dds_::Odometry_"):
    """``nav_msgs/msg/Odometry``: the pose in ``header.frame_id`` and the twist in
    ``child_frame_id`` (the robot's frame)."""

    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    pose: PoseWithCovariance = field(default_factory=PoseWithCovariance)
    twist: TwistWithCovariance = field(default_factory=TwistWithCovariance)
