"""The motion block of a 2D obstacle (``motion: {type: ...}``): one spec per motion model of
:mod:`uvnav.obstacles` (constant, random turn, waypoints, replay, ORCA crowd and wanderer, social
force, plug-in), chosen by ``type`` (:data:`MotionSpec`); each builds its motion model."""

from __future__ import annotations

import itertools
import math
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, field_validator, model_validator

from uvnav.obstacles import (
    ConstantVelocity,
    MotionModel,
    OrcaPedestrian,
    OrcaWanderer,
    RandomTurn,
    Replay,
    Waypoints,
    social_force,
)
from uvnav.obstacles import crowd as orca_crowd
from uvnav.obstacles.motion import motion_plugins
from uvnav.obstacles.social_force import SocialForcePedestrian
from uvnav.scenarios.errors import FieldError
from uvnav.scenarios.limits import FileModel
from uvnav.scenarios.schema_types import Box, Point2

# ----------------------------------------------------------------------------------------- motions


class ConstantMotion(FileModel):
    """Straight line at constant velocity, constant spin (Savkin–Wang's obstacle model)."""

    type: Literal["constant"]
    velocity: tuple[float, float] = Field(description="velocity v_i [m/s], [vx, vy]")
    angular_velocity: float = Field(0.0, description="spin u_i about the mass centre [rad/s]")

    def to_model(self, rng: np.random.Generator) -> ConstantVelocity:
        """The motion model (``rng`` unused: the motion is deterministic)."""
        return ConstantVelocity(
            np.asarray(self.velocity, dtype=float), float(self.angular_velocity)
        )


class RandomTurnMotion(FileModel):
    """Random wandering with bounded speed and turn rate (thesis Figs. 2.7-2.8)."""

    type: Literal["random_turn"]
    speed: tuple[Annotated[float, Field(ge=0)], Annotated[float, Field(ge=0)]] = Field(
        description="(min, max) speed ||v_i|| [m/s]"
    )
    turn_rate: tuple[float, float] = Field(description="(min, max) course turn rate [rad/s]")
    change_period: float = Field(
        1.0, gt=0, description="a new speed and turn rate are drawn this often [s]"
    )
    spin: float = Field(0.0, description="extra constant rotation of the body [rad/s]")
    arena: Box | None = Field(
        None, description="[xmin, ymin, xmax, ymax] [m]; outside it the course turns back"
    )

    @field_validator("speed", "turn_rate")
    @classmethod
    def _ordered(cls, value: tuple[float, float]) -> tuple[float, float]:
        if value[0] > value[1]:
            raise ValueError(f"min {value[0]} > max {value[1]}")
        return value

    def to_model(self, rng: np.random.Generator) -> RandomTurn:
        """The motion model, drawing from ``rng`` (the obstacle's own child generator)."""
        return RandomTurn(
            speed=(float(self.speed[0]), float(self.speed[1])),
            turn_rate=(float(self.turn_rate[0]), float(self.turn_rate[1])),
            rng=rng,
            change_period=float(self.change_period),
            spin=float(self.spin),
            arena=self.arena,
        )


class WaypointsMotion(FileModel):
    """Scripted path through waypoints at constant speed (sharp turns at the waypoints)."""

    type: Literal["waypoints"]
    points: list[Point2] = Field(min_length=1, description="waypoints [[x, y], ...] [m]")
    speed: float = Field(gt=0, description="travel speed [m/s]")
    loop: bool = Field(False, description="restart at the first waypoint after the last")
    turn_with_course: bool = Field(
        True, description="the body turns to face the course (instantaneous turns: unbounded u_i)"
    )

    def to_model(self, rng: np.random.Generator) -> Waypoints:
        """The motion model (``rng`` unused)."""
        return Waypoints(
            np.asarray(self.points, dtype=float),
            float(self.speed),
            self.loop,
            self.turn_with_course,
        )


class ReplayMotion(FileModel):
    """A recorded trajectory, linearly interpolated (e.g. pedestrians)."""

    type: Literal["replay"]
    times: list[float] = Field(min_length=1, description="sample times, strictly increasing [s]")
    positions: list[Point2] = Field(
        min_length=1, description="mass-centre positions [[x, y], ...] [m]"
    )

    @field_validator("times")
    @classmethod
    def _increasing(cls, value: list[float]) -> list[float]:
        if any(b <= a for a, b in itertools.pairwise(value)):
            raise ValueError("times must be strictly increasing")
        return value

    @model_validator(mode="after")
    def _same_length(self) -> ReplayMotion:
        if len(self.times) != len(self.positions):
            raise FieldError(
                "positions",
                f"needs one position per time ({len(self.positions)} != {len(self.times)})",
            )
        return self

    def to_model(self, rng: np.random.Generator) -> Replay:
        """The motion model (``rng`` unused)."""
        return Replay(np.asarray(self.times, dtype=float), np.asarray(self.positions, dtype=float))


