"""``uvnav view``: an episode served live over Foxglove's WebSocket protocol, read by a client.

The client (``tests/foxglove_client.py``) is written on the standard library (RFC 6455
framing; no WebSocket client package is a dependency): it opens ``foxglove.sdk.v1``, reads
``serverInfo`` and ``advertise``, subscribes to every channel, and decodes the binary
``messageData`` frames (opcode 1, uint32 subscription id, uint64 log time, CDR payload) with
``rosbags``' CDR decoder.
"""

from __future__ import annotations

import itertools
import os
import subprocess
import sys
from pathlib import Path

import pytest

from foxglove_client import session, view_port

pytest.importorskip("foxglove")
pytest.importorskip("mcap_ros2")
pytest.importorskip("rosbags")

SRC = Path(__file__).resolve().parents[2] / "src"


def _view(*args: str) -> subprocess.Popen[str]:
    env = {**os.environ, "PYTHONPATH": str(SRC), "PYTHONUNBUFFERED": "1"}
    cmd = [sys.executable, "-m", "uvnav", "view", *args, "--port", "0", "--once"]
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)


def test_view_serves_the_episode_topics_to_a_websocket_client() -> None:
    proc = _view("random-ch2:3", "--speed", "50")
    try:
        info, channels, got = session(view_port(proc))
        assert proc.wait(timeout=60) == 0, proc.stderr.read() if proc.stderr else ""
    finally:
        proc.kill()
    assert info.get("name") == "uvnav"
    by_topic = {c["topic"]: c for c in channels.values()}
    assert set(by_topic) == {"/tf", "/bodies", "/odom", "/cmd_vel", "/mode", "/scan"}
    odom = by_topic["/odom"]
    assert (odom["encoding"], odom["schemaName"], odom["schemaEncoding"]) == (
        "cdr",
        "nav_msgs/msg/Odometry",
        "ros2msg",
    )
    assert "geometry_msgs/PoseWithCovariance pose" in odom["schema"]
    times = [t for topic, t, _ in got if topic == "/odom"]
    assert len(times) > 20
    assert all(b > a for a, b in itertools.pairwise(times))
    assert {topic for topic, _, _ in got} >= {"/tf", "/bodies", "/odom", "/cmd_vel", "/mode"}
    from uvnav.bags.messages import typestore

    last = [p for topic, _, p in got if topic == "/odom"][-1]
    msg = typestore().deserialize_cdr(last, "nav_msgs/msg/Odometry")
    assert msg.header.frame_id == "map"
    assert msg.child_frame_id == "base_link"
    assert msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec == times[-1]


def test_view_refuses_a_non_positive_speed() -> None:
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    cmd = [sys.executable, "-m", "uvnav", "view", "random-ch2:3", "--speed", "0", "--once"]
    out = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=60)
    assert out.returncode == 2
    assert out.stderr.strip().splitlines() == [
        "error: --speed: must be a finite number > 0 (got 0.0)"
    ]
