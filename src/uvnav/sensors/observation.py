"""What a controller is given: :class:`Observation` and per-obstacle :class:`ObstacleReading`.

These are the only inputs of ``Controller.act`` (DESIGN §2).  The thesis's Ch. 2 sensing model
(§2.2) is: for every obstacle within sensing range, the distance d_i (2.5) and nearest boundary
point r_min, the obstacle's shape and mass centre, and its velocity v_i and angular velocity u_i.
Whether v_i, u_i are the true values ("known") or finite-difference estimates is decided by the
simulator's sensing configuration and written in :attr:`ObstacleReading.velocity_source`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from uvnav.geometry.angles import FloatArray


@dataclass(frozen=True)
class ObstacleReading:
    """One obstacle as sensed from the robot's current position.

    Attributes:
        obstacle_id: stable index of the obstacle in the world (lets controllers track it).
        distance: distance d_i from the robot centre to the obstacle set [m] (0 when inside).
        nearest_point: r_min, the closest boundary point [m], shape (2,).
        centre: mass centre [m], shape (2,).
        velocity: v_i [m/s], shape (2,) (true or estimated, see ``velocity_source``).
        angular_velocity: u_i [rad/s].
        outline: boundary vertices in the world frame [m], (n, 2); empty for a disc.
        radius: disc radius [m]; 0 for a polygon.
        bounding_radius: radius of the centroid-centred disc containing the body [m].
        velocity_source: ``"known"`` (ground truth) or ``"estimated"``.
        position_std: the sensor's declared 1-sigma noise of ``centre`` [m] (per axis); 0 when
            the sensor declares none (exact sensing, or a source that does not know it).
    """

    obstacle_id: int
    distance: float
    nearest_point: FloatArray
    centre: FloatArray
    velocity: FloatArray
    angular_velocity: float
    outline: FloatArray
    radius: float
    bounding_radius: float
    velocity_source: str = "known"
    position_std: float = 0.0

    @classmethod
    def polygon(
        cls,
        obstacle_id: int,
        distance: float,
        nearest_point: FloatArray,
        centre: FloatArray,
        velocity: FloatArray,
        angular_velocity: float,
        outline: FloatArray,
        bounding_radius: float,
    ) -> ObstacleReading:
        """A polygon's reading with its true velocity, built without the frozen ``__init__``
        (which sets each field through ``object.__setattr__``): the same object, in half the
        time, for a simulator that builds thousands of readings a second."""
        r = object.__new__(cls)
        r.__dict__.update(
            obstacle_id=obstacle_id, distance=distance, nearest_point=nearest_point,
            centre=centre, velocity=velocity, angular_velocity=angular_velocity,
            outline=outline, radius=0.0, bounding_radius=bounding_radius,
            velocity_source="known", position_std=0.0,
        )  # fmt: skip
        return r

    @property
    def is_disc(self) -> bool:
        return self.radius > 0.0

    @property
    def speed(self) -> float:
        """||v_i|| [m/s], computed once (kept in the instance's ``__dict__``, as
        ``functools.cached_property`` would keep it, without its per-access lock)."""
        got = self.__dict__.get("_speed")
        if got is None:
            got = self.__dict__["_speed"] = float(np.hypot(self.velocity[0], self.velocity[1]))
        return got


@dataclass(frozen=True)
class LidarScan:
    """Ranges [m] along ``angles`` [rad, world frame, in (-pi, pi]]; ``max_range`` where nothing
    is seen, NaN on dropout."""

    angles: FloatArray
    ranges: FloatArray
    max_range: float


@dataclass(frozen=True)
class Observation:
    """Everything a controller may use at one decision time.

    Attributes:
        time: simulation time [s].
        pose: the robot's own ``[x, y, theta]`` ([m], [m], [rad]).
        speed: the robot's current speed V_R [m/s] (its last applied command).
        goal: target point T [m], shape (2,).
        obstacles: readings of the obstacles within sensing range, nearest first.
        lidar: optional range scan.
        extras: readings of the plug-in sensors the scene mounts, by sensor name
            (:mod:`uvnav.sensors.plugins`).
    """

    time: float
    pose: FloatArray
    speed: float
    goal: FloatArray
    obstacles: tuple[ObstacleReading, ...] = ()
    lidar: LidarScan | None = None
    extras: Mapping[str, Any] = field(default_factory=dict)

    @property
    def position(self) -> FloatArray:
        return self.pose[:2]

    @property
    def heading(self) -> float:
        return float(self.pose[2])
