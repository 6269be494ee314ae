"""A 2D episode as an MCAP file of ROS 2 messages (``uvnav simulate --mcap``).

:class:`McapEpisode` is a probe (:class:`uvnav.core.Probe`): it watches the loop of a one-robot
2D world (:class:`~uvnav.sim.episode.World2D`) or a multi-robot one
(:class:`~uvnav.sim.multi.MultiUnicycleWorld`) and writes, with ``mcap-ros2-support``'s writer
(profile ``ros2``, ``ros2msg`` schemas, CDR messages, zstd chunks), stamped with the simulation
time:

==========================  ===================================  ==============================
topic                       type                                 when
==========================  ===================================  ==============================
``/tf``                     ``tf2_msgs/msg/TFMessage``           every integration step and the
                                                                 end: ``map`` -> each robot's
                                                                 ``base_link``
``/bodies``                 ``visualization_msgs/msg/            every step: a DELETEALL, then
                            MarkerArray``                        the bodies (``bodies``: discs
                                                                 as cylinders, polygons as line
                                                                 strips, id = the body's
                                                                 index), the robots' footprints
                                                                 (``robots``) and goals
                                                                 (``goals``)
``[/NAME]/odom``            ``nav_msgs/msg/Odometry``            every step: the pose, the
                                                                 velocity and turn rate now
                                                                 in ``base_link``
``[/NAME]/cmd_vel``         ``geometry_msgs/msg/Twist``          every step: the command held
``[/NAME]/mode``            ``std_msgs/msg/String``              every step: the law's mode
``[/NAME]/scan``            ``sensor_msgs/msg/LaserScan``        each decision, when the robot
                                                                 has a lidar (after the step's
                                                                 odometry)
==========================  ===================================  ==============================

:class:`EpisodeProbe` builds these messages; :class:`McapEpisode` writes them, and
:class:`uvnav.bags.live.FoxgloveEpisode` serves them live.  :class:`McapFolder` makes one
:class:`McapEpisode` per campaign job (``uvnav bench --mcap-dir``).

One robot has the topics without a prefix and the frame ``base_link``; robot ``NAME`` of a
multi-robot scene has ``/NAME/...`` and ``NAME/base_link``.  ``uvnav replay`` reads ``/scan``
and ``/odom`` of such a file back.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from pathlib import Path
from typing import IO, Any

import numpy as np

from uvnav.bags import messages as m
from uvnav.bags import require
from uvnav.core import BaseProbe

#: the scene kinds whose episodes are written
KINDS = ("nav2d", "multi2d")

#: the message types an episode file declares
TYPES = (m.TF_T, m.MARKERS_T, m.ODOM_T, m.TWIST_T, m.STRING_T, m.SCAN_T)


def _names(world: Any) -> list[str]:
    """Topic prefixes of the world's robots: ``""`` for the one robot, else each robot's name
    (letters, digits and ``_``; ``robotI`` when empty or taken)."""
    robots = getattr(world, "robots", None)
    if robots is None:
        return [""]
    out: list[str] = []
    for i, r in enumerate(robots):
        name = re.sub(r"\W", "_", str(getattr(r, "name", "") or ""))
        if not name or name in out or name[0].isdigit():
            name = f"robot{i}"
        out.append(name)
    return out


class EpisodeProbe(BaseProbe):
    """The messages of an episode (the topics of the module docstring), handed with their topic,
    ROS 2 type and simulation time to :meth:`_send`, which a subclass defines."""

    def __init__(self) -> None:
        self.names: list[str] = []
        self._seq: dict[str, int] = {}
        self._scans: list[tuple[int, dict[str, Any]]] = []  # (agent, LaserScan) to write

    def _send(
        self, topic: str, type_name: str, message: dict[str, Any], t: float, seq: int
    ) -> None:
        """Deliver ``message`` (the ``seq``-th on ``topic``) stamped with time ``t`` [s]."""
        raise NotImplementedError

    def _write(self, topic: str, type_name: str, message: dict[str, Any], t: float) -> None:
        seq = self._seq.get(topic, 0)
        self._seq[topic] = seq + 1
        self._send(topic, type_name, message, t, seq)

    def topics(self) -> list[tuple[str, str]]:
        """``(topic, type)`` of every topic the episode may use (``/scan`` topics included,
        which carry messages only when the robot reads a lidar); known after :meth:`on_start`."""
        out = [("/tf", m.TF_T), ("/bodies", m.MARKERS_T)]
        for i in range(len(self.names)):
            for leaf, type_name in (("odom", m.ODOM_T), ("cmd_vel", m.TWIST_T),
                                    ("mode", m.STRING_T), ("scan", m.SCAN_T)):  # fmt: skip
                out.append((self._topic(i, leaf), type_name))
        return out

    def _frame(self, i: int) -> str:
        return f"{self.names[i]}/base_link" if self.names[i] else "base_link"

    def _topic(self, i: int, leaf: str) -> str:
        return f"/{self.names[i]}/{leaf}" if self.names[i] else f"/{leaf}"

    def on_start(self, world: Any, laws: Sequence[Any]) -> None:
        """Name the robots (their topics and frames)."""
        if not (hasattr(world, "field") and (hasattr(world, "pose") or hasattr(world, "state"))):
            raise TypeError(f"no episode messages of a {type(world).__name__}: 2D worlds only")
        self.names = _names(world)

    def on_decision(self, world: Any, agent: int, law: Any, obs: Any, applied: Any) -> None:
        """The scan the robot's law just read, if it has one (written after the step's
        odometry, which a reader of the file then knows when the scan arrives)."""
        scan = getattr(obs, "lidar", None)
        if scan is None:
            return
        msg = m.laser_scan(scan, float(obs.pose[2]), float(world.t), self._frame(agent))
        self._scans.append((agent, msg))

    def on_step(self, world: Any, laws: Sequence[Any]) -> None:
        """The state now: the robots' transforms, odometry, commands and modes, the bodies."""
        t = float(world.t)
        poses, velocities, turns, commands, radii, goals = _robots(world)
        transforms = []
        for i, (x, y, yaw) in enumerate(poses):
            transforms.append({
                "header": m.header(t, "map"), "child_frame_id": self._frame(i),
                "transform": {"translation": {"x": x, "y": y, "z": 0.0},
                              "rotation": m.quaternion(yaw)},
            })  # fmt: skip
        self._write("/tf", m.TF_T, {"transforms": transforms}, t)
        for i, (x, y, yaw) in enumerate(poses):
            odom = {
                "header": m.header(t, "map"), "child_frame_id": self._frame(i),
                "pose": {"pose": m.pose(x, y, yaw)},
                "twist": {"twist": m.twist(m.to_body(*velocities[i], yaw), turns[i])},
            }  # fmt: skip
            self._write(self._topic(i, "odom"), m.ODOM_T, odom, t)
            self._write(self._topic(i, "cmd_vel"), m.TWIST_T, m.command_twist(commands[i], yaw), t)
            mode = {"data": str(getattr(laws[i], "mode", ""))}
            self._write(self._topic(i, "mode"), m.STRING_T, mode, t)
        for i, scan in self._scans:
            self._write(self._topic(i, "scan"), m.SCAN_T, scan, t)
        self._scans.clear()
        field, count = _bodies(world)
        markers = m.body_markers(field, t, count)
        for i, (x, y, _) in enumerate(poses):
            markers.append(m.disc_marker("robots", i, np.array((x, y)), radii[i], t, "robot"))
            goal = {"x": float(goals[i][0]), "y": float(goals[i][1]), "z": 0.0}
            markers.append(m.marker("goals", i, m.SPHERE, t, "goal",
                                    pose={"position": goal, "orientation": m.quaternion(0.0)},
                                    scale={"x": 0.2, "y": 0.2, "z": 0.2}))  # fmt: skip
        self._write("/bodies", m.MARKERS_T, m.marker_array(t, markers), t)

    on_end = on_step


