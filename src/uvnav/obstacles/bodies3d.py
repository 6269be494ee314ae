"""Rigid 3D obstacle bodies: triangle meshes, spheres and analytic star-shaped bodies.

Thesis Chapter 3 §3.2 (Y. Zhang, ICCAR 2020): obstacles are *solid* sets, not necessarily convex,
moving with velocity v_i(t) and rotating about their mass centre with rotation vector u_i(t); bodies
with inner space the robot cannot see (Fig. 3.1(b)) or narrow U-traps (Fig. 3.1(c)) are excluded.
Chapter 5 reuses these bodies (3D star-shaped obstacles for the underwater vehicle).

Every body lives in its own frame with the mass centre at the origin; a pose is ``(centre,
rotation)`` with ``world = centre + rotation @ body``.  Queries are made in the body frame (one
3x3 transform of the query point instead of transforming every vertex), exactly:

* :class:`MeshBody` — nearest surface point by the vectorised Ericson kernel with the sign from
  angle-weighted pseudo-normals, batch inside tests by the winding number, ray casts by
  Möller–Trumbore (:mod:`uvnav.geometry.mesh3d`);
* :class:`SphereBody` — closed form;
* :class:`StarBody` — an analytic star-shaped body r(d) = R0 (1 + sum_j h_j exp(k_j (d . n_j - 1)))
  (bumps h_j > 0 and dents h_j < 0 around unit directions n_j); its inside test is analytic and its
  distance queries go through :meth:`StarBody.to_mesh` (a tessellation on an icosphere whose
  vertices lie *on* the analytic surface; :meth:`StarBody.tessellation_error` measures the largest
  radial gap between the two).

Bad input (degenerate or open meshes, non-positive radii, a star function that is not positive)
raises ``ValueError`` with one line naming the problem.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.kernels3d import numba_enabled, signed_nearest_world
from uvnav.geometry.mesh3d import (
    PseudoNormals,
    Triangles,
    contains_points,
    icosphere,
    mesh_volume_centroid,
    ray_triangles,
    signed_nearest,
    validate_mesh,
)


@dataclass(frozen=True)
class MeshBody:
    """A solid bounded by a closed, outward-oriented triangle mesh (body frame, mass centre at 0).

    Build with :meth:`from_mesh`, which validates the mesh and moves the volume centroid (the mass
    centre of a uniform solid) to the origin.

    Attributes:
        vertices: (n, 3) vertices [m] in the body frame.
        faces: (m, 3) vertex indices, outward orientation.
        tri: the triangles for the kernels.
        bounding_radius: max vertex distance from the mass centre [m].
        volume: enclosed volume [m^3].
    """

    vertices: FloatArray
    faces: np.ndarray
    tri: Triangles = field(repr=False)
    normals: PseudoNormals = field(repr=False)
    bounding_radius: float
    volume: float

    @staticmethod
    def from_mesh(vertices: FloatArray, faces: np.ndarray) -> MeshBody:
        """Validated body from a mesh given in any frame (it is re-centred on its centroid).

        Raises:
            MeshError: (a ``ValueError``) the mesh is not a closed solid (see
                :func:`uvnav.geometry.mesh3d.validate_mesh`).
        """
        v, f = validate_mesh(vertices, faces)
        volume, centroid = mesh_volume_centroid(v, f)
        v = v - centroid
        return MeshBody(
            vertices=v,
            faces=f,
            tri=Triangles.from_mesh(v, f),
            normals=PseudoNormals.from_mesh(v, f),
            bounding_radius=float(np.sqrt((v * v).sum(axis=1)).max()),
            volume=abs(volume),
        )

    def nearest_body(self, p: FloatArray) -> tuple[FloatArray, float]:
        """Nearest surface point (body frame) to body-frame point ``p`` and the signed distance
        [m] (negative inside)."""
        q, d, _ = signed_nearest(p, self.tri, self.normals)
        return q, d

    def nearest_world(
        self, point: FloatArray, centre: FloatArray, rotation: FloatArray
    ) -> tuple[FloatArray, float]:
        """Nearest surface point (world) to the world point ``point`` and the signed distance
        [m], for the pose ``world = centre + rotation @ body`` (one compiled call with numba)."""
        if numba_enabled():
            t, n = self.tri, self.normals
            qx, qy, qz, d, _ = signed_nearest_world(
                np.asarray(point, dtype=float), centre, rotation, t.a, t.ab, t.ac, t.centre,
                t.radius, n.face, n.edge, n.vertex,
            )  # fmt: skip
            return np.array((qx, qy, qz)), d
        q, d = self.nearest_body(rotation.T @ (np.asarray(point, dtype=float) - centre))
        return rotation @ q + centre, d

    def contains_body(self, points: FloatArray) -> np.ndarray:
        """(n,) booleans: body-frame points inside the solid."""
        return contains_points(points, self.tri)

    def ray_body(self, origins: FloatArray, directions: FloatArray) -> FloatArray:
        """(r,) distance along each body-frame ray (unit direction) to its first hit (inf: none)."""
        t = ray_triangles(origins, directions, self.tri)
        return t.min(axis=1) if t.shape[1] else np.full(t.shape[0], np.inf)

    def outline_points(self) -> FloatArray:
        """Points that span the body (its vertices), body frame, (n, 3) [m]."""
        return self.vertices


@dataclass(frozen=True)
class SphereBody:
    """A solid ball of ``radius`` [m] (> 0) centred at the mass centre; queries in closed form."""

    radius: float
    _samples: FloatArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.radius) and self.radius > 0):
            raise ValueError(f"sphere radius must be a number > 0 (got {self.radius!r})")
        object.__setattr__(self, "_samples", icosphere(1)[0] * self.radius)

    @property
    def bounding_radius(self) -> float:
        return float(self.radius)

    @property
    def volume(self) -> float:
        return 4.0 / 3.0 * math.pi * self.radius**3

    def nearest_body(self, p: FloatArray) -> tuple[FloatArray, float]:
        # scaled by the largest coordinate first: the squares (or the norm) of tiny coordinates
        # underflow to subnormals, and dividing by those gives a direction that is not unit
        m = float(np.max(np.abs(p)))
        if m == 0.0:
            return np.array([self.radius, 0.0, 0.0]), -self.radius
        u = p / m
        k = math.hypot(float(u[0]), float(u[1]), float(u[2]))
        return u / k * self.radius, m * k - self.radius

    def nearest_world(
        self, point: FloatArray, centre: FloatArray, rotation: FloatArray
    ) -> tuple[FloatArray, float]:
        """Nearest surface point (world) and signed distance [m] for the ball at ``centre`` (its
        rotation is irrelevant)."""
        q, d = self.nearest_body(np.asarray(point, dtype=float) - centre)
        return q + centre, d

    def contains_body(self, points: FloatArray) -> np.ndarray:
        pts = np.atleast_2d(points)
        return np.asarray((pts * pts).sum(axis=1) < self.radius**2)

    def ray_body(self, origins: FloatArray, directions: FloatArray) -> FloatArray:
        o = np.atleast_2d(np.asarray(origins, dtype=float))
        d = np.atleast_2d(np.asarray(directions, dtype=float))
        b = (o * d).sum(axis=1)
        c = (o * o).sum(axis=1) - self.radius**2
        disc = b * b - c
        root = np.sqrt(np.maximum(disc, 0.0))
        t0 = -b - root
        t1 = -b + root
        t = np.where(t0 >= 0, t0, np.where(t1 >= 0, 0.0, np.inf))  # origin inside: hit at 0
        return np.where(disc >= 0, t, np.inf)

    def outline_points(self) -> FloatArray:
        """Points on the sphere (an 80-face icosphere's vertices), body frame [m]."""
        return self._samples


@dataclass(frozen=True)
class StarBody:
    """Analytic star-shaped solid ``{x : ||x|| < r(x / ||x||)}`` with
    ``r(d) = R0 (1 + sum_j h_j exp(k_j (d . n_j - 1)))``.

    Attributes:
        base_radius: R0 [m] (> 0).
        directions: (k, 3) unit bump directions n_j (normalised on construction).
        heights: (k,) relative bump heights h_j (negative: dents); r(d) must stay > 0.
        sharpness: (k,) k_j > 0 (larger: narrower bumps).
    """

    base_radius: float
    directions: FloatArray = field(default_factory=lambda: np.zeros((0, 3)))
    heights: FloatArray = field(default_factory=lambda: np.zeros(0))
    sharpness: FloatArray = field(default_factory=lambda: np.zeros(0))

    def __post_init__(self) -> None:
        if not (math.isfinite(self.base_radius) and self.base_radius > 0):
            raise ValueError(f"base_radius must be a number > 0 (got {self.base_radius!r})")
        d = np.atleast_2d(np.asarray(self.directions, dtype=float)).reshape(-1, 3)
        h = np.asarray(self.heights, dtype=float).reshape(-1)
        k = np.asarray(self.sharpness, dtype=float).reshape(-1)
        if not (len(d) == len(h) == len(k)):
            raise ValueError("directions, heights and sharpness must have the same length")
        n = np.linalg.norm(d, axis=1)
        if np.any(n < 1e-12) or not np.all(np.isfinite(d)):
            raise ValueError("bump directions must be finite non-zero vectors")
        if np.any(k <= 0) or not np.all(np.isfinite(k)) or not np.all(np.isfinite(h)):
            raise ValueError("sharpness must be > 0 and heights finite")
        if float(h[h < 0].sum()) <= -1.0:
            raise ValueError("dents too deep: 1 + sum of negative heights must stay > 0")
        object.__setattr__(self, "directions", d / n[:, None])
        object.__setattr__(self, "heights", h)
        object.__setattr__(self, "sharpness", k)

    def radius(self, dirs: FloatArray) -> FloatArray:
        """r(d) [m] for unit directions (n, 3)."""
        d = np.atleast_2d(dirs)
        if len(self.heights) == 0:
            return np.full(d.shape[0], self.base_radius)
        bumps = np.exp(self.sharpness[None] * (d @ self.directions.T - 1.0)) @ self.heights
        return np.asarray(self.base_radius * (1.0 + bumps))

    def contains_body(self, points: FloatArray) -> np.ndarray:
        """(n,) booleans: body-frame points strictly inside (analytic)."""
        p = np.atleast_2d(np.asarray(points, dtype=float))
        n = np.linalg.norm(p, axis=1)
        safe = np.where(n[:, None] > 0, p / np.where(n > 0, n, 1.0)[:, None], [1.0, 0.0, 0.0])
        return np.asarray(n < self.radius(safe))

    def to_mesh(self, subdivisions: int = 2) -> MeshBody:
        """Tessellation on an icosphere of level ``subdivisions`` with its vertices on the
        analytic surface (re-centred on the tessellation's volume centroid by :class:`MeshBody`)."""
        dirs, faces = icosphere(subdivisions)
        return MeshBody.from_mesh(dirs * self.radius(dirs)[:, None], faces)

    def tessellation_error(self, subdivisions: int = 2) -> float:
        """Largest radial gap [m] between the analytic surface and :meth:`to_mesh`'s, sampled along
        the directions of an icosphere two levels finer (a costly check, not done on building)."""
        dirs, faces = icosphere(subdivisions)
        verts = dirs * self.radius(dirs)[:, None]
        fine, _ = icosphere(subdivisions + 2)
        t = _radial_hits(fine, verts, faces)
        return float(np.abs(t - self.radius(fine)).max())


def _radial_hits(dirs: FloatArray, verts: FloatArray, faces: np.ndarray) -> FloatArray:
    """Distance from the origin along each unit direction to the mesh (first hit)."""
    tri = Triangles.from_mesh(verts, faces)
    return np.asarray(ray_triangles(np.zeros((len(dirs), 3)), dirs, tri).min(axis=1))


Body3D = MeshBody | SphereBody
"""The bodies the 3D world simulates (a :class:`StarBody` enters through its mesh)."""
