"""A minimal Foxglove WebSocket client on the standard library (subprotocol
``foxglove.sdk.v1``), for the tests that watch ``uvnav view``: the handshake, the frames, a
subscription to every advertised channel, and the port a ``uvnav view`` process prints."""

from __future__ import annotations

import base64
import json
import os
import socket
import struct
import subprocess
from collections.abc import Iterator
from typing import IO, Any

SUBPROTOCOL = "foxglove.sdk.v1"


def handshake(port: int) -> tuple[socket.socket, IO[bytes]]:
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


def frames(stream: IO[bytes]) -> Iterator[tuple[int, bytes]]:
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


def send_text(sock: socket.socket, text: str) -> None:
    data = text.encode()
    mask = os.urandom(4)
    size = len(data)
    head = bytes([0x81]) + (
        bytes([0x80 | size]) if size < 126 else bytes([0x80 | 126]) + struct.pack("!H", size)
    )
    sock.sendall(head + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data)))


def view_port(proc: subprocess.Popen[str]) -> int:
    """The port ``uvnav view --port 0`` listens on (its first line of output)."""
    assert proc.stdout is not None
    line = proc.stdout.readline()
    assert "ws://127.0.0.1:" in line, (line, proc.stderr.read() if proc.stderr else "")
    return int(line.split("ws://127.0.0.1:")[1].split(";")[0])


def session(port: int) -> tuple[dict[str, Any], dict[int, dict[str, Any]], list[Any]]:
    """Subscribe to every channel of the server on ``port`` until it closes: serverInfo, the
    advertised channels by id, and every (topic, log time, payload)."""
    sock, stream = handshake(port)
    info: dict[str, Any] = {}
    channels: dict[int, dict[str, Any]] = {}
    got: list[tuple[str, int, bytes]] = []
    subs: dict[int, str] = {}
    with sock:
        for opcode, payload in frames(stream):
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
                    send_text(sock, json.dumps({"op": "subscribe", "subscriptions": wanted}))
            elif payload[0] == 1:
                sub, log_time = struct.unpack_from("<IQ", payload, 1)
                got.append((subs[sub], log_time, payload[13:]))
    return info, channels, got
