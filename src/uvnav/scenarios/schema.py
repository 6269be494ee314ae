"""Pydantic v2 schema of a scenario file (DESIGN §3).

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

import itertools
import math
from functools import lru_cache
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import (
    AfterValidator,
    Field,
    ValidationInfo,
    field_validator,
    model_validator,
)

from uvnav.dynamics.unicycle import UnicycleSpec
from uvnav.obstacles import (
    Body,
    ConstantVelocity,
    DiscBody,
    MotionModel,
    Obstacle,
    ObstacleField,
    ObstacleState,
    OrcaPedestrian,
    OrcaWanderer,
    PolygonBody,
    RandomTurn,
    Replay,
    Waypoints,
    social_force,
)
from uvnav.obstacles import crowd as orca_crowd
from uvnav.obstacles.motion import motion_plugins
from uvnav.obstacles.social_force import SocialForcePedestrian
from uvnav.scenarios.errors import FieldError, ScenarioError
from uvnav.scenarios.limits import (
    BoundedScene,
    Coordinate,
    FieldEqualScene,
    FileModel,
    check_timing,
)
from uvnav.scenarios.pedestrians import (
    DATASETS,
    DEFAULT_RADIUS,
    Track,
    all_positions,
    crowd_obstacles,
    episode_tracks,
    load_tracks,
)
from uvnav.sensors.plugins import sensor_plugin
from uvnav.sim import LidarConfig, SensingConfig

Point2 = Annotated[tuple[Coordinate, Coordinate], Field(description="[x, y] [m]")]
"""A planar point ``[x, y]`` [m]."""


_Model = FileModel


def _ordered_box(value: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    if not (value[0] < value[2] and value[1] < value[3]):
        raise ValueError(f"need xmin < xmax and ymin < ymax (got {list(value)})")
    return value


#: a box ``[xmin, ymin, xmax, ymax]`` [m] with xmin < xmax and ymin < ymax
Box = Annotated[tuple[float, float, float, float], AfterValidator(_ordered_box)]


def _heading_of(vector: np.ndarray, default: float) -> float:
    """Direction [rad] of ``vector``, or ``default`` for a (near) zero vector."""
    if float(np.hypot(vector[0], vector[1])) <= 1e-12:
        return default
    return float(np.arctan2(vector[1], vector[0]))


# ------------------------------------------------------------------------------------------- robot


class RobotSpec(_Model):
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
            "'turn-then-move' (CrowdNav's: the period's turn at once, then straight)"
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
        return _heading_of(gap, 0.0)

    def to_spec(self) -> UnicycleSpec:
        """The simulator's :class:`~uvnav.dynamics.UnicycleSpec`."""
        return UnicycleSpec(
            v_max=self.v_max, u_max=self.u_max, radius=self.radius, kinematics=self.kinematics,
            accel_max=math.inf if self.accel_max is None else self.accel_max,
            turn_accel_max=math.inf if self.turn_accel_max is None else self.turn_accel_max,
        )  # fmt: skip


# ----------------------------------------------------------------------------------------- sensing


class LidarSpec(_Model):
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


class SensorPluginSpec(_Model):
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


class SensingSpec(_Model):
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


# ------------------------------------------------------------------------------------------ bodies


class BodySpec(_Model):
    """An obstacle body: exactly one of ``polygon`` or ``disc``.

    The polygon is given in the body frame; it is re-centred on its area centroid (the mass centre
    the thesis's rotation u_i refers to), so ``start.position`` is where the centroid goes.
    """

    polygon: list[Point2] | None = Field(
        None, description="simple polygon (non-convex allowed), vertices [[x, y], ...] [m]"
    )
    disc: float | None = Field(None, gt=0, description="disc radius [m]")

    @field_validator("polygon")
    @classmethod
    def _simple_polygon(
        cls, value: list[tuple[float, float]] | None
    ) -> list[tuple[float, float]] | None:
        if value is None:
            return value
        if len(value) < 3:
            raise ValueError(f"a polygon needs at least 3 vertices (got {len(value)})")
        problem = _polygon_problem(tuple(value))
        if problem is not None:
            raise ValueError(problem)
        return value

    @model_validator(mode="after")
    def _exactly_one(self) -> BodySpec:
        if (self.polygon is None) == (self.disc is None):
            raise ValueError("give exactly one of 'polygon' (vertices [m]) or 'disc' (radius [m])")
        return self

    def to_body(self) -> Body:
        """A :class:`~uvnav.obstacles.PolygonBody` (centred on its centroid) or a disc.

        Built once per shape and shared by the episodes and by the specs of the same shape (bodies
        are frozen, and re-centring a polygon costs more than the rest of an episode's set-up; a
        generator validates each of its shapes once and builds its scene from them again)."""
        verts = np.asarray(self.polygon if self.polygon is not None else [self.disc], dtype=float)
        key = (verts.shape, verts.tobytes())  # the very numbers, -0.0 included
        body = _BODIES.get(key)
        if body is None:
            body = (
                PolygonBody.from_vertices(verts)
                if self.polygon is not None
                else DiscBody(float(verts[0]))
            )
            if len(_BODIES) >= 4096:
                _BODIES.clear()
            _BODIES[key] = body
        return body


