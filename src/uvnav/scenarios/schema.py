"""Pydantic v2 schema of a 2D scenario file (DESIGN §3): :class:`Scenario` and its parts.

The parts live beside it and are importable from here too: the robot, sensing and default law
(:mod:`uvnav.scenarios.schema_robot`), the obstacles' bodies and poses
(:mod:`uvnav.scenarios.schema_obstacle`), their motions (:mod:`uvnav.scenarios.schema_motion`),
the replayed pedestrians (:mod:`uvnav.scenarios.schema_crowd`) and the shared point and box types
(:mod:`uvnav.scenarios.schema_types`).

Every model forbids unknown fields (``extra="forbid"``) and non-finite numbers, so a typo in a YAML
file is an error, not a silently ignored key.  Units are SI and written in each field's
description (they show up in ``uvnav scenarios schema``).

Besides the per-field checks (positive limits, valid polygons, ordered ranges), the model checks the
scene as a whole at t = 0: the decision period is a positive multiple of the integration step, the
goal is not inside an obstacle, and the robot's disc does not overlap one.  Each spec knows how to
instantiate the library object it describes (:meth:`BodySpec.to_body`,
:meth:`ObstacleSpec.to_obstacle`, ...); :func:`uvnav.scenarios.build.build_episode` assembles them.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from pydantic import Field, model_validator

from uvnav.obstacles import ObstacleField, OrcaPedestrian
from uvnav.obstacles.social_force import SocialForcePedestrian
from uvnav.scenarios.errors import FieldError
from uvnav.scenarios.limits import BoundedScene, FieldEqualScene, check_timing
from uvnav.scenarios.schema_crowd import CrowdSpec
from uvnav.scenarios.schema_motion import (
    MOTION_TYPES,
    ConstantMotion,
    MotionSpec,
    OrcaCrowdMotion,
    OrcaWanderMotion,
    PluginMotion,
    RandomTurnMotion,
    ReplayMotion,
    SocialForceMotion,
    WaypointsMotion,
)
from uvnav.scenarios.schema_obstacle import BodySpec, ObstacleSpec, ObstacleStart
from uvnav.scenarios.schema_robot import (
    ControllerSpec,
    LidarSpec,
    RobotSpec,
    SensingSpec,
    SensorPluginSpec,
)
from uvnav.scenarios.schema_types import Box, Point2

__all__ = [
    "MOTION_TYPES",
    "BodySpec",
    "Box",
    "ConstantMotion",
    "ControllerSpec",
    "CrowdSpec",
    "LidarSpec",
    "MotionSpec",
    "ObstacleSpec",
    "ObstacleStart",
    "OrcaCrowdMotion",
    "OrcaWanderMotion",
    "PluginMotion",
    "Point2",
    "RandomTurnMotion",
    "ReplayMotion",
    "RobotSpec",
    "Scenario",
    "SensingSpec",
    "SensorPluginSpec",
    "SocialForceMotion",
    "WaypointsMotion",
]


class Scenario(BoundedScene, FieldEqualScene):
    """A complete scenario (DESIGN §3): robot, sensing, obstacles, timing and default controller."""

    name: str = Field(min_length=1, description="scenario name, e.g. thesis-ch2-one-obstacle")
    description: str = Field("", description="what the scene is and where it comes from")
    dim: Literal[2] = Field(2, description="dimension of the world (2 for Ch. 2 scenes)")
    dt: float = Field(0.1, gt=0, description="integration step [s]")
    control_period: float = Field(
        0.1, gt=0, description="decision period [s], a positive multiple of dt (defaults to dt)"
    )
    t_max: float = Field(60.0, gt=0, description="time limit of an episode [s]")
    goal_tolerance: float = Field(
        0.1, gt=0, description="the goal counts as reached within this distance [m]"
    )
    robot: RobotSpec
    sensing: SensingSpec = Field(default_factory=lambda: SensingSpec.model_validate({}))
    obstacles: list[ObstacleSpec] = Field(default_factory=list)
    crowd: CrowdSpec | None = Field(
        None, description="real pedestrians replayed as moving discs (appended after obstacles)"
    )
    controller: ControllerSpec = Field(default_factory=lambda: ControllerSpec.model_validate({}))

    @model_validator(mode="before")
    @classmethod
    def _default_control_period(cls, data: Any) -> Any:
        dt = data.get("dt") if isinstance(data, dict) else None
        numeric = isinstance(dt, int | float) and not isinstance(dt, bool)
        if numeric and "control_period" not in data:
            data = {**data, "control_period": data["dt"]}
        return data

    @model_validator(mode="after")
    def _consistent(self) -> Scenario:
        check_timing(self.t_max, self.dt, self.control_period)
        rng = np.random.default_rng(0)
        obstacles = [o.to_obstacle(rng, self.dt, j) for j, o in enumerate(self.obstacles)]
        if obstacles:
            field = ObstacleField.from_obstacles(obstacles)
            _, _, inside = field.nearest(np.asarray(self.robot.goal, dtype=float))
            # ORCA pedestrians walk on (CrowdNav's square crossing may start one on the goal)
            walking = np.array(
                [isinstance(o.motion, OrcaPedestrian | SocialForcePedestrian) for o in obstacles]
            )
            inside = inside & ~walking
            if inside.any():
                j = int(np.argmax(inside))
                raise FieldError(
                    "robot.goal", f"lies inside obstacle {j} ({obstacles[j].name}) at t=0"
                )
        # pedestrians walk on: one crossing the goal at t = 0 is no error, one on the start is
        if self.crowd is not None:
            obstacles += self.crowd.to_obstacles(self.t_max)
        if not obstacles:
            return self
        field = ObstacleField.from_obstacles(obstacles)
        dist, _, inside = field.nearest(np.asarray(self.robot.start, dtype=float))
        gaps = np.where(inside, -np.inf, dist - self.robot.radius)
        j = int(np.argmin(gaps))
        if gaps[j] < 0:
            raise FieldError(
                "robot.start",
                f"robot disc (radius {self.robot.radius:g} m) overlaps obstacle {j} "
                f"({obstacles[j].name}) at t=0",
            )
        return self