class OrcaCrowdMotion(FileModel):
    """A pedestrian walking to ``goal`` by its own ORCA policy (:mod:`uvnav.obstacles.crowd`).

    The scene's ``orca_crowd`` pedestrians with the same ``crowd`` id form one crowd, simulated
    together by one RVO2 simulator (``pyrvo``): each avoids the others reciprocally.  The robot is
    invisible to them (CrowdNav's protocol).  At its goal a pedestrian stops but keeps stepping
    aside for the others, unless it has further goals (``next_goals``), which it moves on to at
    its ``change_times`` and on arriving within ``arrival`` of its goal.  Defaults are
    CrowdNav's (Chen et al., ICRA 2019).  The body must be a disc; the pedestrian starts at
    rest, and may start on the robot's goal (it walks on).
    """

    type: Literal["orca_crowd"]
    goal: Point2 = Field(description="where the pedestrian walks to [m]")
    v_pref: float = Field(
        orca_crowd.V_PREF, gt=0, description="preferred (and largest) speed [m/s]"
    )
    crowd: str = Field(
        orca_crowd.DEFAULT_CROWD,
        min_length=1,
        description="crowd id: pedestrians with the same id are simulated together",
    )
    neighbor_dist: float = Field(
        orca_crowd.NEIGHBOR_DIST, gt=0, description="RVO2 neighbour distance, centre to centre [m]"
    )
    max_neighbors: int = Field(orca_crowd.MAX_NEIGHBORS, ge=1, description="RVO2 max neighbours")
    time_horizon: float = Field(
        orca_crowd.TIME_HORIZON, gt=0, description="ORCA horizon for other pedestrians [s]"
    )
    time_horizon_obst: float = Field(
        orca_crowd.TIME_HORIZON_OBST, gt=0, description="ORCA horizon for static obstacles [s]"
    )
    safety_margin: float = Field(
        orca_crowd.SAFETY_MARGIN, ge=0, description="added to the body radius for RVO2 [m]"
    )
    period: float | None = Field(
        None,
        gt=0,
        description="decision period of the crowd [s] (omitted = every integration step dt); "
        "the same for every pedestrian of a crowd",
    )
    sees_robot: bool = Field(
        False,
        description="the robot is an agent of the crowd's ORCA: the pedestrians avoid it "
        "(CrowdNav's visible robot); false = invisible (CrowdNav's test protocol)",
    )
    next_goals: list[Point2] = Field(
        default_factory=list, description="goals after 'goal', walked to in order [m]"
    )
    change_times: list[float] = Field(
        default_factory=list,
        description="ascending times at which the pedestrian moves on to its next goal [s]",
    )
    arrival: float = Field(
        0.0,
        ge=0,
        allow_inf_nan=False,
        description="within this distance of its goal it moves on to the next [m] (0: never)",
    )

    @field_validator("change_times")
    @classmethod
    def _ascending(cls, value: list[float]) -> list[float]:
        if any(not math.isfinite(t) or t < 0 for t in value):
            raise ValueError("change times must be finite and >= 0")
        if any(b < a for a, b in itertools.pairwise(value)):
            raise ValueError("change times must be ascending")
        return value

    def to_model(self, rng: np.random.Generator) -> OrcaPedestrian:
        """The motion model (``rng`` unused: ORCA is deterministic); joined to its crowd when the
        episode's obstacles are batched (:func:`uvnav.obstacles.crowd.join_crowds`)."""
        return OrcaPedestrian(
            goal=np.asarray(self.goal, dtype=float),
            v_pref=float(self.v_pref),
            crowd_id=self.crowd,
            neighbor_dist=float(self.neighbor_dist),
            max_neighbors=int(self.max_neighbors),
            time_horizon=float(self.time_horizon),
            time_horizon_obst=float(self.time_horizon_obst),
            safety_margin=float(self.safety_margin),
            period=None if self.period is None else float(self.period),
            sees_robot=bool(self.sees_robot),
            next_goals=np.asarray(self.next_goals, dtype=float).reshape(-1, 2),
            change_times=np.asarray(self.change_times, dtype=float),
            arrival=float(self.arrival),
        )


