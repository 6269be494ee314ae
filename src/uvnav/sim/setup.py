"""What an episode is given and what it returns (:func:`uvnav.sim.run.run_episode`), in one
module: the result of one vehicle in any world, the 2D setup, the multi-robot setup and result
(the loop world and the compiled swarm) and the sensing configuration they share.

The worlds import these and nothing here imports a world, so the loop world, the packed worlds
and the swarm build on one definition without importing each other.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Generic, TypeVar

import numpy as np

from uvnav.controllers.base import Controller
from uvnav.dynamics.unicycle import UnicycleSpec
from uvnav.geometry.angles import FloatArray
from uvnav.obstacles.obstacle import Obstacle
from uvnav.sensors.config import SensingConfig
from uvnav.sim.metrics import EpisodeMetrics


@dataclass
class EpisodeSetup:
    """A fully instantiated episode (what a scenario builds for one seed).

    Attributes:
        spec: robot limits and radius.
        start: initial pose ``[x, y, theta]``.
        goal: target T [m].
        obstacles: obstacles with their episode-specific motion models.
        dt: integration step [s].
        control_period: decision period [s], a whole multiple of ``dt`` (within 1e-9 relative).
        t_max: time limit [s].
        goal_tolerance: the goal is reached within this distance [m].
        sensing: sensing configuration.
    """

    spec: UnicycleSpec
    start: FloatArray
    goal: FloatArray
    obstacles: list[Obstacle]
    dt: float = 0.1
    control_period: float = 0.1
    t_max: float = 60.0
    goal_tolerance: float = 0.2
    sensing: SensingConfig = field(default_factory=SensingConfig)


TrajT = TypeVar("TrajT")


@dataclass
class EpisodeResult(Generic[TrajT]):
    """One vehicle's episode, whatever its world (:func:`uvnav.sim.run.run_episode`).

    Attributes:
        metrics: the common metrics (:mod:`uvnav.sim.metrics`).
        status: ``success``, ``collision`` or ``timeout``.
        trajectory: the world's own record of the run (2D :class:`~uvnav.sim.recorder.Trajectory`,
            :class:`~uvnav.sim.episode3d.Trajectory3D`,
            :class:`~uvnav.sim.episode_uuv2d.Uuv2dTrajectory`,
            :class:`~uvnav.sim.episode_uuv3d.LocatedTrace`); ``None`` unrecorded.
        decision_us: the law's CPU time per decision [us].
        contact_time: a collision's first contact [s] (``None`` without one).
        flags: the world's own events (Ch. 4 ``entered_forbidden``, Ch. 5
            ``entered_inner_space``); empty where the world has none.
    """

    metrics: EpisodeMetrics
    status: str
    trajectory: TrajT | None
    decision_us: FloatArray
    contact_time: float | None = None
    flags: dict[str, bool] = field(default_factory=dict)


GROUP_METRIC_NAMES: tuple[str, ...] = (
    "all_arrived",
    "arrived",
    "robot_collisions",
    "obstacle_collisions",
    "makespan",
    "sum_of_times",
    "deadlocks",
)


@dataclass
class RobotSetup:
    """One robot of a multi-robot episode.

    Attributes:
        spec: limits and radius.
        start: initial pose ``[x, y, theta]`` ([m], [m], [rad]).
        goal: target [m], shape (2,).
        controller: its navigation law (reset at the start of the episode).
        sensing: its sensing configuration.
        name: label.
    """

    spec: UnicycleSpec
    start: FloatArray
    goal: FloatArray
    controller: Controller
    sensing: SensingConfig = field(default_factory=SensingConfig)
    name: str = ""


@dataclass
class MultiSetup:
    """A fully instantiated multi-robot episode.

    Attributes:
        robots: the robots.
        obstacles: the world's (non-robot) obstacles.
        dt: integration step [s].
        control_period: decision period [s] (a whole multiple of ``dt``).
        t_max: time limit [s].
        goal_tolerance: arrival radius [m].
        deadlock_window: the window of the deadlock test [s].
        deadlock_distance: a robot that moved less than this [m] over the window is stuck.
    """

    robots: list[RobotSetup]
    obstacles: list[Obstacle] = field(default_factory=list)
    dt: float = 0.1
    control_period: float = 0.1
    t_max: float = 60.0
    goal_tolerance: float = 0.2
    deadlock_window: float = 10.0
    deadlock_distance: float = 0.2


@dataclass(frozen=True)
class GroupMetrics:
    """Outcome of the group (see the module docstring)."""

    all_arrived: bool
    arrived: int
    robot_collisions: int
    obstacle_collisions: int
    makespan: float | None
    sum_of_times: float | None
    deadlocks: int

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass
class MultiResult:
    """Per-robot metrics and statuses, group metrics, and the recorded robot trajectories.

    Attributes:
        robots: per-robot :class:`EpisodeMetrics` (same names as single-robot episodes).
        statuses: per robot ``success``, ``collision`` or ``timeout``.
        group: the group metrics.
        times: (n,) sample times [s] (empty when not recorded).
        poses: (n, N, 3) robot poses (empty when not recorded).
        collided_pairs: the robot index pairs that overlapped.
        obstacle_paths: (n, K, 2) positions of the world's K obstacles [m] at the same times
            (empty when not recorded or when there are none).
    """

    robots: list[EpisodeMetrics]
    statuses: list[str]
    group: GroupMetrics
    times: FloatArray
    poses: FloatArray
    collided_pairs: list[tuple[int, int]]
    obstacle_paths: FloatArray = field(default_factory=lambda: np.zeros((0, 0, 2)))