class McapEpisode(EpisodeProbe):
    """Writes the episode it watches into ``stream`` (module docstring); call :meth:`close`
    after the run (or use it as a context manager).

    Args:
        stream: a binary file open for writing.
        metadata: written as the file's ``uvnav`` metadata record (scene, law, seed...).

    Raises:
        MissingExtraError: the ``ros`` extra is not installed.
    """

    def __init__(self, stream: IO[bytes], metadata: dict[str, str] | None = None) -> None:
        require("writing an episode as MCAP")
        from mcap_ros2.writer import Writer

        super().__init__()
        self.writer = Writer(stream)
        self.schemas = {t: self.writer.register_msgdef(t, m.msgdef(t)) for t in TYPES}
        if metadata:
            self.writer.add_metadata("uvnav", {k: str(v) for k, v in metadata.items()})
        self._owned: IO[bytes] | None = None
        self.path: Path | None = None  # the file :meth:`open` opened

    @classmethod
    def open(cls, path: Path, metadata: dict[str, str] | None = None) -> McapEpisode:
        """A probe writing into a new file at ``path`` (replaced if it exists), which
        :meth:`close` closes.

        Raises:
            MissingExtraError: the ``ros`` extra is not installed.
            OSError: the file cannot be written.
        """
        require("writing an episode as MCAP")
        stream = Path(path).open("wb")  # noqa: SIM115 (closed by close())
        try:
            probe = cls(stream, metadata)
        except BaseException:
            stream.close()
            raise
        probe._owned = stream
        probe.path = Path(path)
        return probe

    def __enter__(self) -> McapEpisode:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Write the file's summary and end it (and close the file :meth:`open` opened; that
        file is removed when no run started, as when the law was refused)."""
        self.writer.finish()
        if self._owned is not None:
            self._owned.close()
            self._owned = None
            if not self.names and self.path is not None:
                self.path.unlink(missing_ok=True)

    def _send(
        self, topic: str, type_name: str, message: dict[str, Any], t: float, seq: int
    ) -> None:
        ns = m.nanoseconds(t)
        self.writer.write_message(
            topic, self.schemas[type_name], message, log_time=ns, publish_time=ns, sequence=seq
        )


def _robots(world: Any) -> tuple[list[tuple[float, float, float]], list[tuple[float, float]],
                                 list[float], list[Any], list[float], list[Any]]:  # fmt: skip
    """Poses ``(x, y, yaw)``, world-frame velocities [m/s], turn rates [rad/s] (the vehicle's
    now; 0 for a vehicle without one, such as the holonomic robot), held commands, radii [m]
    and goals of the world's robots."""
    if hasattr(world, "state"):  # the multi-robot world: ideal unicycles at their commands
        state = np.asarray(world.state, dtype=float)
        poses = [(float(x), float(y), float(th)) for x, y, th in state]
        cmds = list(world.applied)
        vel = [
            (float(c.v) * math.cos(p[2]), float(c.v) * math.sin(p[2]))
            for c, p in zip(cmds, poses, strict=True)
        ]
        turns = [float(c.u) for c in cmds]
        return poses, vel, turns, cmds, [float(r) for r in world.radii], list(world.goals)
    x, y, th = (float(v) for v in world.pose)
    vx, vy = world.velocity()
    rate = getattr(world.body, "turn_rate", None)
    turn = float(rate()) if callable(rate) else 0.0
    radius = float(world.spec.radius)
    return [(x, y, th)], [(float(vx), float(vy))], [turn], [world.applied], [radius], [world.goal]


