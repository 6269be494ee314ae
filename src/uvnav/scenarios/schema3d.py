"""Pydantic v2 schema of a 3D scenario file (``dim: 3``; thesis Chapter 3, later Chapter 5).

Same rules as the 2D schema (:mod:`uvnav.scenarios.schema`): unknown fields and non-finite numbers
are errors, SI units in every field's description, one-line :class:`ScenarioError` messages naming
the file, the field and the problem.  Whole-scene checks at t = 0: the decision period is a whole
multiple of dt; the heading is a unit vector; meshes are closed solids; the robot and E are not
inside or touching an obstacle; obstacle motion bounds satisfy the thesis's (3.9)
``||v_i|| < V_max`` and (3.10) ``||u_i|| < U_max``.

Example::

    name: thesis-ch3-fig3-6-whole-manoeuvre
    dim: 3
    dt: 0.05
    control_period: 0.1
    robot: {start: [0, 0, 0], goal: [20, 20, 8], v_max: 1.0, u_max: 1.0, radius: 0.1}
    obstacles:
      - body: {star: {radius: 1.5, bumps: [{direction: [1, 0, 0], height: 0.5}]}}
        start: {position: [10, 10, 4]}
        motion: {type: ar, v_mean: [-0.2, 0.3, 0.0], u_mean: [0, 0, 0.1]}
    controller: {name: zhang2020-3d-v1}
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, Field, ValidationError, model_validator

from uvnav.dynamics.vehicle3d import Vehicle3DSpec
from uvnav.geometry.frames3d import rotation_from_vector
from uvnav.geometry.mesh3d import box_mesh
from uvnav.obstacles.bodies3d import Body3D, MeshBody, SphereBody, StarBody
from uvnav.obstacles.motion3d import (
    ARMotion3D,
    ConstantMotion3D,
    MotionModel3D,
    Obstacle3D,
    ObstacleState3D,
    PeriodicMotion3D,
    Waypoints3D,
)
from uvnav.scenarios.errors import FieldError, ScenarioError, from_validation_error
from uvnav.scenarios.limits import (
    BoundedScene,
    Coordinate,
    FieldEqualScene,
    FileModel,
    check_timing,
)
from uvnav.sim.episode3d import Episode3DSetup, Sensing3DConfig, clearance3d

Point3 = Annotated[tuple[Coordinate, Coordinate, Coordinate], Field(description="[x, y, z] [m]")]
Vec3 = tuple[float, float, float]


_Model = FileModel


class Robot3DSpec(_Model):
    """The 3D vehicle, thesis (3.1)-(3.7)."""

    model: Literal["vehicle3d"] = Field("vehicle3d", description="vehicle model")
    start: Point3 = Field(description="start point S [m]")
    heading: Vec3 | None = Field(None, description="unit heading a_R(0); omitted = toward E")
    goal: Point3 = Field(description="end point E [m]")
    v_max: float = Field(gt=0, description="maximum speed V_max [m/s]")
    u_max: float = Field(gt=0, description="maximum turn rate U_max [rad/s]")
    radius: float = Field(0.1, ge=0, description="radius of the robot's sphere [m]")

    @model_validator(mode="after")
    def _unit_heading(self) -> Robot3DSpec:
        if self.heading is not None:
            n = math.sqrt(sum(x * x for x in self.heading))
            if abs(n - 1.0) > 1e-6:
                raise FieldError("heading", f"must be a unit vector (norm {n:.6g})")
        if math.dist(self.start, self.goal) < 1e-9:
            raise FieldError("goal", "must differ from start")
        return self

    def initial_heading(self) -> np.ndarray:
        if self.heading is not None:
            h = np.asarray(self.heading, float)
            return h / np.linalg.norm(h)
        gap = np.asarray(self.goal, float) - np.asarray(self.start, float)
        return gap / np.linalg.norm(gap)

    def to_spec(self) -> Vehicle3DSpec:
        return Vehicle3DSpec(self.v_max, self.u_max, self.radius)


class Sensing3DSpec(_Model):
    """What the robot knows about obstacles."""

    range: float = Field(8.0, gt=0, description="sensing range [m]")
    velocities: Literal["known", "estimated"] = Field(
        "estimated", description="'known': true v_i, u_i (oracle); 'estimated': finite differences"
    )
    position_noise: float = Field(0.0, ge=0, description="std of noise on sensed centres [m]")


class BumpSpec(_Model):
    """One bump (height > 0) or dent (height < 0) of a star-shaped body."""

    direction: Vec3 = Field(description="direction n_j from the centre (normalised)")
    height: float = Field(description="relative height h_j (radius factor 1 + h_j at n_j)")
    sharpness: float = Field(4.0, gt=0, description="k_j: larger is narrower")


class StarSpec(_Model):
    """Analytic star-shaped body r(d) = R0 (1 + sum_j h_j exp(k_j (d . n_j - 1)))."""

    radius: float = Field(gt=0, description="base radius R0 [m]")
    bumps: list[BumpSpec] = Field(default_factory=list)
    subdivisions: int = Field(2, ge=0, le=4, description="icosphere level of the tessellation")


class MeshSpec(_Model):
    """A closed triangle mesh (outward or inward orientation; degenerate faces are errors)."""

    vertices: list[Vec3] = Field(min_length=4, description="vertices [m]")
    faces: list[tuple[int, int, int]] = Field(min_length=4, description="vertex index triples")


class Body3DSpec(_Model):
    """Exactly one of ``sphere``, ``box``, ``star``, ``mesh``."""

    sphere: float | None = Field(None, gt=0, description="sphere radius [m]")
    box: Vec3 | None = Field(None, description="box half-extents [m]")
    star: StarSpec | None = None
    mesh: MeshSpec | None = None

    @model_validator(mode="after")
    def _one(self) -> Body3DSpec:
        given = [k for k in ("sphere", "box", "star", "mesh") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError(f"give exactly one of sphere, box, star, mesh (got {given or 'none'})")
        if self.box is not None and min(self.box) <= 0:
            raise FieldError("box", "half-extents must be > 0")
        try:
            self.to_body()
        except ValueError as exc:
            raise FieldError(given[0], str(exc)) from None
        return self

    def to_body(self) -> Body3D:
        if self.sphere is not None:
            return SphereBody(self.sphere)
        if self.box is not None:
            return MeshBody.from_mesh(*box_mesh(np.array(self.box, float)))
        if self.star is not None:
            s = self.star
            star = StarBody(
                s.radius,
                np.array([b.direction for b in s.bumps], float).reshape(-1, 3),
                np.array([b.height for b in s.bumps], float),
                np.array([b.sharpness for b in s.bumps], float),
            )
            return star.to_mesh(s.subdivisions)
        assert self.mesh is not None
        return MeshBody.from_mesh(np.array(self.mesh.vertices, float), np.array(self.mesh.faces))


class Start3DSpec(_Model):
    position: Point3 = Field(description="mass centre at t = 0 [m]")
    rotation: Vec3 = Field((0.0, 0.0, 0.0), description="orientation as a rotation vector [rad]")


class ConstantMotion3DSpec(_Model):
    type: Literal["constant"]
    velocity: Vec3 = Field(description="v_i [m/s]")
    rotation_rate: Vec3 = Field((0.0, 0.0, 0.0), description="u_i [rad/s]")

    def bounds(self) -> tuple[float, float]:
        return float(np.linalg.norm(self.velocity)), float(np.linalg.norm(self.rotation_rate))

    def build(self, rng: np.random.Generator) -> MotionModel3D:
        return ConstantMotion3D(np.array(self.velocity, float), np.array(self.rotation_rate, float))


class ARMotion3DSpec(_Model):
    """Slowly varying AR motion sampled every ``period`` (see :class:`ARMotion3D`)."""

    type: Literal["ar"]
    v_mean: Vec3 = Field(description="mean velocity [m/s]")
    phi: list[float] = Field([0.6, 0.2], min_length=1, max_length=6, description="AR coefficients")
    v_sigma: float = Field(0.05, ge=0, description="velocity noise std [m/s]")
    v_min: float = Field(0.02, ge=0, description="lower bound of ||v_i|| [m/s]")
    v_max: float = Field(0.5, gt=0, description="upper bound of ||v_i|| [m/s]")
    u_mean: Vec3 = Field((0.0, 0.0, 0.0), description="mean rotation vector [rad/s]")
    u_sigma: float = Field(0.02, ge=0, description="rotation noise std [rad/s]")
    u_max: float = Field(0.3, ge=0, description="upper bound of ||u_i|| [rad/s]")
    period: float = Field(1.0, gt=0, description="sampling period T_s [s]")

    @model_validator(mode="after")
    def _stationary(self) -> ARMotion3DSpec:
        roots = np.roots(np.r_[1.0, -np.asarray(self.phi)])
        if np.any(np.abs(roots) >= 1.0):
            raise FieldError("phi", "AR coefficients must give a stationary process")
        if self.v_min > self.v_max:
            raise FieldError("v_min", "must be <= v_max")
        return self

    def bounds(self) -> tuple[float, float]:
        return self.v_max, self.u_max

    def build(self, rng: np.random.Generator) -> MotionModel3D:
        return ARMotion3D(
            rng=rng, v_mean=np.array(self.v_mean, float), phi=np.array(self.phi, float),
            v_sigma=self.v_sigma, v_min=self.v_min, v_max=self.v_max,
            u_mean=np.array(self.u_mean, float), u_sigma=self.u_sigma, u_max=self.u_max,
            period=self.period,
        )  # fmt: skip


class PeriodicMotion3DSpec(_Model):
    """Weaving / circling motion about a mean velocity, sampled every ``period`` (see
    :class:`PeriodicMotion3D`)."""

    type: Literal["periodic"]
    v_mean: Vec3 = Field(description="mean velocity [m/s]")
    amp_cos: Vec3 = Field((0.0, 0.0, 0.0), description="cosine amplitude of v_i [m/s]")
    amp_sin: Vec3 = Field((0.0, 0.0, 0.0), description="sine amplitude of v_i [m/s]")
    osc_period: float = Field(gt=0, description="period of the oscillation [s]")
    phase: float = Field(0.0, description="phase at t = 0 [rad]")
    v_max: float = Field(0.5, gt=0, description="upper bound of ||v_i|| [m/s]")
    rotation_rate: Vec3 = Field((0.0, 0.0, 0.0), description="u_i [rad/s]")
    period: float = Field(1.0, gt=0, description="sampling period T_s [s]")
    damping: float = Field(1.0, gt=0, le=1, description="modulus r of the oscillator's roots")
    v_sigma: float = Field(0.0, ge=0, description="innovation std of the oscillation [m/s]")

    def bounds(self) -> tuple[float, float]:
        return self.v_max, float(np.linalg.norm(self.rotation_rate))

    def build(self, rng: np.random.Generator) -> MotionModel3D:
        return PeriodicMotion3D(
            v_mean=np.array(self.v_mean, float), amp_cos=np.array(self.amp_cos, float),
            amp_sin=np.array(self.amp_sin, float), osc_period=self.osc_period, phase=self.phase,
            v_max=self.v_max, rotation_rate=np.array(self.rotation_rate, float),
            period=self.period, damping=self.damping, v_sigma=self.v_sigma, rng=rng,
        )  # fmt: skip


class Waypoints3DSpec(_Model):
    type: Literal["waypoints"]
    points: list[Point3] = Field(min_length=1, description="waypoints [m]")
    speed: float = Field(gt=0, description="speed along the path [m/s]")
    rotation_rate: Vec3 = Field((0.0, 0.0, 0.0), description="u_i [rad/s]")
    loop: bool = Field(True, description="go back along the points at the end")

    def bounds(self) -> tuple[float, float]:
        return self.speed, float(np.linalg.norm(self.rotation_rate))

    def build(self, rng: np.random.Generator) -> MotionModel3D:
        return Waypoints3D(
            np.array(self.points, float), self.speed, np.array(self.rotation_rate, float),
            self.loop,
        )  # fmt: skip


Motion3DSpec = Annotated[
    ConstantMotion3DSpec | ARMotion3DSpec | PeriodicMotion3DSpec | Waypoints3DSpec,
    Field(discriminator="type"),
]
MOTION3D_TYPES: dict[str, type[BaseModel]] = {
    "constant": ConstantMotion3DSpec,
    "ar": ARMotion3DSpec,
    "periodic": PeriodicMotion3DSpec,
    "waypoints": Waypoints3DSpec,
}


class Obstacle3DSpec(_Model):
    body: Body3DSpec
    start: Start3DSpec
    motion: Motion3DSpec = Field(
        default_factory=lambda: ConstantMotion3DSpec(
            type="constant", velocity=(0.0, 0.0, 0.0), rotation_rate=(0.0, 0.0, 0.0)
        )
    )

    def to_obstacle(self, rng: np.random.Generator) -> Obstacle3D:
        state = ObstacleState3D(
            centre=np.array(self.start.position, float),
            rotation=rotation_from_vector(np.array(self.start.rotation, float)),
        )
        return Obstacle3D(self.body.to_body(), self.motion.build(rng), state)


class Controller3DSpec(_Model):
    name: str = Field("zhang2020-3d-v1", min_length=1, description="registered 3D law")
    params: dict[str, Any] = Field(default_factory=dict, description="the law's parameters")


class Scenario3D(BoundedScene, FieldEqualScene):
    """A complete 3D scenario."""

    name: str = Field(min_length=1)
    description: str = ""
    dim: Literal[3] = Field(description="3 for 3D scenes")
    dt: float = Field(0.05, gt=0, description="integration step [s]")
    control_period: float = Field(0.1, gt=0, description="decision period [s], a multiple of dt")
    t_max: float = Field(120.0, gt=0, description="time limit [s]")
    goal_tolerance: float = Field(0.3, gt=0, description="E is reached within this distance [m]")
    robot: Robot3DSpec
    sensing: Sensing3DSpec = Field(default_factory=lambda: Sensing3DSpec.model_validate({}))
    obstacles: list[Obstacle3DSpec] = Field(default_factory=list)
    controller: Controller3DSpec = Field(
        default_factory=lambda: Controller3DSpec.model_validate({})
    )

    @model_validator(mode="after")
    def _consistent(self) -> Scenario3D:
        check_timing(self.t_max, self.dt, self.control_period)
        for j, ob in enumerate(self.obstacles):
            v_b, u_b = ob.motion.bounds()
            if v_b >= self.robot.v_max:
                raise FieldError(
                    f"obstacles.{j}.motion",
                    f"obstacle speed bound {v_b:g} m/s must be < robot v_max (thesis (3.9))",
                )
            if u_b >= self.robot.u_max:
                raise FieldError(
                    f"obstacles.{j}.motion",
                    f"obstacle rotation bound {u_b:g} rad/s must be < robot u_max (thesis (3.10))",
                )
        obstacles = [o.to_obstacle(np.random.default_rng(0)) for o in self.obstacles]
        if obstacles:
            gap, j = clearance3d(np.array(self.robot.start, float), obstacles, self.robot.radius)
            if gap <= 0:
                raise FieldError("robot.start", f"robot overlaps obstacle {j} at t = 0")
            gap, j = clearance3d(np.array(self.robot.goal, float), obstacles, 0.0)
            if gap <= 0:
                raise FieldError("robot.goal", f"goal lies inside obstacle {j} at t = 0")
        return self

    def build(self, seed: int, *, velocities: str | None = None) -> Episode3DSetup:
        """The episode for ``seed``: obstacle ``i`` draws from child ``i`` of
        ``default_rng(seed)`` (appending obstacles does not change the others)."""
        children = np.random.default_rng(seed).spawn(max(len(self.obstacles), 1))
        obstacles = [o.to_obstacle(children[i]) for i, o in enumerate(self.obstacles)]
        sensing = Sensing3DConfig(
            sensing_range=self.sensing.range,
            velocities=(velocities or self.sensing.velocities),  # type: ignore[arg-type]
            position_noise=self.sensing.position_noise,
        )
        return Episode3DSetup(
            spec=self.robot.to_spec(),
            start=np.array(self.robot.start, float),
            heading=self.robot.initial_heading(),
            goal=np.array(self.robot.goal, float),
            obstacles=obstacles,
            dt=self.dt,
            control_period=self.control_period,
            t_max=self.t_max,
            goal_tolerance=self.goal_tolerance,
            sensing=sensing,
        )


def scenario3d_from_dict(data: dict[str, Any], source: str = "<dict>") -> Scenario3D:
    """Validate a mapping as a :class:`Scenario3D`.

    Raises:
        ScenarioError: one line naming ``source``, the field path and the problem.
    """
    try:
        sc = Scenario3D.model_validate(data)
    except ValidationError as exc:
        raise from_validation_error(exc, source, tags=tuple(MOTION3D_TYPES)) from None
    except FieldError as exc:  # pragma: no cover - pydantic wraps these
        raise ScenarioError(source, exc.path, exc.problem) from None
    sc._source = source
    return sc
