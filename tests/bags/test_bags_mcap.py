"""An episode written as MCAP (``uvnav.bags.mcap``) and read back with the ``mcap`` reader and
``mcap-ros2-support``'s decoder: every step's pose, bodies, scan, command and mode are there,
under the declared ROS 2 schemas, stamped with the simulation time."""

from __future__ import annotations

import math
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

pytest.importorskip("mcap_ros2")
pytest.importorskip("rosbags")

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

from uvnav.bags.mcap import McapEpisode
from uvnav.scenarios.catalog import resolve
from uvnav.scenarios.episodes import run_scene
from uvnav.scenarios.loader import builtin_text

N_RAYS = 90
SCHEMAS = {
    "/tf": "tf2_msgs/msg/TFMessage",
    "/bodies": "visualization_msgs/msg/MarkerArray",
    "/odom": "nav_msgs/msg/Odometry",
    "/cmd_vel": "geometry_msgs/msg/Twist",
    "/mode": "std_msgs/msg/String",
    "/scan": "sensor_msgs/msg/LaserScan",
}


def _lidar_scene(tmp_path: Path) -> Path:
    """Fig. 2.7's scene (one polygon body) with a lidar on the robot."""
    data = yaml.safe_load(builtin_text("thesis-ch2-one-obstacle"))
    data["name"] = "one-obstacle-lidar"
    data["sensing"]["lidar"] = {"n_rays": N_RAYS, "max_range": 5.0}
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _read(path: Path) -> tuple[Any, dict[str, list[tuple[int, Any]]]]:
    """The file's summary and its decoded messages by topic, ``(log_time, message)``."""
    by_topic: dict[str, list[tuple[int, Any]]] = defaultdict(list)
    with path.open("rb") as fh:
        reader = make_reader(fh, validate_crcs=True, decoder_factories=[DecoderFactory()])
        header = reader.get_header()
        summary = reader.get_summary()
        for _, channel, message, decoded in reader.iter_decoded_messages(log_time_order=False):
            by_topic[channel.topic].append((message.log_time, decoded))
    assert header.profile == "ros2"
    return summary, by_topic


def _yaw(q: Any) -> float:
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


@pytest.fixture(scope="module")
def episode(tmp_path_factory: pytest.TempPathFactory) -> tuple[Any, Any, Any]:
    tmp = tmp_path_factory.mktemp("mcap")
    resolved = resolve(str(_lidar_scene(tmp)))
    path = tmp / "run.mcap"
    with McapEpisode.open(path, {"scene": "one-obstacle-lidar"}) as probe:
        out = run_scene(resolved, "zhang2019-v1", record=True, probes=[probe])
    return out, *_read(path)


def test_declared_schemas_are_ros2_messages(episode: tuple[Any, Any, Any]) -> None:
    _, summary, _ = episode
    declared = {}
    for channel in summary.channels.values():
        schema = summary.schemas[channel.schema_id]
        assert schema.encoding == "ros2msg" and channel.message_encoding == "cdr"
        declared[channel.topic] = schema.name
    assert declared == SCHEMAS
    header_of = {s.name: s.data.decode() for s in summary.schemas.values()}
    assert "MSG: std_msgs/Header" in header_of["sensor_msgs/msg/LaserScan"]


def test_every_step_has_its_pose_command_mode_and_bodies(episode: tuple[Any, Any, Any]) -> None:
    out, _, msgs = episode
    traj = out.trajectory
    n = len(traj.times)
    assert n > 100 and out.status == "success"
    stamps = [round(t * 1e9) for t in traj.times]
    for topic in ("/tf", "/odom", "/cmd_vel", "/mode", "/bodies"):
        assert [t for t, _ in msgs[topic]] == stamps, topic
    assert np.all(np.diff(stamps) > 0)
    for i, (_, odom) in enumerate(msgs["/odom"]):
        p = odom.pose.pose
        got = (p.position.x, p.position.y, _yaw(p.orientation))
        np.testing.assert_allclose(got, traj.robot[i], atol=1e-12)
        assert odom.header.stamp.sec + 1e-9 * odom.header.stamp.nanosec == pytest.approx(
            traj.times[i], abs=1e-9
        )
    for i, (_, tf) in enumerate(msgs["/tf"]):
        (tr,) = tf.transforms
        assert (tr.header.frame_id, tr.child_frame_id) == ("map", "base_link")
        assert (tr.transform.translation.x, tr.transform.translation.y) == tuple(traj.robot[i, :2])
    cmds = np.array([(m.linear.x, m.angular.z) for _, m in msgs["/cmd_vel"]])
    np.testing.assert_array_equal(cmds, traj.commands)
    assert [m.data for _, m in msgs["/mode"]] == traj.modes
    assert len(set(traj.modes)) > 1  # the law changed mode: the column is not constant


