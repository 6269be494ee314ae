"""A moving rigid obstacle and a vectorised snapshot of many of them.

:class:`ObstacleField` is what the simulator steps and what sensors query: it holds every obstacle's
world-frame geometry as arrays (discs as centres + radii, polygons as one edge soup), rebuilt once per
integration step, so nearest-point, containment and ray queries over all obstacles are single numpy
passes (see :mod:`uvnav.geometry.polygons`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.polygons import (
    edge_soup,
    nearest_on_polygons,
    rays_circles_hit,
    rays_segments_hit,
    transform_points,
)
from uvnav.obstacles.bodies import Body, DiscBody, PolygonBody
from uvnav.obstacles.motion import MotionModel, ObstacleState


@dataclass
class Obstacle:
    """A rigid body, its current state, and the model that moves it."""

    body: Body
    state: ObstacleState
    motion: MotionModel
    name: str = ""

    def world_outline(self) -> FloatArray:
        """Boundary vertices in the world frame [m] (a fine polygon for discs; for plots)."""
        return transform_points(self.body.outline(), self.state.position, self.state.heading)


@dataclass(frozen=True)
class ObstacleField:
    """World-frame geometry of all obstacles at one instant.

    Attributes:
        centres: (k, 2) mass centres [m].
        velocities: (k, 2) true velocities [m/s].
        angular_velocities: (k,) true rotation rates [rad/s].
        headings: (k,) body rotations [rad].
        radii: (k,) disc radius [m], 0 for polygons.
        bounding_radii: (k,) radius of the centroid-centred disc containing each body [m].
        polygons: tuple of (n_j, 2) world vertices for every obstacle (``None`` for discs).
    """

    centres: FloatArray
    velocities: FloatArray
    angular_velocities: FloatArray
    headings: FloatArray
    radii: FloatArray
    bounding_radii: FloatArray
    polygons: tuple[FloatArray | None, ...]
    _poly_ids: np.ndarray
    _starts: FloatArray
    _ends: FloatArray
    _offsets: np.ndarray

    @classmethod
    def from_obstacles(cls, obstacles: Sequence[Obstacle], template: FieldTemplate | None = None) -> ObstacleField:
        """Snapshot of ``obstacles``; pass the episode's :class:`FieldTemplate` to skip re-stacking bodies."""
        tpl = template if template is not None else FieldTemplate.from_bodies([o.body for o in obstacles])
        k = len(obstacles)
        centres = np.empty((k, 2))
        velocities = np.empty((k, 2))
        omegas = np.empty(k)
        headings = np.empty(k)
        for j, ob in enumerate(obstacles):
            st = ob.state
            centres[j] = st.position
            velocities[j] = st.velocity
            omegas[j] = st.angular_velocity
            headings[j] = st.heading
        return tpl.field(centres, headings, velocities, omegas)

    def __len__(self) -> int:
        return len(self.centres)

    @property
    def is_disc(self) -> np.ndarray:
        """(k,) True for disc obstacles."""
        return self.radii > 0

    def nearest(self, point: FloatArray) -> tuple[FloatArray, FloatArray, np.ndarray]:
        """Distance from ``point`` to each obstacle *set* [m], its nearest boundary point, and containment.

        Returns ``(distance (k,), nearest (k, 2), inside (k,))``.  ``distance`` is 0 for a point inside
        an obstacle (the thesis's d_i of eq. (2.5) is a distance to the set), while ``nearest`` is
        still the closest boundary point.
        """
        p = np.asarray(point, dtype=float)
        k = len(self)
        dist = np.zeros(k)
        near = np.zeros((k, 2))
        inside = np.zeros(k, dtype=bool)
        discs = np.nonzero(self.is_disc)[0]
        if discs.size:
            off = p - self.centres[discs]
            r = np.hypot(off[:, 0], off[:, 1])
            safe = np.where(r > 0, r, 1.0)
            unit = np.where((r > 0)[:, None], off / safe[:, None], np.array([1.0, 0.0]))
            near[discs] = self.centres[discs] + unit * self.radii[discs, None]
            dist[discs] = np.maximum(r - self.radii[discs], 0.0)
            inside[discs] = r < self.radii[discs]
        if self._poly_ids.size:
            d, n, ins = nearest_on_polygons(p, self._starts, self._ends, self._offsets)
            dist[self._poly_ids] = np.where(ins, 0.0, d)
            near[self._poly_ids] = n
            inside[self._poly_ids] = ins
        return dist, near, inside

    def ray_hits(self, origin: FloatArray, directions: FloatArray) -> FloatArray:
        """(R, k) distance [m] along each unit ray to each obstacle's boundary, ``inf`` on a miss."""
        R = len(directions)
        out = np.full((R, len(self)), np.inf)
        discs = np.nonzero(self.is_disc)[0]
        if discs.size:
            out[:, discs] = rays_circles_hit(origin, directions, self.centres[discs], self.radii[discs])
        if self._poly_ids.size:
            t = rays_segments_hit(origin, directions, self._starts, self._ends)
            out[:, self._poly_ids] = np.minimum.reduceat(t, self._offsets[:-1], axis=1)
        return out


