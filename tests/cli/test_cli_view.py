"""``uvnav view``: an episode served live over Foxglove's WebSocket protocol, read by a client.

The client is written here on the standard library (RFC 6455 framing; no WebSocket client
package is a dependency): it opens ``foxglove.sdk.v1``, reads ``serverInfo`` and ``advertise``,
subscribes to every channel, and decodes the binary ``messageData`` frames (opcode 1, uint32
subscription id, uint64 log time, CDR payload) with ``rosbags``' CDR decoder.
"""

from __future__ import annotations

import base64
import itertools
import json
import os
import socket
import struct
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

import pytest

pytest.importorskip("foxglove")
pytest.importorskip("mcap_ros2")
pytest.importorskip("rosbags")

SRC = Path(__file__).resolve().parents[2] / "src"
SUBPROTOCOL = "foxglove.sdk.v1"


def _handshake(port: int) -> tuple[socket.socket, IO[bytes]]:
    sock = socket.create_connection(("127.0.0.1", port), timeout=20)
    key = base64.b64encode(os.urandom(16)).decode()
    sock.sendall(
        (
            f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n"
            f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n"
            f"Sec-WebSocket-Protocol: {SUBPROTOCOL}\r\n\r\n"
        ).encode()
    )
    stream = sock.makefile("rb")
    head = b""
    while not head.endswith(b"\r\n\r\n"):
        head += stream.read(1)
    text = head.decode().lower()
    assert text.startswith("http/1.1 101"), text
    assert f"sec-websocket-protocol: {SUBPROTOCOL}" in text
    return sock, stream


def _frames(stream: IO[bytes]) -> Iterator[tuple[int, bytes]]:
    """(opcode, payload) of each whole message the server sends, until it closes."""
    parts: list[bytes] = []
    first = 0
    while True:
        head = stream.read(2)
        if len(head) < 2:
            return
        opcode, size = head[0] & 0x0F, head[1] & 0x7F
        if size == 126:
            size = struct.unpack("!H", stream.read(2))[0]
        elif size == 127:
            size = struct.unpack("!Q", stream.read(8))[0]
        payload = stream.read(size)
        if opcode == 8:
            return
        if opcode in (1, 2):
            first = opcode
        if opcode in (0, 1, 2):
            parts.append(payload)
            if head[0] & 0x80:
                yield first, b"".join(parts)
                parts = []


def _send_text(sock: socket.socket, text: str) -> None:
    data = text.encode()
    mask = os.urandom(4)
    size = len(data)
    head = bytes([0x81]) + (
        bytes([0x80 | size]) if size < 126 else bytes([0x80 | 126]) + struct.pack("!H", size)
    )
    sock.sendall(head + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data)))


def _view(*args: str) -> subprocess.Popen[str]:
    env = {**os.environ, "PYTHONPATH": str(SRC), "PYTHONUNBUFFERED": "1"}
    cmd = [sys.executable, "-m", "uvnav", "view", *args, "--port", "0", "--once"]
    return subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)


def _port(proc: subprocess.Popen[str]) -> int:
    assert proc.stdout is not None
    line = proc.stdout.readline()
    assert "ws://127.0.0.1:" in line, (line, proc.stderr.read() if proc.stderr else "")
    return int(line.split("ws://127.0.0.1:")[1].split(";")[0])


def _session(port: int) -> tuple[dict[str, Any], dict[int, dict[str, Any]], list[Any]]:
    """serverInfo, the advertised channels by id, and every (topic, log time, payload)."""
    sock, stream = _handshake(port)
    frames = _frames(stream)
    info: dict[str, Any] = {}
    channels: dict[int, dict[str, Any]] = {}
    got: list[tuple[str, int, bytes]] = []
    subs: dict[int, str] = {}
    with sock:
        for opcode, payload in frames:
            if opcode == 1:
                msg = json.loads(payload)
                if msg["op"] == "serverInfo":
                    info = msg
                elif msg["op"] == "advertise":
                    wanted = []
                    for c in msg["channels"]:
                        channels[c["id"]] = c
                        wanted.append({"id": len(subs), "channelId": c["id"]})
                        subs[len(subs)] = c["topic"]
                    _send_text(sock, json.dumps({"op": "subscribe", "subscriptions": wanted}))
            elif payload[0] == 1:
                sub, log_time = struct.unpack_from("<IQ", payload, 1)
                got.append((subs[sub], log_time, payload[13:]))
    return info, channels, got


def test_view_serves_the_episode_topics_to_a_websocket_client() -> None:
    proc = _view("random-ch2:3", "--speed", "50")
    try:
        info, channels, got = _session(_port(proc))
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