def _bodies(world: Any) -> tuple[Any, int]:
    """The world's field and how many of its first bodies are obstacles (the multi-robot
    world's field ends with its robots)."""
    field = world.field
    return field, int(getattr(world, "k", len(field)))


def episode_file(label: str, controller: str, seed: int) -> str:
    """The file name of a campaign's episode, ``<label>__<controller>__<seed>.mcap``, with
    every run of characters other than letters, digits, ``.``, ``-`` and ``_`` as one ``_``."""

    def clean(text: str) -> str:
        return re.sub(r"[^A-Za-z0-9._-]+", "_", text).strip("._") or "_"

    return f"{clean(label)}__{clean(controller)}__{int(seed)}.mcap"


class McapFolder:
    """A campaign's ``probe_factory`` (:func:`uvnav.bench.campaign.run_campaign`): for each
    job whose scene is 2D (``nav2d``, ``multi2d``), an :class:`McapEpisode` writing
    :func:`episode_file` in ``folder`` (replaced if it exists), with the job's scene, law and
    seed as metadata; no probe for other jobs.  Picklable: it crosses to the workers."""

    def __init__(self, folder: Path) -> None:
        self.folder = Path(folder)

    def __call__(self, job: Any) -> list[McapEpisode]:
        """The probes of ``job``'s episode (none, or one :class:`McapEpisode`)."""
        from uvnav.bench.campaign import job_scene

        if job.scenario is None and job.generator_seed is None:
            return []
        if job_scene(job).kind.name not in KINDS:
            return []
        label = job.scenario_label
        meta = {"scene": label, "law": job.controller, "seed": str(int(job.seed))}
        path = self.folder / episode_file(label, job.controller, int(job.seed))
        return [McapEpisode.open(path, meta)]
