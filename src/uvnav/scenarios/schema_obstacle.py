"""An obstacle of a 2D scenario file: its body (:class:`BodySpec`, a simple polygon or a disc),
its initial pose (:class:`ObstacleStart`) and its motion (:mod:`uvnav.scenarios.schema_motion`);
:meth:`ObstacleSpec.to_obstacle` builds a fresh :class:`~uvnav.obstacles.Obstacle` for one
episode."""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from pydantic import Field, field_validator, model_validator

from uvnav.obstacles import (
    Body,
    DiscBody,
    MotionModel,
    Obstacle,
    ObstacleState,
    OrcaWanderer,
    PolygonBody,
    RandomTurn,
)
from uvnav.scenarios.errors import FieldError
from uvnav.scenarios.limits import FileModel
from uvnav.scenarios.schema_motion import (
    ConstantMotion,
    MotionSpec,
    OrcaCrowdMotion,
    PluginMotion,
    ReplayMotion,
    SocialForceMotion,
    WaypointsMotion,
)
from uvnav.scenarios.schema_types import Point2, heading_of

# ------------------------------------------------------------------------------------------ bodies


class BodySpec(FileModel):
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


class ObstacleStart(FileModel):
    """Initial pose of an obstacle."""

    position: Point2 = Field(description="mass-centre position at t = 0 [m]")
    heading: float = Field(0.0, description="rotation of the body frame at t = 0 [rad]")


# ---------------------------------------------------------------------------------------- obstacle


class ObstacleSpec(FileModel):
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
                heading = heading_of(vel, 0.0)
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
                heading = heading_of(gap, 0.0)
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
