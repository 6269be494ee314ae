"""The ROS 2 messages as Cyclone DDS types: the DDS type names ROS 2 uses, and the bytes a ROS 2
node writes (rosbags' CDR serializer of the ROS 2 Humble definitions, an independent reading of
the ``.msg`` files) read back field for field and written back byte for byte."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

pytest.importorskip("cyclonedds")

from uvnav.ros2 import msgs

F32 = np.float32


def test_type_names_follow_the_ros2_dds_mapping() -> None:
    expected = {
        msgs.Time: "builtin_interfaces::msg::dds_::Time_",
        msgs.Header: "std_msgs::msg::dds_::Header_",
        msgs.LaserScan: "sensor_msgs::msg::dds_::LaserScan_",
        msgs.Odometry: "nav_msgs::msg::dds_::Odometry_",
        msgs.PoseStamped: "geometry_msgs::msg::dds_::PoseStamped_",
        msgs.Twist: "geometry_msgs::msg::dds_::Twist_",
        msgs.PoseWithCovariance: "geometry_msgs::msg::dds_::PoseWithCovariance_",
        msgs.TwistWithCovariance: "geometry_msgs::msg::dds_::TwistWithCovariance_",
    }
    for cls, name in expected.items():
        assert cls.__idl_typename__ == name


def _ros(store: Any, name: str, **fields: Any) -> Any:
    return store.types[name](**fields)


@pytest.fixture(scope="module")
def store() -> Any:
    typesys = pytest.importorskip("rosbags.typesys")
    return typesys.get_typestore(typesys.Stores.ROS2_HUMBLE)


def _header(store: Any) -> Any:
    stamp = _ros(store, "builtin_interfaces/msg/Time", sec=12, nanosec=345)
    return _ros(store, "std_msgs/msg/Header", stamp=stamp, frame_id="base_link")


def test_a_ros2_laser_scan_reads_and_writes_back_byte_for_byte(store: Any) -> None:
    ros = _ros(
        store, "sensor_msgs/msg/LaserScan", header=_header(store), angle_min=F32(-3.0),
        angle_max=F32(3.0), angle_increment=F32(0.25), time_increment=F32(0.001),
        scan_time=F32(0.1), range_min=F32(0.05), range_max=F32(8.0),
        ranges=np.array([1.5, np.inf, 0.25], dtype=F32),
        intensities=np.array([7.0, 8.0], dtype=F32),
    )  # fmt: skip
    wire = bytes(store.serialize_cdr(ros, "sensor_msgs/msg/LaserScan"))
    got = msgs.LaserScan.deserialize(wire)
    assert (got.header.stamp.sec, got.header.stamp.nanosec) == (12, 345)
    assert got.header.frame_id == "base_link"
    assert (got.angle_min, got.angle_max, got.angle_increment) == (-3.0, 3.0, 0.25)
    assert (got.range_min, got.range_max) == (F32(0.05), 8.0)
    assert got.ranges == [1.5, np.inf, 0.25] and got.intensities == [7.0, 8.0]
    assert got.serialize() == wire


def _pose(store: Any, x: float, y: float, qz: float, qw: float) -> Any:
    point = _ros(store, "geometry_msgs/msg/Point", x=x, y=y, z=0.5)
    quat = _ros(store, "geometry_msgs/msg/Quaternion", x=0.0, y=0.0, z=qz, w=qw)
    return _ros(store, "geometry_msgs/msg/Pose", position=point, orientation=quat)


def _vec(store: Any, x: float, y: float, z: float) -> Any:
    return _ros(store, "geometry_msgs/msg/Vector3", x=x, y=y, z=z)


def test_a_ros2_odometry_reads_and_writes_back_byte_for_byte(store: Any) -> None:
    cov = np.arange(36, dtype=np.float64)
    twist = _ros(store, "geometry_msgs/msg/Twist", linear=_vec(store, 0.4, -0.1, 0.0),
                 angular=_vec(store, 0.0, 0.0, 0.7))  # fmt: skip
    ros = _ros(
        store, "nav_msgs/msg/Odometry", header=_header(store), child_frame_id="base_link",
        pose=_ros(store, "geometry_msgs/msg/PoseWithCovariance",
                  pose=_pose(store, 1.5, -2.0, 0.6, 0.8), covariance=cov),
        twist=_ros(store, "geometry_msgs/msg/TwistWithCovariance", twist=twist,
                   covariance=2 * cov),
    )  # fmt: skip
    wire = bytes(store.serialize_cdr(ros, "nav_msgs/msg/Odometry"))
    got = msgs.Odometry.deserialize(wire)
    assert got.child_frame_id == "base_link"
    p = got.pose.pose
    assert (p.position.x, p.position.y, p.position.z) == (1.5, -2.0, 0.5)
    assert (p.orientation.z, p.orientation.w) == (0.6, 0.8)
    assert list(got.pose.covariance) == cov.tolist()
    assert list(got.twist.covariance) == (2 * cov).tolist()
    t = got.twist.twist
    assert (t.linear.x, t.linear.y, t.angular.z) == (0.4, -0.1, 0.7)
    assert got.serialize() == wire


def test_pose_stamped_and_twist_read_and_write_back_byte_for_byte(store: Any) -> None:
    ros_goal = _ros(store, "geometry_msgs/msg/PoseStamped", header=_header(store),
                    pose=_pose(store, 3.0, 4.0, 0.0, 1.0))  # fmt: skip
    wire = bytes(store.serialize_cdr(ros_goal, "geometry_msgs/msg/PoseStamped"))
    goal = msgs.PoseStamped.deserialize(wire)
    assert (goal.pose.position.x, goal.pose.position.y) == (3.0, 4.0)
    assert goal.serialize() == wire
    ours = msgs.Twist(linear=msgs.Vector3(0.5, -0.25, 0.0), angular=msgs.Vector3(0.0, 0.0, 1.5))
    ros_twist = store.deserialize_cdr(ours.serialize(), "geometry_msgs/msg/Twist")
    assert (ros_twist.linear.x, ros_twist.linear.y, ros_twist.angular.z) == (0.5, -0.25, 1.5)