#: :meth:`BodySpec.to_body`'s bodies by their vertices' (a disc: its radius's) shape and bytes
_BODIES: dict[tuple[tuple[int, ...], bytes], Body] = {}


@lru_cache(maxsize=4096)
def _polygon_problem(vertices: tuple[tuple[float, float], ...]) -> str | None:
    """Why ``vertices`` are not a simple polygon of non-zero area (one line), or None."""
    from shapely.geometry import Polygon
    from shapely.validation import explain_validity

    poly = Polygon(vertices)
    if not poly.is_valid:
        return f"polygon is not simple: {explain_validity(poly)}"
    if poly.area <= 1e-12:
        return "polygon has zero area"
    return None


class ObstacleStart(_Model):
    """Initial pose of an obstacle."""

    position: Point2 = Field(description="mass-centre position at t = 0 [m]")
    heading: float = Field(0.0, description="rotation of the body frame at t = 0 [rad]")


# ----------------------------------------------------------------------------------------- motions


class ConstantMotion(_Model):
    """Straight line at constant velocity, constant spin (Savkin–Wang's obstacle model)."""

    type: Literal["constant"]
    velocity: tuple[float, float] = Field(description="velocity v_i [m/s], [vx, vy]")
    angular_velocity: float = Field(0.0, description="spin u_i about the mass centre [rad/s]")

    def to_model(self, rng: np.random.Generator) -> ConstantVelocity:
        """The motion model (``rng`` unused: the motion is deterministic)."""
        return ConstantVelocity(
            np.asarray(self.velocity, dtype=float), float(self.angular_velocity)
        )


class RandomTurnMotion(_Model):
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


class WaypointsMotion(_Model):
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


class ReplayMotion(_Model):
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


