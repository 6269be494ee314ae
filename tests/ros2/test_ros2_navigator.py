"""The node's decisions without DDS: the safe stop (no goal, no odometry, no scan, stale scan,
goal reached, a law that raises), commands toward the goal, and the observation the law reads
(the scan's bodies with estimated velocities, perceived once per scan)."""

from __future__ import annotations

import math
from typing import Any

import pytest

pytest.importorskip("cyclonedds")

from ros2_world import goal_pose, laser_scan, odometry

from uvnav.ros2.msgs import Twist
from uvnav.ros2.navigator import Navigator, RobotConfig
from uvnav.sensors.observation import Observation

ZERO = Twist()
POSE = (0.0, 0.0, 0.5)


def _ready(law: str = "straight-holonomic-v1", **params: Any) -> Navigator:
    nav = Navigator(law, params, RobotConfig(scan_timeout=0.5))
    nav.on_goal(goal_pose(4.0, 0.0), 0.0)
    nav.on_odom(odometry(POSE), 0.0)
    nav.on_scan(laser_scan(POSE, []), 0.0)
    return nav


def _world(t: Twist, yaw: float) -> tuple[float, float]:
    c, s = math.cos(yaw), math.sin(yaw)
    return c * t.linear.x - s * t.linear.y, s * t.linear.x + c * t.linear.y


def test_stands_still_until_goal_odometry_and_scan_have_arrived() -> None:
    nav = Navigator("straight-holonomic-v1", {}, RobotConfig())
    assert nav.decide(0.0) == ZERO and nav.status == "waiting for a goal"
    nav.on_goal(goal_pose(4.0, 0.0), 0.0)
    assert nav.decide(0.1) == ZERO and nav.status == "stopped: no odometry yet"
    nav.on_odom(odometry(POSE), 0.1)
    assert nav.decide(0.2) == ZERO and nav.status.startswith("stopped: no scan")
    nav.on_scan(laser_scan(POSE, []), 0.2)
    twist = nav.decide(0.25)
    assert nav.status == "driving"
    assert _world(twist, POSE[2]) == pytest.approx((1.0, 0.0))  # V_max toward the goal


def test_a_stale_scan_stops_the_robot_and_a_new_one_restarts_it() -> None:
    nav = _ready()
    assert nav.decide(0.5) != ZERO
    assert nav.decide(0.51) == ZERO and nav.status == "stopped: no scan for 0.5 s"
    nav.on_scan(laser_scan(POSE, []), 0.6)
    assert nav.decide(0.6) != ZERO and nav.status == "driving"


def test_the_goal_reached_stops_the_robot_and_a_new_goal_moves_it() -> None:
    nav = _ready()
    at_goal = (3.85, 0.05, 0.5)
    nav.on_odom(odometry(at_goal), 0.1)
    assert nav.decide(0.1) == ZERO and nav.status == "goal reached"
    nav.on_goal(goal_pose(0.0, 3.0), 0.2)
    twist = nav.decide(0.2)
    vx, vy = _world(twist, at_goal[2])
    assert nav.status == "driving" and math.atan2(vy, vx) == pytest.approx(
        math.atan2(3.0 - 0.05, -3.85)
    )


def test_a_law_that_raises_stops_the_robot_and_the_node_keeps_deciding(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    nav = _ready()
    act = nav.law.act

    def broken(obs: Observation) -> Any:
        raise RuntimeError("singular matrix")

    monkeypatch.setattr(nav.law, "act", broken)
    assert nav.decide(0.1) == ZERO
    assert nav.status == "stopped: the law raised RuntimeError: singular matrix"
    monkeypatch.setattr(nav.law, "act", act)
    assert nav.decide(0.2) != ZERO and nav.status == "driving"


def test_a_unicycle_law_turns_toward_the_goal() -> None:
    nav = _ready("straight-v1")
    twist = nav.decide(0.1)
    assert twist.linear.y == 0.0 and twist.angular.z < 0.0  # goal at bearing -0.5 rad
    assert twist.linear.x >= 0.0


def test_the_law_reads_the_scans_bodies_with_estimated_velocities(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    nav = _ready("zhang2019-holonomic-v2")
    seen: list[Observation] = []
    act = nav.law.act

    def spy(obs: Observation) -> Any:
        seen.append(obs)
        return act(obs)

    monkeypatch.setattr(nav.law, "act", spy)
    for k in range(3):  # a disc of radius 0.3 moving at (0, 1) m/s, seen every 0.1 s
        t = 0.1 * k
        nav.on_scan(laser_scan(POSE, [(2.0, -0.5 + t, 0.3)]), t)
        nav.decide(t)
    nav.decide(0.25)  # between two scans: the last scan's bodies, the robot's time now
    for obs in seen:
        assert len(obs.obstacles) == 1
    rd = seen[2].obstacles[0]
    assert rd.velocity_source == "estimated"
    assert rd.centre == pytest.approx((2.0, -0.3), abs=0.06)
    assert rd.velocity == pytest.approx((0.0, 1.0), abs=0.15)
    assert seen[3].time == 0.25 and seen[3].obstacles == seen[2].obstacles
