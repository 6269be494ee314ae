"""A moving rigid obstacle and a vectorised snapshot of many of them.

:class:`ObstacleField` is what the simulator steps and what sensors query: every obstacle's pose
and rates as arrays, over a :class:`FieldTemplate` that holds the bodies' geometry packed once per
episode (discs as radii, polygons as padded closed rings, see
:func:`uvnav.geometry.polygons.closed_rings`).  Building a field is a handful of references; the
world-frame outlines are transformed only when something asks for them.

Queries go through :meth:`ObstacleField.query`, which culls with bounding discs and then runs the
exact kernels on the obstacles that can matter.  The cull is conservative (a margin of 1e-9
relative plus 1e-9 m absolute covers the rounding of the bound), so what it returns is bit for bit
what the unculled computation gives for those obstacles, and the obstacles it leaves out are
provably farther than everything it reports.

A field may mark some bodies absent (``present``, from the motion models' optional
``present(t)``: a replayed pedestrian outside its recorded interval).  Absent bodies take part in
no query: :meth:`ObstacleField.query` (hence collision, clearance and sensing), :meth:`nearest`
and :meth:`ray_hits` skip them, whatever their stored pose.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.polygons import (
    closed_rings,
    edge_soup,
    rays_circles_hit,
    rays_rings_hit,
    ring_perp,
    rings_nearest,
    transform_points,
    transform_rings,
)
from uvnav.obstacles.bodies import Body, DiscBody, PolygonBody
from uvnav.obstacles.motion import ConstantVelocity, MotionModel, ObstacleState

#: relative and absolute [m] slack of the bounding-disc cull (far above the rounding it covers)
_CULL_REL = 1e-9
_CULL_ABS = 1e-9
_X_AXIS = np.array([1.0, 0.0])
_NO_RINGS = np.zeros((2, 0, 1))


def model_present(model: object, t: float) -> bool:
    """Whether a body moved by ``model`` exists at ``t`` [s]: its ``present(t)`` when it has one,
    else always (see :mod:`uvnav.obstacles.motion`)."""
    present = getattr(model, "present", None)
    return True if present is None else bool(present(t))


@dataclass
class Obstacle:
    """A rigid body, its current state, and the model that moves it."""

    body: Body
    state: ObstacleState
    motion: MotionModel
    name: str = ""

    @classmethod
    def moving_disc(
        cls,
        position: tuple[float, float] | FloatArray,
        radius: float,
        velocity: tuple[float, float] | FloatArray = (0.0, 0.0),
        *,
        name: str = "",
    ) -> Obstacle:
        """A disc of ``radius`` [m] at ``position`` [m] moving at constant ``velocity`` [m/s]."""
        vel = np.asarray(velocity, dtype=float)
        state = ObstacleState(np.asarray(position, dtype=float), velocity=vel)
        return cls(DiscBody(float(radius)), state, ConstantVelocity(vel), name)

    def world_outline(self) -> FloatArray:
        """Boundary vertices in the world frame [m] (a fine polygon for discs; for plots)."""
        return transform_points(self.body.outline(), self.state.position, self.state.heading)


class NearestQuery:
    """Exact nearest-point answers from one point for the obstacles that can matter.

    Made by :meth:`ObstacleField.query`; ``ids`` is a superset of (a) every obstacle whose set
    lies within ``radius`` of ``point`` and, if ``with_nearest``, (b) every obstacle nearest to
    ``point`` (smallest ``signed``).  Every obstacle not in ``ids`` is strictly farther than
    ``radius`` (and, if ``with_nearest``, than the nearest one); without ``with_nearest``, ``ids``
    may be empty.  The entries are bit for bit those :meth:`ObstacleField.nearest` gives for the
    same ids.  Read-only: the arrays may be shared with the field.

    Attributes:
        point: the query point ``(x, y)`` [m].
        radius: the radius [m] the query was made for.
        with_nearest: whether the nearest obstacle is guaranteed to be included.
        bounds: ``(low, high)`` [m], guaranteed bounds of the distance from ``point`` to the
            nearest obstacle set, from the bounding discs (``(inf, inf)`` with no obstacle).
        ids: (m,) obstacle indices, increasing.
        distance: (m,) distance to the obstacle *set* [m] (0 inside).
        nearest: (m, 2) nearest boundary point [m].
        inside: (m,) the point is inside the obstacle.
        signed: (m,) ``distance`` outside, minus the distance to the boundary inside [m].
    """

    __slots__ = (
        "_field",
        "_ring_of",
        "_rings",
        "bounds",
        "distance",
        "ids",
        "inside",
        "nearest",
        "point",
        "radius",
        "signed",
        "with_nearest",
    )

    def __init__(
        self,
        field: ObstacleField,
        point: tuple[float, float],
        radius: float,
        with_nearest: bool,
        ids: np.ndarray,
        distance: FloatArray,
        nearest: FloatArray,
        inside: np.ndarray,
        signed: FloatArray,
        rings: FloatArray,
        ring_of: np.ndarray | None,
        bounds: tuple[float, float],
    ) -> None:
        self._field = field
        self.point = point
        self.radius = radius
        self.with_nearest = with_nearest
        self.ids = ids
        self.distance = distance
        self.nearest = nearest
        self.inside = inside
        self.signed = signed
        self._rings = rings
        self._ring_of = ring_of
        self.bounds = bounds

    def __len__(self) -> int:
        return len(self.ids)

    def outline(self, i: int) -> FloatArray | None:
        """World vertices (n, 2) [m] of obstacle ``ids[i]`` (``None`` for a disc).

        Equal to ``field.polygons[ids[i]]``, taken from the rings this query transformed.
        """
        r = i if self._ring_of is None else int(self._ring_of[i])
        if r < 0:
            return None
        tpl = self._field.template
        n = int(tpl.counts[tpl.poly_row[self.ids[i]]])
        return self._rings[:, r, :n].T.copy()


class ObstacleField:
    """World-frame geometry of all obstacles at one instant.

    Attributes:
        centres: (k, 2) mass centres [m].
        velocities: (k, 2) true velocities [m/s].
        angular_velocities: (k,) true rotation rates [rad/s].
        headings: (k,) body rotations [rad].
        radii: (k,) disc radius [m], 0 for polygons.
        bounding_radii: (k,) radius of the centroid-centred disc containing each body [m].
        polygons: tuple of (n_j, 2) world vertices for every obstacle (``None`` for discs),
            built on first access.
        template: the packed body geometry.
        present: (k,) bool, False for a body that does not exist at this instant (skipped by
            every query), or ``None`` when every body is present.

    A field is a snapshot: it never changes its arrays, and callers must not either.
    """

    __slots__ = (
        "_last",
        "_polygons",
        "_world",
        "angular_velocities",
        "centres",
        "headings",
        "present",
        "template",
        "velocities",
    )

    def __init__(
        self,
        template: FieldTemplate,
        centres: FloatArray,
        headings: FloatArray,
        velocities: FloatArray,
        angular_velocities: FloatArray,
        present: np.ndarray | None = None,
    ) -> None:
        self.template = template
        self.present = None if present is None or bool(np.all(present)) else present
        self.centres = centres
        self.headings = headings
        self.velocities = velocities
        self.angular_velocities = angular_velocities
        self._polygons: tuple[FloatArray | None, ...] | None = None
        self._world: FloatArray | None = None
        self._last: NearestQuery | None = None

    @classmethod
    def from_obstacles(
        cls,
        obstacles: Sequence[Obstacle],
        template: FieldTemplate | None = None,
        *,
        t: float | None = None,
    ) -> ObstacleField:
        """Snapshot of ``obstacles``.

        Pass the episode's :class:`FieldTemplate` to skip re-packing the bodies.  With a time
        ``t`` [s], bodies whose motion model says it is not ``present(t)`` are marked absent.
        """
        tpl = (
            template
            if template is not None
            else FieldTemplate.from_bodies([o.body for o in obstacles])
        )
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
        present = None
        if t is not None:
            present = np.array([model_present(ob.motion, t) for ob in obstacles], dtype=bool)
        return tpl.field(centres, headings, velocities, omegas, present)

    def __len__(self) -> int:
        return len(self.centres)

    def __repr__(self) -> str:
        return f"ObstacleField(k={len(self)})"

    @property
    def radii(self) -> FloatArray:
        return self.template.radii

    @property
    def bounding_radii(self) -> FloatArray:
        return self.template.bounding_radii

    @property
    def is_disc(self) -> np.ndarray:
        """(k,) True for disc obstacles."""
        return self.template.radii > 0

    # ---------------------------------------------------------------- world-frame outlines

    def _transform(self, ids: np.ndarray) -> FloatArray:
        """(2, m, w) world rings of the polygon obstacles ``ids``."""
        tpl = self.template
        rows = ids if tpl.n_discs == 0 else tpl.poly_row.take(ids)
        r4 = tpl.rings4.take(rows, axis=1)
        return transform_rings(
            r4[:2], self.centres.take(ids, axis=0), self.headings.take(ids), perp=r4[2:]
        )

    def _world_rings(self) -> FloatArray:
        """(2, p, w) world rings of all polygons (rows of ``template.poly_ids``), cached."""
        if self._world is None:
            tpl = self.template
            if tpl.n_discs == 0:
                c, h = self.centres, self.headings
            else:
                c = self.centres.take(tpl.poly_ids, axis=0)
                h = self.headings.take(tpl.poly_ids)
            self._world = transform_rings(tpl.rings4[:2], c, h, perp=tpl.rings4[2:])
        return self._world

    @property
    def polygons(self) -> tuple[FloatArray | None, ...]:
        if self._polygons is None:
            tpl = self.template
            out: list[FloatArray | None] = [None] * len(self)
            if len(tpl.poly_ids):
                w = self._world_rings()
                pairs = zip(tpl.poly_ids.tolist(), tpl.counts.tolist(), strict=True)
                for r, (j, n) in enumerate(pairs):
                    out[j] = w[:, r, :n].T.copy()
            self._polygons = tuple(out)
        return self._polygons

    # ---------------------------------------------------------------- queries

    def query(
        self,
        point: FloatArray | tuple[float, float],
        radius: float = 0.0,
        *,
        nearest: bool = True,
    ) -> NearestQuery:
        """Exact nearest boundary points of the obstacles within ``radius`` [m] of ``point`` and,
        with ``nearest``, of the nearest obstacle wherever it is.

        Obstacles whose bounding disc is farther than ``radius`` (and, with ``nearest``, than an
        upper bound of the nearest obstacle's distance) are culled before the exact kernels run;
        see :class:`NearestQuery` for the guarantee.  The last answer is kept, so asking again
        from the same point for no more (the simulator's collision check, then the sensors)
        costs nothing.
        """
        px = float(point[0])
        py = float(point[1])
        last = self._last
        if (
            last is not None
            and last.point == (px, py)
            and last.radius >= radius
            and (last.with_nearest or not nearest)
        ):
            return last
        q = self._query(px, py, float(radius), nearest)
        self._last = q
        return q

    def _query(self, px: float, py: float, radius: float, with_nearest: bool) -> NearestQuery:
        tpl = self.template
        k = len(self.centres)
        cen = self.centres
        ids: np.ndarray | None = None
        maybe_inside = False
        bounds = (math.inf, math.inf)
        if k:
            dc = np.hypot(cen[:, 0] - px, cen[:, 1] - py)
            lower = dc - tpl.bounding_radii
            if self.present is not None:  # absent bodies: beyond any radius
                lower = np.where(self.present, lower, math.inf)
            j0 = int(lower.argmin())
            if math.isinf(lower[j0]):  # nobody present
                e = np.zeros(0)
                return NearestQuery(
                    self, (px, py), radius, with_nearest, np.zeros(0, dtype=np.intp), e,
                    np.zeros((0, 2)), np.zeros(0, bool), e, _NO_RINGS, None, bounds,
                )  # fmt: skip
            slack = _CULL_ABS * (1.0 + abs(px) + abs(py))
            # containment is possible only inside an obstacle's bounding disc
            maybe_inside = bool(lower[j0] <= 2.0 * slack)
            dc0 = float(dc[j0])
            r0 = float(tpl.bounding_radii[j0])
            # nearest distance: at least the smallest lower bound, at most j0's upper bound
            bounds = (
                float(lower[j0]) - _CULL_REL * dc0 - 2.0 * slack,
                (dc0 + r0) * (1.0 + _CULL_REL) + 2.0 * slack,
            )
            limit = radius * (1.0 + _CULL_REL) + slack
            if with_nearest:
                limit = max(limit, bounds[1])
            if not math.isinf(limit):
                ids = (lower <= limit).nonzero()[0]
                if len(ids) == k:
                    ids = None
            elif self.present is not None:
                ids = self.present.nonzero()[0]
        if ids is None:
            ids = tpl.all_ids
        m = len(ids)
        if m == 0:
            e = np.zeros(0)
            return NearestQuery(
                self, (px, py), radius, with_nearest, ids, e, np.zeros((0, 2)),
                np.zeros(0, bool), e, _NO_RINGS, None, bounds,
            )  # fmt: skip
        if tpl.n_discs == 0:
            # polygons only (the common case): ring r is obstacle ids[r]
            rings = self._world_rings() if m == k else self._transform(ids)
            dist, near2, ins = rings_nearest((px, py), rings, parity=maybe_inside)
            if ins is None:
                inside = np.zeros(m, dtype=bool)
            else:
                inside = ins
                dist = np.where(ins, 0.0, dist)
            near = near2.T
            ring_of = None
        else:
            dist = np.empty(m)
            near = np.empty((m, 2))
            inside = np.zeros(m, dtype=bool)
            ring_of = np.full(m, -1, dtype=np.intp)
            is_disc = tpl.poly_row.take(ids) < 0
            d_at = is_disc.nonzero()[0]
            p_at = (~is_disc).nonzero()[0]
            rings = _NO_RINGS
            if len(d_at):
                dids = ids.take(d_at)
                rad = tpl.radii.take(dids)
                c = cen.take(dids, axis=0)
                off = np.array([px, py]) - c
                r = np.hypot(off[:, 0], off[:, 1])
                safe = np.where(r > 0, r, 1.0)
                unit = np.where((r > 0)[:, None], off / safe[:, None], _X_AXIS)
                near[d_at] = c + unit * rad[:, None]
                dist[d_at] = np.maximum(r - rad, 0.0)
                inside[d_at] = r < rad
            if len(p_at):
                rings = self._transform(ids.take(p_at))
                d, near2, ins = rings_nearest((px, py), rings, parity=maybe_inside)
                if ins is not None:
                    inside[p_at] = ins
                    d = np.where(ins, 0.0, d)
                dist[p_at] = d
                near[p_at] = near2.T
                ring_of[p_at] = np.arange(len(p_at))
        signed = dist
        if maybe_inside and inside[inside.argmax()]:
            depth = np.hypot(near[:, 0] - px, near[:, 1] - py)
            signed = np.where(inside, -depth, dist)
        return NearestQuery(
            self,
            (px, py),
            radius,
            with_nearest,
            ids,
            dist,
            near,
            inside,
            signed,
            rings,
            ring_of,
            bounds,
        )

    def nearest(self, point: FloatArray) -> tuple[FloatArray, FloatArray, np.ndarray]:
        """Distance from ``point`` to each obstacle *set* [m], its nearest boundary point, and
        containment.

        Returns ``(distance (k,), nearest (k, 2), inside (k,))``.  ``distance`` is 0 for a point
        inside an obstacle (the thesis's d_i of eq. (2.5) is a distance to the set), while
        ``nearest`` is still the closest boundary point.  An absent body reads distance ``inf``,
        nearest point NaN and not inside.  Use :meth:`query` when only the obstacles within some
        radius (or the nearest one) are needed.
        """
        q = self.query(point, math.inf)
        if self.present is None:
            return q.distance.copy(), q.nearest.copy(), q.inside.copy()
        k = len(self)
        dist = np.full(k, math.inf)
        near = np.full((k, 2), math.nan)
        inside = np.zeros(k, dtype=bool)
        dist[q.ids] = q.distance
        near[q.ids] = q.nearest
        inside[q.ids] = q.inside
        return dist, near, inside

    def ray_hits(
        self, origin: FloatArray, directions: FloatArray, *, max_range: float = math.inf
    ) -> FloatArray:
        """(R, k) distance [m] along each unit ray to each obstacle's boundary, ``inf`` on a miss.

        With a finite ``max_range`` [m], obstacles whose bounding disc lies entirely beyond it are
        not ray-cast and read ``inf`` (their hits, if any, are farther than ``max_range``).  Absent
        bodies read ``inf``.
        """
        tpl = self.template
        ox = float(origin[0])
        oy = float(origin[1])
        dirs = np.asarray(directions, dtype=float)
        out = np.full((len(dirs), len(self)), np.inf)
        if len(self) == 0:
            return out
        ids = tpl.all_ids
        if not math.isinf(max_range):
            dc = np.hypot(self.centres[:, 0] - ox, self.centres[:, 1] - oy)
            slack = _CULL_ABS * (1.0 + abs(ox) + abs(oy))
            limit = max_range * (1.0 + _CULL_REL) + slack
            ids = (dc - tpl.bounding_radii <= limit).nonzero()[0]
        if self.present is not None:
            ids = ids[self.present.take(ids)]
        is_disc = tpl.poly_row.take(ids) < 0
        dids = ids[is_disc]
        pids = ids[~is_disc]
        if len(dids):
            out[:, dids] = rays_circles_hit(
                np.array([ox, oy]), dirs, self.centres.take(dids, axis=0), tpl.radii.take(dids)
            )
        if len(pids):
            out[:, pids] = rays_rings_hit((ox, oy), dirs, self._transform(pids))
        return out


@dataclass(frozen=True, eq=False)
class FieldTemplate:
    """Body geometry of an episode's obstacles, packed once so each step is a few array operations.

    Attributes:
        radii: (k,) disc radius [m], 0 for polygons.
        bounding_radii: (k,) [m].
        poly_ids: indices of the polygon obstacles.
        local: (E, 2) all polygon vertices in their body frames, polygon by polygon.
        owner: (E,) obstacle index of each vertex.
        next_vertex: (E,) index of the following vertex of the same polygon (closes each ring).
        offsets: (p + 1,) start of each polygon's vertices in ``local``.
        rings: (2, p, n_max + 1) the polygons as padded closed rings in their body frames
            (:func:`uvnav.geometry.polygons.closed_rings`), row ``i`` for ``poly_ids[i]``.
        rings4: (4, p, n_max + 1) ``rings`` and ``ring_perp(rings)`` stacked (one gather for
            :func:`uvnav.geometry.polygons.transform_rings`).
        counts: (p,) vertices per polygon.
        poly_row: (k,) row of each obstacle in ``rings`` (-1 for discs).
        all_ids: ``arange(k)``.
        n_discs: number of disc obstacles.
    """

    radii: FloatArray
    bounding_radii: FloatArray
    poly_ids: np.ndarray
    local: FloatArray
    owner: np.ndarray
    next_vertex: np.ndarray
    offsets: np.ndarray
    rings: FloatArray
    rings4: FloatArray
    counts: np.ndarray
    poly_row: np.ndarray
    all_ids: np.ndarray
    n_discs: int

    @classmethod
    def from_bodies(cls, bodies: Sequence[Body]) -> FieldTemplate:
        radii = np.array(
            [b.radius if isinstance(b, DiscBody) else 0.0 for b in bodies], dtype=float
        )
        bounds = np.array([b.bounding_radius for b in bodies], dtype=float)
        polys = [(j, b) for j, b in enumerate(bodies) if isinstance(b, PolygonBody)]
        poly_ids = np.array([j for j, _ in polys], dtype=np.intp)
        verts = [b.vertices for _, b in polys]
        _, _, offsets = edge_soup(verts)
        local = np.concatenate(verts, axis=0) if verts else np.zeros((0, 2))
        owner = np.repeat(poly_ids, np.diff(offsets)) if verts else np.zeros(0, dtype=np.intp)
        nxt = np.arange(len(local)) + 1
        if verts:
            nxt[offsets[1:] - 1] = offsets[:-1]
        rings, counts = closed_rings(verts)
        poly_row = np.full(len(bodies), -1, dtype=np.intp)
        poly_row[poly_ids] = np.arange(len(poly_ids))
        return cls(
            radii=radii,
            bounding_radii=bounds,
            poly_ids=poly_ids,
            local=local,
            owner=owner,
            next_vertex=nxt,
            offsets=offsets,
            rings=rings,
            rings4=np.concatenate((rings, ring_perp(rings))),
            counts=counts,
            poly_row=poly_row,
            all_ids=np.arange(len(bodies), dtype=np.intp),
            n_discs=len(bodies) - len(polys),
        )

    def field(
        self,
        centres: FloatArray,
        headings: FloatArray,
        velocities: FloatArray,
        omegas: FloatArray,
        present: np.ndarray | None = None,
    ) -> ObstacleField:
        """The :class:`ObstacleField` for obstacles at ``centres`` (k, 2) [m], ``headings`` (k,)
        [rad], moving at ``velocities`` (k, 2) [m/s] and ``omegas`` (k,) [rad/s]; ``present``
        (k,) bool marks the bodies that exist (``None``: all).

        The arrays are kept, not copied: do not change them afterwards.
        """
        return ObstacleField(self, centres, headings, velocities, omegas, present)

    def __len__(self) -> int:
        return len(self.radii)