class OrcaCrowdMotion(_Model):
    """A pedestrian walking to ``goal`` by its own ORCA policy (:mod:`uvnav.obstacles.crowd`).

    The scene's ``orca_crowd`` pedestrians with the same ``crowd`` id form one crowd, simulated
    together by one RVO2 simulator (``pyrvo``): each avoids the others reciprocally.  The robot is
    invisible to them (CrowdNav's protocol).  At its goal a pedestrian stops but keeps stepping
    aside for the others.  Defaults are CrowdNav's (Chen et al., ICRA 2019).  The body must be a
    disc; the pedestrian starts at rest, and may start on the robot's goal (it walks on).
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


class SocialForceMotion(_Model):
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


class PluginMotion(_Model):
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

MOTION_TYPES: dict[str, type[_Model]] = {
    "constant": ConstantMotion,
    "random_turn": RandomTurnMotion,
    "waypoints": WaypointsMotion,
    "replay": ReplayMotion,
    "orca_crowd": OrcaCrowdMotion,
    "orca_wander": OrcaWanderMotion,
    "social_force": SocialForceMotion,
    "plugin": PluginMotion,
}


# ---------------------------------------------------------------------------------------- obstacle


class ObstacleSpec(_Model):
    """One moving obstacle: body, initial pose and motion."""

    name: str = Field("", description="optional label (plots, messages)")
    body: BodySpec
    start: ObstacleStart | None = Field(
        None,
        description="initial pose; optional for waypoints (first point) and replay (first sample)",
    )
    motion: MotionSpec

    @model_validator(mode="after")
    def _start_given(self) -> ObstacleSpec:
        m = self.motion
        if self.start is None and not isinstance(m, WaypointsMotion | ReplayMotion):
            raise FieldError("start", f"required for motion type {m.type!r}")
        if isinstance(m, OrcaCrowdMotion | SocialForceMotion) and self.body.disc is None:
            raise FieldError("body", f"a {m.type} pedestrian is a disc (give 'disc: RADIUS')")
        if self.start is not None and isinstance(m, ReplayMotion):
            at0 = m.to_model(np.random.default_rng(0)).position_at(0.0)
            if float(np.hypot(*(np.asarray(self.start.position) - at0))) > 1e-6:
                raise FieldError(
                    "start.position",
                    f"must match the replayed position at t=0, {at0.round(6).tolist()}, "
                    "or be omitted",
                )
        return self

    def initial_state(self, dt: float) -> ObstacleState:
        """State at t = 0: pose from ``start`` (or the path), velocity along the initial course.

        For ``random_turn`` the course starts along ``start.heading`` at the middle of the speed
        range (the first step draws the actual speed); for ``waypoints`` it points at the first
        waypoint; for ``replay`` it is the first interpolated displacement over ``dt`` [s].
        """
        m = self.motion
        heading = self.start.heading if self.start is not None else 0.0
        if isinstance(m, ReplayMotion):
            replay = m.to_model(np.random.default_rng(0))
            pos = replay.position_at(0.0)
            vel = (replay.position_at(dt) - pos) / dt
            if self.start is None:
                heading = _heading_of(vel, 0.0)
            return ObstacleState(position=pos, heading=heading, velocity=vel, angular_velocity=0.0)
        if isinstance(m, WaypointsMotion):
            pts = np.asarray(m.points, dtype=float)
            pos = (
                np.asarray(self.start.position, dtype=float)
                if self.start is not None
                else pts[0].copy()
            )
            target = (
                pts[0] if float(np.hypot(*(pts[0] - pos))) > 1e-12 else pts[min(1, len(pts) - 1)]
            )
            gap = target - pos
            dist = float(np.hypot(*gap))
            vel = gap / dist * m.speed if dist > 1e-12 else np.zeros(2)
            if self.start is None:
                heading = _heading_of(gap, 0.0)
            return ObstacleState(position=pos, heading=heading, velocity=vel, angular_velocity=0.0)
        assert self.start is not None
        pos = np.asarray(self.start.position, dtype=float)
        if isinstance(m, ConstantMotion):
            return ObstacleState(
                position=pos,
                heading=heading,
                velocity=np.asarray(m.velocity, dtype=float),
                angular_velocity=float(m.angular_velocity),
            )
        if isinstance(m, PluginMotion | OrcaCrowdMotion | SocialForceMotion):  # at rest until
            return ObstacleState(position=pos, heading=heading)
        speed = 0.5 * (m.speed[0] + m.speed[1])
        vel = speed * np.array([np.cos(heading), np.sin(heading)])
        return ObstacleState(
            position=pos, heading=heading, velocity=vel, angular_velocity=float(m.spin)
        )

    def to_obstacle(self, rng: np.random.Generator, dt: float, index: int = 0) -> Obstacle:
        """A fresh :class:`~uvnav.obstacles.Obstacle` for one episode.

        Args:
            rng: this obstacle's own generator (only ``random_turn`` draws from it).
            dt: the episode's integration step [s] (initial velocity of a replay).
            index: position in the scenario, used for the default name.
        """
        state = self.initial_state(dt)
        motion: MotionModel = self.motion.to_model(rng)
        if isinstance(motion, RandomTurn):
            motion.course = float(state.heading)
        elif isinstance(motion, OrcaWanderer) and motion.wander is not None:
            motion.wander.course = float(state.heading)
        return Obstacle(
            body=self.body.to_body(),
            state=state,
            motion=motion,
            name=self.name or f"obstacle-{index}",
        )


# ------------------------------------------------------------------------------------------- crowd


class CrowdSpec(_Model):
    """Real pedestrians replayed from a recording (:mod:`uvnav.scenarios.pedestrians`).

    At build time every pedestrian whose track overlaps the episode window becomes a disc obstacle
    of ``radius`` replaying its annotations (linear interpolation between them, times shifted so
    that ``t_start`` of the recording is t = 0).  Outside its track a pedestrian is absent: it
    takes part in no collision or clearance query and is never sensed (its motion model reports
    ``present(t)``).  Pedestrians do not react to the robot.  They are
    not bound by the thesis's (2.6)-(2.8): :func:`~uvnav.scenarios.check_constraints` reports them
    as warnings only.
    """

    dataset: str = Field(
        min_length=1,
        description="shipped sequence 'eth' or 'hotel', or a path to a track file "
        "(relative paths are taken from the scenario file's folder)",
    )
    format: Literal["obsmat", "xy4", "trajnet"] = Field(
        "obsmat",
        description="file format: ETH 'obsmat' (frame id x z y vx vz vy), 'xy4' (frame id x y) or "
        "'trajnet' (TrajNet++ ndjson); ignored for the shipped sequences",
    )
    t_start: float = Field(0.0, description="recording time that becomes t = 0 [s]")
    duration: float | None = Field(
        None, gt=0, description="length of the replayed window [s]; omitted = the scene's t_max"
    )
    radius: float = Field(DEFAULT_RADIUS, gt=0, description="pedestrian disc [m]")
    frame_rate: float | None = Field(
        None,
        gt=0,
        description="frames per second of the file [1/s]; omitted = the sequence's own (eth 15, "
        "hotel 25) or, for a file, inferred from a 0.4 s annotation period",
    )
    region: Box | None = Field(
        None, description="optional crop [xmin, ymin, xmax, ymax] [m]: samples outside are absent"
    )
    scale: float = Field(
        1.0,
        gt=0,
        description="file positions are multiplied by this to give metres (before offset)",
    )
    offset: Point2 = Field((0.0, 0.0), description="added to the scaled positions [m]")
    stitch: bool = Field(
        False,
        description="join a track that ends where another starts (at most one annotation step "
        "later, within 1 m) into one person",
    )
    at_rest: bool = Field(
        False,
        description="a person whose track starts after t = 0 waits at rest at its first position "
        "from t = 0 instead of appearing then",
    )

    @field_validator("dataset")
    @classmethod
    def _resolve(cls, value: str, info: ValidationInfo) -> str:
        if value in DATASETS:
            return value
        base = (info.context or {}).get("base_dir") if info.context else None
        path = Path(value).expanduser()
        if not path.is_absolute() and base is not None:
            path = Path(base) / path
        return str(path)

    @model_validator(mode="after")
    def _readable(self) -> CrowdSpec:
        try:
            self.tracks()
        except ScenarioError as exc:
            raise FieldError("dataset", str(exc)) from None
        return self

    def tracks(self) -> dict[int, Track]:
        """All tracks of the recording (recording times) [s], [m]."""
        return load_tracks(
            self.dataset,
            self.format,
            frame_rate=self.frame_rate,
            scale=self.scale,
            offset=(float(self.offset[0]), float(self.offset[1])),
            stitch=self.stitch,
        )

    def window(self, t_max: float) -> float:
        """Length of the replayed window [s]: ``duration`` or the scene's ``t_max``."""
        return float(self.duration) if self.duration is not None else float(t_max)

    def pieces(self, t_max: float) -> list[Track]:
        """Episode-time track pieces, :func:`uvnav.scenarios.pedestrians.episode_tracks`."""
        return episode_tracks(
            self.tracks(),
            t_start=self.t_start,
            duration=self.window(t_max),
            region=self.region,
            at_rest=self.at_rest,
        )

    def to_obstacles(self, t_max: float) -> list[Obstacle]:
        """Fresh replayed disc obstacles for one episode of a scene with time limit ``t_max``."""
        tracks = self.tracks()
        centre = all_positions(tracks).mean(axis=0)
        return crowd_obstacles(self.pieces(t_max), radius=self.radius, centre=centre)


class ControllerSpec(_Model):
    """The navigation law a scenario runs with by default."""

    name: str = Field(
        "zhang2019-v1", min_length=1, description="registered controller name, e.g. zhang2019-v1"
    )
    params: dict[str, Any] = Field(
        default_factory=dict,
        description="fields of the controller's Params (units: `uvnav controllers show NAME`)",
    )


# ---------------------------------------------------------------------------------------- scenario


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