def test_bodies_are_markers_with_ids(episode: tuple[Any, Any, Any]) -> None:
    out, _, msgs = episode
    traj, radius = out.trajectory, out.setup.spec.radius
    for i, (_, array) in enumerate(msgs["/bodies"]):
        first, *markers = array.markers
        assert first.action == 3  # DELETEALL: bodies that left disappear
        by_ns = defaultdict(list)
        for mk in markers:
            by_ns[mk.ns].append(mk)
        (body,) = by_ns["bodies"]  # the one polygon, as a closed line strip
        assert (body.id, body.type, body.header.frame_id) == (0, 4, "map")
        pts = np.array([(p.x, p.y) for p in body.points])
        np.testing.assert_allclose(pts[0], pts[-1])
        np.testing.assert_allclose(pts[:-1], traj.obstacle_outline(0, i), atol=1e-12)
        (robot,) = by_ns["robots"]
        assert robot.type == 3 and robot.scale.x == pytest.approx(2 * radius)
        assert (robot.pose.position.x, robot.pose.position.y) == tuple(traj.robot[i, :2])
        (goal,) = by_ns["goals"]
        assert (goal.pose.position.x, goal.pose.position.y) == (10.0, 10.0)


def test_each_decision_has_its_scan(episode: tuple[Any, Any, Any]) -> None:
    out, _, msgs = episode
    traj = out.trajectory
    scans = msgs["/scan"]
    assert len(scans) == len(traj.times) - 1  # a decision every step, none at the end
    for i, (t, scan) in enumerate(scans):
        assert t == round(traj.times[i] * 1e9) and scan.header.frame_id == "base_link"
        assert len(scan.ranges) == N_RAYS and scan.range_max == 5.0
        assert scan.angle_increment == pytest.approx(2 * math.pi / N_RAYS, rel=1e-6)
    hits = [min(s.ranges) for _, s in scans]
    assert min(hits) < 2.0 < max(hits)  # the body comes into the scan and is passed


def test_the_probe_leaves_the_episode_unchanged(tmp_path: Path) -> None:
    resolved = resolve(str(_lidar_scene(tmp_path)))
    plain = run_scene(resolved, "zhang2019-v1")
    with McapEpisode.open(tmp_path / "run.mcap") as probe:
        watched = run_scene(resolved, "zhang2019-v1", probes=[probe])
    assert watched.metrics | {"decision_us_median": 0, "decision_us_p99": 0} == (
        plain.metrics | {"decision_us_median": 0, "decision_us_p99": 0}
    )


def test_multi_robot_episode_has_topics_per_robot(tmp_path: Path) -> None:
    path = tmp_path / "multi.mcap"
    with McapEpisode.open(path) as probe:
        out = run_scene(resolve("antipodal:3"), record=True, probes=[probe])
    summary, msgs = _read(path)
    names = ["robot_0", "robot_1", "robot_2"]
    topics = {c.topic for c in summary.channels.values()}
    assert topics == {"/tf", "/bodies"} | {f"/{r}/{t}" for r in names for t in
                                            ("odom", "cmd_vel", "mode")}  # fmt: skip
    poses = out.result.poses
    assert len(msgs["/tf"]) == len(poses)
    for i, (_, tf) in enumerate(msgs["/tf"]):
        assert [tr.child_frame_id for tr in tf.transforms] == [f"{r}/base_link" for r in names]
        got = [(tr.transform.translation.x, tr.transform.translation.y) for tr in tf.transforms]
        np.testing.assert_array_equal(got, poses[i][:, :2])
    robots = [mk for mk in msgs["/bodies"][-1][1].markers if mk.ns == "robots"]
    assert [mk.id for mk in robots] == [0, 1, 2]


@pytest.mark.parametrize("heading", [0.0, 0.785, -0.5, 3.0, -3.1])
def test_scan_angles_are_relative_to_the_heading(heading: float) -> None:
    from uvnav.bags.messages import laser_scan, scan_of
    from uvnav.obstacles.bodies import DiscBody
    from uvnav.obstacles.obstacle import FieldTemplate
    from uvnav.sensors.exact import lidar_scan

    field = FieldTemplate.from_bodies([DiscBody(0.5)]).field(
        np.array([[2.0, 1.0]]), np.zeros(1), np.zeros((1, 2)), np.zeros(1)
    )
    for fov in (2 * math.pi, 1.5):
        scan = lidar_scan(np.array((0.0, 0.0, heading)), field, n_rays=72, fov=fov)
        msg = laser_scan(scan, heading, 0.0, "base_link")
        assert -math.pi <= msg["angle_min"] < math.pi
        if fov < math.pi:
            assert msg["angle_min"] == pytest.approx(-0.75)
        decoded = type("Scan", (), {**msg, "ranges": np.float32(msg["ranges"])})
        back = scan_of(decoded, heading)
        diff = np.angle(np.exp(1j * (back.angles - scan.angles)))
        np.testing.assert_allclose(diff, 0.0, atol=1e-6)
        np.testing.assert_allclose(back.ranges, scan.ranges, atol=1e-6)
