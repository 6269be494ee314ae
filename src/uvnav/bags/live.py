"""A 2D episode served live to Foxglove over its WebSocket protocol (``uvnav view``).

:class:`FoxgloveEpisode` is a probe: when the run starts it creates, in its own
:class:`foxglove.Context`, one channel per topic an episode file has (:mod:`uvnav.bags.mcap`:
``/tf``, ``/bodies``, ``[/NAME]/odom``, ``cmd_vel``, ``mode``, ``scan``), each with the ROS 2
type's ``ros2msg`` schema and the ``cdr`` message encoding; starts ``foxglove-sdk``'s WebSocket
server (subprotocol ``foxglove.sdk.v1``) on them; waits for a client to subscribe (and
:data:`SETTLE_S` more, for the client's other subscriptions); then sends every message the file
would hold, CDR-encoded by ``mcap-ros2-support``'s encoder (the bytes the file holds), with log
time = header stamp = simulation time, each step when it is due at ``speed`` times real time.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Sequence
from typing import Any

from uvnav.bags import messages as m
from uvnav.bags import require
from uvnav.bags.mcap import EpisodeProbe

#: the packages a live episode needs beyond the MCAP ones
FOXGLOVE = (("foxglove", "foxglove-sdk"),)

#: seconds waited after the first subscription before the episode starts
SETTLE_S = 0.5


def _listener(event: threading.Event) -> Any:
    """A ``foxglove.websocket.ServerListener`` that sets ``event`` when a client subscribes."""
    from foxglove.websocket import ServerListener

    class Listener(ServerListener):
        def on_subscribe(self, client: Any, channel: Any) -> None:
            event.set()

    return Listener()


class FoxgloveEpisode(EpisodeProbe):
    """Serves the episode it watches to Foxglove clients (module docstring); call :meth:`stop`
    after the run.

    When the run starts it creates the episode's channels in its own context, then starts the
    server, so that a client is sent every channel in its first ``advertise``.

    Args:
        host, port: where the server listens (port 0: a free one).
        speed: simulation seconds per wall-clock second (> 0).
        wait: wait, when the run starts, until a client subscribes.
        on_ready: called with the server's address once it listens.
        clock, sleep: the wall clock [s] and the pause (tests pass their own).

    Raises:
        MissingExtraError: the ``ros`` extra (with ``foxglove-sdk``) is not installed.
    """

    def __init__(
        self,
        host: str = "127.0.0.1",
        port: int = 8765,
        speed: float = 1.0,
        *,
        wait: bool = True,
        on_ready: Callable[[str], None] | None = None,
        clock: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep,
    ) -> None:
        require("serving an episode to Foxglove", FOXGLOVE)
        if not speed > 0.0:
            raise ValueError(f"speed {speed}: must be > 0")
        super().__init__()
        self.host, self.port, self.speed, self.wait = host, port, float(speed), wait
        self.on_ready, self.clock, self.sleep = on_ready, clock, sleep
        self.server: Any = None
        self.context: Any = None
        self.subscribed = threading.Event()
        self.channels: dict[str, Any] = {}
        self._encoders: dict[str, Callable[[Any], bytes]] = {}
        self._start: tuple[float, float] | None = None  # (wall clock, simulation time)
        self.last_t = 0.0  # the simulation time [s] of the last step sent

    @property
    def url(self) -> str:
        """The address a Foxglove client connects to (once the server listens)."""
        return f"ws://{self.host}:{self.server.port if self.server else self.port}"

    def stop(self) -> None:
        """Stop the server (clients are disconnected); nothing if it never started."""
        if self.server is not None:
            self.server.stop()
            self.server = None

    def on_start(self, world: Any, laws: Sequence[Any]) -> None:
        """Create the episode's channels, start the server, then wait for a subscriber (with
        ``wait``).

        Raises:
            RuntimeError: the server cannot listen at ``host``:``port`` (``foxglove-sdk``'s).
        """
        super().on_start(world, laws)
        import foxglove

        self.context = context = foxglove.Context()  # its channels live as long as it
        for topic, type_name in self.topics():
            schema = foxglove.Schema(
                name=type_name, encoding="ros2msg", data=m.msgdef(type_name).encode()
            )
            self.channels[topic] = foxglove.Channel(
                topic, schema=schema, message_encoding="cdr", context=context
            )
        self.server = foxglove.start_server(
            name="uvnav", host=self.host, port=self.port, context=context,
            server_listener=_listener(self.subscribed),
        )  # fmt: skip
        if self.on_ready is not None:
            self.on_ready(self.url)
        if self.wait:
            while not self.subscribed.wait(0.2):
                pass
            self.sleep(SETTLE_S)

    def _encoder(self, type_name: str) -> Callable[[Any], bytes]:
        encoder = self._encoders.get(type_name)
        if encoder is None:
            from mcap_ros2._dynamic import serialize_dynamic  # the MCAP writer's CDR encoder

            encoder = serialize_dynamic(type_name, m.msgdef(type_name))[type_name]
            self._encoders[type_name] = encoder
        return encoder

    def _pace(self, t: float) -> None:
        """Pause until simulation time ``t`` [s] is due on the wall clock."""
        now = self.clock()
        if self._start is None:
            self._start = (now, t)
            return
        due = self._start[0] + (t - self._start[1]) / self.speed
        if due > now:
            self.sleep(due - now)

    def on_step(self, world: Any, laws: Sequence[Any]) -> None:
        """Wait until the step is due, then send its messages."""
        self.last_t = float(world.t)
        self._pace(self.last_t)
        super().on_step(world, laws)

    on_end = on_step

    def _send(
        self, topic: str, type_name: str, message: dict[str, Any], t: float, seq: int
    ) -> None:
        data = self._encoder(type_name)(message)
        self.channels[topic].log(data, log_time=m.nanoseconds(t))
