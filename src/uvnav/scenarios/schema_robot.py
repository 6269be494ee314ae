"""The robot, sensing and default-law blocks of a 2D scenario file (:class:`RobotSpec`,
:class:`SensingSpec` with its :class:`LidarSpec` and :class:`SensorPluginSpec`,
:class:`ControllerSpec`); each builds the simulator's config it describes."""

from __future__ import annotations

import math
from typing import Any, Literal

import numpy as np
from pydantic import Field, model_validator

from uvnav.dynamics.unicycle import UnicycleSpec
from uvnav.scenarios.errors import FieldError
from uvnav.scenarios.limits import FileModel
from uvnav.scenarios.schema_types import Point2, heading_of
from uvnav.sensors.plugins import sensor_plugin
from uvnav.sim import LidarConfig, SensingConfig

# ------------------------------------------------------------------------------------------- robot


class RobotSpec(FileModel):
    """The controlled vehicle, thesis Ch. 2 eqs. (2.1)-(2.4)."""

    model: Literal["unicycle"] = Field(
        "unicycle", description="vehicle model (only 'unicycle' in 2D)"
    )
    start: Point2 = Field(description="initial point I, [x, y] [m]")
    heading: float | None = Field(
        None, description="initial heading theta_0 [rad]; omitted = facing the goal"
    )
    goal: Point2 = Field(description="target point T, [x, y] [m]")
    v_max: float = Field(gt=0, description="maximum speed V_max [m/s]")
    u_max: float = Field(gt=0, description="maximum angular velocity U_max [rad/s]")
    radius: float = Field(0.1, ge=0, description="radius of the robot's disc body [m]")
    kinematics: Literal["arc", "turn-then-move"] = Field(
        "arc",
        description=(
            "how a held command moves the unicycle: 'arc' (the thesis's, a continuous turn) or "
            "'turn-then-move' (CrowdNav's: the period's turn at once, then straight; under "
            "turn_accel_max, the turn the ramped rate makes over the period)"
        ),
    )
    accel_max: float | None = Field(
        None, gt=0, description="largest rate of change of the speed [m/s^2]; omitted = at once"
    )
    turn_accel_max: float | None = Field(
        None, gt=0,
        description="largest rate of change of the turn rate [rad/s^2]; omitted = at once",
    )  # fmt: skip

    def initial_heading(self) -> float:
        """``heading`` or, when omitted, the direction from start to goal [rad]."""
        if self.heading is not None:
            return float(self.heading)
        gap = np.asarray(self.goal, dtype=float) - np.asarray(self.start, dtype=float)
        return heading_of(gap, 0.0)

    def to_spec(self) -> UnicycleSpec:
        """The simulator's :class:`~uvnav.dynamics.UnicycleSpec`."""
        return UnicycleSpec(
            v_max=self.v_max, u_max=self.u_max, radius=self.radius, kinematics=self.kinematics,
            accel_max=math.inf if self.accel_max is None else self.accel_max,
            turn_accel_max=math.inf if self.turn_accel_max is None else self.turn_accel_max,
        )  # fmt: skip


# ----------------------------------------------------------------------------------------- sensing


class LidarSpec(FileModel):
    """An optional range scanner on the robot."""

    n_rays: int = Field(72, ge=1, description="number of beams")
    max_range: float = Field(5.0, gt=0, description="maximum range [m]")
    fov: float = Field(2.0 * math.pi, gt=0, le=2.0 * math.pi, description="field of view [rad]")
    noise_std: float = Field(0.0, ge=0, description="std of additive range noise [m]")
    dropout: float = Field(0.0, ge=0, le=1, description="probability that a beam returns nothing")

    def to_config(self) -> LidarConfig:
        """The simulator's :class:`~uvnav.sim.LidarConfig`."""
        return LidarConfig(
            n_rays=self.n_rays,
            max_range=self.max_range,
            fov=self.fov,
            noise_std=self.noise_std,
            dropout=self.dropout,
        )


class SensorPluginSpec(FileModel):
    """A third-party sensor mounted on the robot (:mod:`uvnav.sensors.plugins`)."""

    name: str = Field(min_length=1, description="the plug-in's entry-point name")
    params: dict[str, Any] = Field(default_factory=dict, description="its keyword arguments")

    @model_validator(mode="after")
    def _known(self) -> SensorPluginSpec:
        try:
            sensor_plugin(self.name)
        except KeyError as exc:
            raise FieldError("name", str(exc.args[0])) from None
        return self


class SensingSpec(FileModel):
    """What the robot can know about obstacles (thesis §2.2 sensing model)."""

    range: float = Field(5.0, gt=0, description="obstacles farther than this are not seen [m]")
    velocities: Literal["known", "estimated"] = Field(
        "known",
        description="'known': true v_i, u_i (thesis assumption); 'estimated': finite differences",
    )
    position_noise: float = Field(
        0.0, ge=0, description="std of the noise on sensed centres when estimating [m]"
    )
    lidar: LidarSpec | None = Field(None, description="optional range scanner")
    plugins: list[SensorPluginSpec] = Field(
        default_factory=list,
        description="third-party sensors (entry-point group uvnav.sensors); readings in "
        "Observation.extras",
    )
    bodies: Literal["exact", "lidar"] = Field(
        "exact",
        description="the law's readings of the bodies: 'exact' geometry, or 'lidar': the bodies "
        "the scan shows (segmented, fitted as discs, tracked; needs lidar and velocities: "
        "estimated)",
    )

    @model_validator(mode="after")
    def _lidar_bodies(self) -> SensingSpec:
        if self.bodies == "lidar" and self.lidar is None:
            raise FieldError("bodies", "'lidar' needs a lidar block")
        if self.bodies == "lidar" and self.velocities != "estimated":
            raise FieldError("bodies", "'lidar' needs velocities: estimated (the scan has none)")
        return self

    def to_config(self) -> SensingConfig:
        """The simulator's :class:`~uvnav.sim.SensingConfig`."""
        return SensingConfig(
            sensing_range=self.range,
            velocities=self.velocities,
            position_noise=self.position_noise,
            lidar=self.lidar.to_config() if self.lidar is not None else None,
            plugins=tuple((p.name, dict(p.params)) for p in self.plugins),
            bodies=self.bodies,
        )


# ------------------------------------------------------------------------------------ controller


class ControllerSpec(FileModel):
    """The navigation law a scenario runs with by default."""

    name: str = Field(
        "zhang2019-v1", min_length=1, description="registered controller name, e.g. zhang2019-v1"
    )
    params: dict[str, Any] = Field(
        default_factory=dict,
        description="fields of the controller's Params (units: `uvnav controllers show NAME`)",
    )