@dataclass(frozen=True)
class FieldTemplate:
    """Body geometry of an episode's obstacles, stacked once so each step is a few array operations.

    Attributes:
        radii: (k,) disc radius [m], 0 for polygons.
        bounding_radii: (k,) [m].
        poly_ids: indices of the polygon obstacles.
        local: (E, 2) all polygon vertices in their body frames, polygon by polygon.
        owner: (E,) obstacle index of each vertex.
        next_vertex: (E,) index of the following vertex of the same polygon (closes each ring).
        offsets: (p + 1,) start of each polygon's vertices in ``local``.
    """

    radii: FloatArray
    bounding_radii: FloatArray
    poly_ids: np.ndarray
    local: FloatArray
    owner: np.ndarray
    next_vertex: np.ndarray
    offsets: np.ndarray

    @classmethod
    def from_bodies(cls, bodies: Sequence[Body]) -> FieldTemplate:
        radii = np.array([b.radius if isinstance(b, DiscBody) else 0.0 for b in bodies], dtype=float)
        bounds = np.array([b.bounding_radius for b in bodies], dtype=float)
        poly_ids = np.array([j for j, b in enumerate(bodies) if isinstance(b, PolygonBody)], dtype=np.intp)
        verts = [bodies[j].vertices for j in poly_ids]  # type: ignore[union-attr]
        _, _, offsets = edge_soup(verts)
        local = np.concatenate(verts, axis=0) if verts else np.zeros((0, 2))
        owner = np.repeat(poly_ids, np.diff(offsets)) if verts else np.zeros(0, dtype=np.intp)
        nxt = np.arange(len(local)) + 1
        if verts:
            nxt[offsets[1:] - 1] = offsets[:-1]
        return cls(radii, bounds, poly_ids, local, owner, nxt, offsets)

    def field(
        self, centres: FloatArray, headings: FloatArray, velocities: FloatArray, omegas: FloatArray
    ) -> ObstacleField:
        """The :class:`ObstacleField` for obstacles at ``centres`` (k, 2) [m] and ``headings`` (k,) [rad]."""
        c = np.cos(headings[self.owner])
        s = np.sin(headings[self.owner])
        lx, ly = self.local[:, 0], self.local[:, 1]
        world = np.empty_like(self.local)
        world[:, 0] = c * lx - s * ly + centres[self.owner, 0]
        world[:, 1] = s * lx + c * ly + centres[self.owner, 1]
        polygons: list[FloatArray | None] = [None] * len(centres)
        for i, j in enumerate(self.poly_ids):
            polygons[j] = world[self.offsets[i] : self.offsets[i + 1]]
        return ObstacleField(
            centres=centres,
            velocities=velocities,
            angular_velocities=omegas,
            headings=headings,
            radii=self.radii,
            bounding_radii=self.bounding_radii,
            polygons=tuple(polygons),
            _poly_ids=self.poly_ids,
            _starts=world,
            _ends=world[self.next_vertex],
            _offsets=self.offsets,
        )