class OrcaWanderMotion(RandomTurnMotion):
    """Random wandering (as ``random_turn``) of bodies that avoid each other by ORCA
    (:class:`~uvnav.obstacles.crowd.OrcaWanderer`).

    The ``orca_wander`` bodies with the same ``crowd`` id form one crowd, simulated together by one
    RVO2 simulator (``pyrvo``): every step each body's preferred velocity is the one its
    wandering proposes (speed and course turn rate drawn from ``speed`` and ``turn_rate`` every
    ``change_period``, turned back inside ``arena``), and ORCA changes it as little as it can so
    that no two bounding discs collide.  The body may be a polygon (its bounding disc is what the
    others avoid); it does not rotate (``spin`` must be 0).  The robot is invisible to the
    bodies.  ORCA's parameters are CrowdNav's (:class:`OrcaCrowdMotion`).
    """

    type: Literal["orca_wander"]  # type: ignore[assignment]
    crowd: str = Field(
        orca_crowd.DEFAULT_CROWD,
        min_length=1,
        description="crowd id: bodies with the same id avoid each other",
    )
    safety_margin: float = Field(
        orca_crowd.SAFETY_MARGIN, ge=0, description="added to the bounding radius for RVO2 [m]"
    )

    @field_validator("spin")
    @classmethod
    def _no_spin(cls, value: float) -> float:
        if value != 0.0:
            raise ValueError("an orca_wander body does not rotate (spin must be 0)")
        return value

    def to_model(self, rng: np.random.Generator) -> OrcaWanderer:  # type: ignore[override]
        """The motion model; its wandering draws from ``rng`` (the obstacle's own generator)."""
        return OrcaWanderer(
            goal=np.zeros(2),
            v_pref=max(float(self.speed[1]), 1e-9),
            crowd_id=self.crowd,
            safety_margin=float(self.safety_margin),
            wander=super().to_model(rng),
        )


class SocialForceMotion(FileModel):
    """A pedestrian walking by the social force model (Helbing and Molnár 1995;
    :mod:`uvnav.obstacles.social_force`); the scene's ``social_force`` pedestrians with the same
    ``crowd`` id form one crowd.  The body must be a disc."""

    type: Literal["social_force"]
    goal: Point2 = Field(description="where the pedestrian walks to [m]")
    v_pref: float = Field(1.0, gt=0, description="preferred speed v0 [m/s]")
    crowd: str = Field(social_force.DEFAULT_CROWD, min_length=1, description="crowd id")
    tau: float = Field(social_force.TAU, gt=0, description="relaxation time [s]")
    strength: float = Field(social_force.STRENGTH, gt=0, description="repulsion A [m/s^2]")
    range: float = Field(social_force.RANGE, gt=0, description="repulsion range B [m]")
    goal_radius: float = Field(
        social_force.GOAL_RADIUS, ge=0, description="it stops within this of its goal [m]"
    )
    sees_robot: bool = Field(False, description="a visible robot repels it too")

    def to_model(self, rng: np.random.Generator) -> SocialForcePedestrian:
        """The motion model (``rng`` unused: the model is deterministic)."""
        return SocialForcePedestrian(
            goal=np.asarray(self.goal, dtype=float), v_pref=float(self.v_pref),
            crowd_id=self.crowd, tau=float(self.tau), strength=float(self.strength),
            range=float(self.range), goal_radius=float(self.goal_radius),
            sees_robot=bool(self.sees_robot),
        )  # fmt: skip


class PluginMotion(FileModel):
    """A third-party motion model (entry-point group ``uvnav.motions``, see
    :data:`uvnav.obstacles.motion.MOTION_GROUP`), built from its keyword ``params``."""

    type: Literal["plugin"]
    name: str = Field(min_length=1, description="the plug-in's entry-point name")
    params: dict[str, Any] = Field(default_factory=dict, description="its keyword arguments")

    @model_validator(mode="after")
    def _builds(self) -> PluginMotion:
        plugins = motion_plugins()
        if self.name not in plugins:
            known = ", ".join(sorted(plugins)) or "none installed"
            raise FieldError("name", f"unknown motion plug-in {self.name!r} (known: {known})")
        self.to_model(np.random.default_rng(0))  # its own parameter checks, at load time
        return self

    def to_model(self, rng: np.random.Generator) -> MotionModel:
        """The plug-in's motion model, drawing from ``rng`` (the obstacle's own generator).

        Raises:
            FieldError: the plug-in refuses ``params``.
        """
        try:
            model: MotionModel = motion_plugins()[self.name](rng, **self.params)
        except (TypeError, ValueError) as exc:
            raise FieldError("params", f"{self.name}: {exc}") from None
        return model


MotionSpec = Annotated[
    ConstantMotion
    | RandomTurnMotion
    | WaypointsMotion
    | ReplayMotion
    | OrcaCrowdMotion
    | OrcaWanderMotion
    | SocialForceMotion
    | PluginMotion,
    Field(discriminator="type"),
]
"""One of the motion specs, chosen by its ``type`` field."""

MOTION_TYPES: dict[str, type[FileModel]] = {
    "constant": ConstantMotion,
    "random_turn": RandomTurnMotion,
    "waypoints": WaypointsMotion,
    "replay": ReplayMotion,
    "orca_crowd": OrcaCrowdMotion,
    "orca_wander": OrcaWanderMotion,
    "social_force": SocialForceMotion,
    "plugin": PluginMotion,
}
