"""Recorder of robot and obstacle trajectories (one row per integration step, plus t = 0)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.obstacles.obstacle import ObstacleField


@dataclass
class Trajectory:
    """Recorded episode, arrays stacked over time (n samples).

    Attributes:
        times: (n,) [s].
        robot: (n, 3) robot pose ``[x, y, theta]``.
        commands: (n, 2) applied ``[V_R, u_R]`` ([m/s], [rad/s]) in force from each sample on.
        modes: (n,) controller mode names.
        clearance: (n,) gap between robot disc and nearest obstacle [m].
        nearest_id: (n,) index of the nearest obstacle (-1 when there is none).
        obstacle_centres: (n, k, 2) [m]; obstacle_headings: (n, k) [rad];
        obstacle_velocities: (n, k, 2) [m/s]; obstacle_omegas: (n, k) [rad/s].
        obstacle_shapes: per obstacle, its outline in the body frame (k entries of (m, 2)) [m].
        command_names: what the two command columns hold, with units (``V_R``, ``u_R`` for the
            unicycle; ``v_x``, ``v_y`` for the holonomic robot).
    """

    times: FloatArray
    robot: FloatArray
    commands: FloatArray
    modes: list[str]
    clearance: FloatArray
    nearest_id: np.ndarray
    obstacle_centres: FloatArray
    obstacle_headings: FloatArray
    obstacle_velocities: FloatArray
    obstacle_omegas: FloatArray
    obstacle_shapes: list[FloatArray] = field(default_factory=list)
    command_names: tuple[str, str] = ("V_R [m/s]", "u_R [rad/s]")

    def obstacle_outline(self, j: int, i: int) -> FloatArray:
        """World outline of obstacle ``j`` at sample ``i`` [m]."""
        local = self.obstacle_shapes[j]
        c, s = np.cos(self.obstacle_headings[i, j]), np.sin(self.obstacle_headings[i, j])
        rot = np.array([[c, -s], [s, c]])
        return np.asarray(local @ rot.T + self.obstacle_centres[i, j], dtype=float)


@dataclass
class TrajectoryRecorder:
    """Appends samples to lists and stacks them into a :class:`Trajectory` at the end."""

    shapes: list[FloatArray]
    command_names: tuple[str, str] = ("V_R [m/s]", "u_R [rad/s]")
    _t: list[float] = field(default_factory=list)
    _robot: list[FloatArray] = field(default_factory=list)
    _cmd: list[tuple[float, float]] = field(default_factory=list)
    _mode: list[str] = field(default_factory=list)
    _clear: list[float] = field(default_factory=list)
    _near: list[int] = field(default_factory=list)
    _oc: list[FloatArray] = field(default_factory=list)
    _oh: list[FloatArray] = field(default_factory=list)
    _ov: list[FloatArray] = field(default_factory=list)
    _ow: list[FloatArray] = field(default_factory=list)

    def add(
        self,
        t: float,
        robot: FloatArray,
        command: tuple[float, float],
        mode: str,
        clearance: float,
        nearest: int,
        field: ObstacleField,
    ) -> None:
        """One sample: time [s], robot pose, applied command, mode, clearance [m], nearest
        obstacle index and the obstacles' state (``field``)."""
        self._t.append(t)
        self._robot.append(robot)
        self._cmd.append(command)
        self._mode.append(mode)
        self._clear.append(clearance)
        self._near.append(nearest)
        self._oc.append(field.centres)
        self._oh.append(field.headings)
        self._ov.append(field.velocities)
        self._ow.append(field.angular_velocities)

    def finish(self) -> Trajectory:
        k = len(self.shapes)
        n = len(self._t)
        return Trajectory(
            times=np.asarray(self._t),
            robot=np.asarray(self._robot).reshape(n, 3),
            commands=np.asarray(self._cmd, dtype=float).reshape(n, 2),
            modes=list(self._mode),
            clearance=np.asarray(self._clear),
            nearest_id=np.asarray(self._near, dtype=np.intp),
            obstacle_centres=np.asarray(self._oc).reshape(n, k, 2),
            obstacle_headings=np.asarray(self._oh).reshape(n, k),
            obstacle_velocities=np.asarray(self._ov).reshape(n, k, 2),
            obstacle_omegas=np.asarray(self._ow).reshape(n, k),
            obstacle_shapes=list(self.shapes),
            command_names=self.command_names,
        )
