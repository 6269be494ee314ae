"""ROS 2 messages to what a law reads: quaternion -> yaw, LaserScan -> LidarScan in the world
frame, a law's command -> Twist in the robot's frame."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("cyclonedds")

from uvnav.dynamics.omni import VelocityCommand
from uvnav.dynamics.unicycle import UnicycleCommand
from uvnav.ros2.convert import lidar_of, pose_of, quaternion_of, speed_of, twist_of, yaw_of
from uvnav.ros2.msgs import LaserScan, Odometry, Quaternion, Vector3


@pytest.mark.parametrize("yaw", [0.0, 0.3, -1.2, 2.9, -3.1, math.pi])
def test_yaw_of_a_rotation_about_z(yaw: float) -> None:
    got = yaw_of(quaternion_of(yaw))
    assert math.isclose(math.remainder(got - yaw, 2 * math.pi), 0.0, abs_tol=1e-12)


def test_yaw_ignores_the_sign_of_the_quaternion_and_reads_a_tilted_one() -> None:
    q = quaternion_of(0.7)
    assert yaw_of(Quaternion(-q.x, -q.y, -q.z, -q.w)) == pytest.approx(0.7)
    # yaw 0.5 after a roll of 0.2 (q = q_yaw * q_roll): the yaw survives the roll
    cr, sr, cy, sy = math.cos(0.1), math.sin(0.1), math.cos(0.25), math.sin(0.25)
    tilted = Quaternion(x=cy * sr, y=sy * sr, z=sy * cr, w=cy * cr)
    assert yaw_of(tilted) == pytest.approx(0.5)


def test_pose_and_speed_of_odometry() -> None:
    odom = Odometry()
    odom.pose.pose.position.x, odom.pose.pose.position.y = 2.0, -1.0
    odom.pose.pose.orientation = quaternion_of(1.0)
    odom.twist.twist.linear = Vector3(0.3, 0.4, 0.0)
    np.testing.assert_allclose(pose_of(odom), [2.0, -1.0, 1.0])
    assert speed_of(odom) == pytest.approx(0.5)


def test_scan_angles_are_world_angles_and_bad_ranges_are_no_return() -> None:
    msg = LaserScan(angle_min=-0.5, angle_max=0.5, angle_increment=0.25, range_min=0.1,
                    range_max=4.0,
                    ranges=[1.0, math.nan, math.inf, 4.5, 0.05])  # fmt: skip
    scan = lidar_of(msg, yaw=3.0)
    expected = [math.remainder(3.0 + a, 2 * math.pi) for a in (-0.5, -0.25, 0.0, 0.25, 0.5)]
    np.testing.assert_allclose(scan.angles, expected, atol=1e-7)
    assert np.all((scan.angles > -math.pi) & (scan.angles <= math.pi))
    np.testing.assert_array_equal(scan.ranges, [1.0, 4.0, 4.0, 4.0, 4.0])
    assert scan.max_range == 4.0


def test_a_full_turn_of_float32_increments_is_exact() -> None:
    n = 100  # float32(2 pi / 100) misses the turn by 3e-7 rad
    msg = LaserScan(angle_min=-math.pi, angle_increment=float(np.float32(2 * math.pi / n)),
                    range_max=5.0, ranges=[5.0] * n)  # fmt: skip
    scan = lidar_of(msg, yaw=0.0)
    step = np.remainder(np.diff(scan.angles), 2 * math.pi)
    np.testing.assert_allclose(step, 2 * math.pi / n, rtol=1e-9)


def test_unicycle_command_is_forward_speed_and_turn_rate() -> None:
    t = twist_of(UnicycleCommand(0.6, -0.4), yaw=1.0)
    assert (t.linear.x, t.linear.y, t.linear.z) == (0.6, 0.0, 0.0)
    assert (t.angular.x, t.angular.y, t.angular.z) == (0.0, 0.0, -0.4)


@pytest.mark.parametrize("yaw", [0.0, 0.5, -2.0])
def test_holonomic_command_is_the_world_velocity_in_the_robot_frame(yaw: float) -> None:
    t = twist_of(VelocityCommand(0.3, -0.8), yaw=yaw)
    world = (
        math.cos(yaw) * t.linear.x - math.sin(yaw) * t.linear.y,
        math.sin(yaw) * t.linear.x + math.cos(yaw) * t.linear.y,
    )
    assert world == pytest.approx((0.3, -0.8))
    assert t.angular.z == 0.0
