"""Shape-changing 3D obstacles with a fixed centre (thesis Chapter 5, §5.2.4, Scenes 1-3).

Reference: Y. Zhang and J. Zhang, "An Obstacle Avoidance Method for Sonar-based Robots Avoiding
Shape Changeable Obstacles in Underwater Environments", ICCAE 2022; thesis Chapter 5 §5.2.4 ("the
boundaries should be smooth, the mass centre of them are fixed, and ... the deformation rate will
not exceed 10% of the length from the point to the mass centre"; Scene 2: "a really narrow space
inside the obstacle" the robot is wider than).

Model (:class:`DeformingStar`).  A star-shaped solid about a fixed centre ``c`` with a fixed linear
shape matrix ``M = rotation @ diag(axes)``::

    S(t) = { c + M (rho d) : d in S^2, 0 <= rho < r(d, t) },
    r(d, t) = r_ref(d) (1 + delta(d, t)),
    r_ref(d) = R0 (1 + sum_k b_k Yh_k(d)),          sum_k |b_k| < 1,
    delta(d, t) = sum_k c_k sin(w_k t + phi_k) Yh_k(d),  sum_k |c_k| <= delta_max <= 0.1,

with ``Yh_k = Y_lm / sqrt((2l+1)/(4 pi))`` the real spherical harmonics of degree l = 2, 3 scaled
by Unsöld's bound (``sum_m Y_lm^2 = (2l+1)/(4 pi)``) so that ``|Yh_k| <= 1`` everywhere.  Hence, for
every direction, the surface point ``c + M r(d,t) d`` is displaced from its reference position
``c + M r_ref(d) d`` by exactly ``delta(d,t)`` times the reference centre-to-point vector, and
``|delta| <= delta_max``: the thesis's 10 % bound holds *exactly* (tested), for any ``axes``.
Degree 1 (a pure translation to first order) is left out of ``delta`` so that the volume centroid
stays at the fixed centre to second order in ``delta_max`` (its measured drift is tested).

Geometry.  Queries run on a tessellation at time ``t`` (:meth:`DeformingStar.triangles`): an
icosphere whose vertices lie *on* the analytic surface (``subdivisions`` = 3: 1280 triangles).
Distances and sonar returns are then exact for the mesh (vectorised Ericson / Möller–Trumbore
kernels of :mod:`uvnav.geometry.mesh3d`, and :func:`uvnav.sensors.sonar_array.cone_nearest`), and
differ from the analytic surface by at most the Hausdorff distance between the two, which is
bounded by the largest *radial* gap (every point of one surface has a point of the other on the same
centre ray): :meth:`DeformingStar.tessellation_error` measures that gap on a 16x finer icosphere.
The analytic ray cast (:meth:`DeformingStar.ray_cast_exact`) brackets the first sign change of
``g(s) = |M^-1 (x(s) - c)| - r(., t)`` on a fine sampling of the ray inside the bounding sphere and
refines it by bisection to ``1e-10`` m (a grazing double root thinner than the sampling step can be
missed; the tests use it to check the mesh).

Non-star bodies (:class:`CompoundBody`, Scene 2): a union of deforming stars (e.g. a horseshoe,
:func:`horseshoe`) whose ``inner_space`` box, a slot narrower than the vehicle, is known in the
world frame for the "never enters the inner space" check.  Distance to a union is the minimum of
the distances to its parts (exact outside every part); so are ray casts and cone returns.

Why not a library: trimesh/open3d are not in the dependency set and rebuilding their acceleration
structures every time step would cost more than the vectorised kernels on 1280 triangles.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.mesh3d import (
    Triangles,
    icosphere,
    mesh_volume_centroid,
    nearest_on_mesh,
    ray_triangles,
    validate_mesh,
)

#: largest deformation the thesis allows (Scene 1): 10 % of the centre-to-point length
THESIS_DEFORMATION = 0.1

_SQ = math.sqrt
_PI = math.pi
#: (degree l, Cartesian real spherical harmonic) for l = 2, 3 (m = -l..l)
_HARMONICS: tuple[tuple[int, float, str], ...] = (
    (2, 0.5 * _SQ(15 / _PI), "xy"),
    (2, 0.5 * _SQ(15 / _PI), "yz"),
    (2, 0.25 * _SQ(5 / _PI), "3zz-1"),
    (2, 0.5 * _SQ(15 / _PI), "xz"),
    (2, 0.25 * _SQ(15 / _PI), "xx-yy"),
    (3, 0.25 * _SQ(35 / (2 * _PI)), "y(3xx-yy)"),
    (3, 0.5 * _SQ(105 / _PI), "xyz"),
    (3, 0.25 * _SQ(21 / (2 * _PI)), "y(5zz-1)"),
    (3, 0.25 * _SQ(7 / _PI), "z(5zz-3)"),
    (3, 0.25 * _SQ(21 / (2 * _PI)), "x(5zz-1)"),
    (3, 0.25 * _SQ(105 / _PI), "z(xx-yy)"),
    (3, 0.25 * _SQ(35 / (2 * _PI)), "x(xx-3yy)"),
)
#: number of shape/deformation coefficients (degrees 2 and 3)
N_HARMONICS = len(_HARMONICS)


def harmonic_basis(dirs: FloatArray) -> FloatArray:
    """Real spherical harmonics of degrees 2 and 3 at unit directions, each divided by Unsöld's
    bound ``sqrt((2l+1)/(4 pi))`` so that ``|value| <= 1``: (n, 3) -> (n, 12)."""
    d = np.atleast_2d(np.asarray(dirs, dtype=float))
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    terms = {
        "xy": x * y,
        "yz": y * z,
        "3zz-1": 3 * z * z - 1,
        "xz": x * z,
        "xx-yy": x * x - y * y,
        "y(3xx-yy)": y * (3 * x * x - y * y),
        "xyz": x * y * z,
        "y(5zz-1)": y * (5 * z * z - 1),
        "z(5zz-3)": z * (5 * z * z - 3),
        "x(5zz-1)": x * (5 * z * z - 1),
        "z(xx-yy)": z * (x * x - y * y),
        "x(xx-3yy)": x * (x * x - 3 * y * y),
    }
    cols = [k * terms[name] / _SQ((2 * deg + 1) / (4 * _PI)) for deg, k, name in _HARMONICS]
    return np.stack(cols, axis=1)


@dataclass(frozen=True)
class DeformingStar:
    """A smooth star-shaped solid with a fixed centre whose radius changes in time (module doc).

    Attributes:
        centre: fixed centre c [m], (3,).
        base_radius: R0 [m] (> 0).
        shape: (12,) reference-shape coefficients b_k (sum |b_k| < 1).
        amplitude: (12,) deformation amplitudes c_k (sum |c_k| = the bound ``delta_max``).
        frequency: (12,) angular frequencies w_k [rad/s] (>= 0).
        phase: (12,) phases phi_k [rad].
        axes: (3,) positive scale factors of the shape matrix (1, 1, 1: no stretch).
        rotation: (3, 3) fixed body-to-world rotation of the shape matrix.
        subdivisions: icosphere level of the tessellation (3: 1280 triangles).
    """

    centre: FloatArray
    base_radius: float
    shape: FloatArray = field(default_factory=lambda: np.zeros(N_HARMONICS))
    amplitude: FloatArray = field(default_factory=lambda: np.zeros(N_HARMONICS))
    frequency: FloatArray = field(default_factory=lambda: np.zeros(N_HARMONICS))
    phase: FloatArray = field(default_factory=lambda: np.zeros(N_HARMONICS))
    axes: FloatArray = field(default_factory=lambda: np.ones(3))
    rotation: FloatArray = field(default_factory=lambda: np.eye(3))
    subdivisions: int = 3
    _dirs: FloatArray = field(init=False, repr=False)
    _faces: np.ndarray = field(init=False, repr=False)
    _basis: FloatArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        c = np.asarray(self.centre, dtype=float).reshape(-1)
        if c.shape != (3,) or not np.all(np.isfinite(c)):
            raise ValueError(f"centre must be a finite 3-vector (got {np.asarray(self.centre)!r})")
        if not (math.isfinite(self.base_radius) and self.base_radius > 0):
            raise ValueError(f"base_radius must be a number > 0 (got {self.base_radius!r})")
        arrs = {}
        for name in ("shape", "amplitude", "frequency", "phase"):
            a = np.asarray(getattr(self, name), dtype=float).reshape(-1)
            if a.shape != (N_HARMONICS,) or not np.all(np.isfinite(a)):
                raise ValueError(f"{name} must hold {N_HARMONICS} finite numbers")
            arrs[name] = a
        if float(np.abs(arrs["shape"]).sum()) >= 1.0:
            raise ValueError("shape coefficients too large: sum |b_k| must be < 1")
        if float(np.abs(arrs["amplitude"]).sum()) >= 1.0:
            raise ValueError("deformation amplitudes too large: sum |c_k| must be < 1")
        axes = np.asarray(self.axes, dtype=float).reshape(-1)
        if axes.shape != (3,) or not np.all(axes > 0) or not np.all(np.isfinite(axes)):
            raise ValueError("axes must be three numbers > 0")
        rot = np.asarray(self.rotation, dtype=float)
        if rot.shape != (3, 3) or not np.allclose(rot @ rot.T, np.eye(3), atol=1e-9):
            raise ValueError("rotation must be a 3x3 rotation matrix")
        dirs, faces = icosphere(int(self.subdivisions))
        for name, a in arrs.items():
            object.__setattr__(self, name, a)
        object.__setattr__(self, "centre", c)
        object.__setattr__(self, "axes", axes)
        object.__setattr__(self, "rotation", rot)
        object.__setattr__(self, "_dirs", dirs)
        object.__setattr__(self, "_faces", faces)
        object.__setattr__(self, "_basis", harmonic_basis(dirs))

    # ---------------------------------------------------------------------------- analytic shape

    @property
    def delta_max(self) -> float:
        """Bound on |delta(d, t)|: the largest relative displacement of a surface point."""
        return float(np.abs(self.amplitude).sum())

    @property
    def matrix(self) -> FloatArray:
        """Shape matrix M = rotation @ diag(axes), (3, 3)."""
        return np.asarray(self.rotation * self.axes[None, :])

    @property
    def bounding_radius(self) -> float:
        """Radius [m] of a centre-centred sphere containing the body at every time."""
        return float(
            self.base_radius
            * (1.0 + np.abs(self.shape).sum())
            * (1.0 + self.delta_max)
            * self.axes.max()
        )

    @property
    def boundary_speed(self) -> float:
        """A bound [m/s] on the speed of every surface point (and every tessellation vertex):
        ``|M r_ref(d) d| |d delta / dt| <= R0 (1 + sum |b_k|) max(axes) sum |c_k w_k|``."""
        return float(
            self.base_radius
            * (1.0 + np.abs(self.shape).sum())
            * self.axes.max()
            * np.abs(self.amplitude * self.frequency).sum()
        )

    def reference_radius(self, dirs: FloatArray, basis: FloatArray | None = None) -> FloatArray:
        """r_ref(d) [m] (shape-space radius) at unit directions (n, 3)."""
        b = harmonic_basis(dirs) if basis is None else basis
        return np.asarray(self.base_radius * (1.0 + b @ self.shape))

    def deformation(
        self, dirs: FloatArray, t: float, basis: FloatArray | None = None
    ) -> FloatArray:
        """delta(d, t) at unit directions (n, 3), time ``t`` [s]; |delta| <= delta_max."""
        b = harmonic_basis(dirs) if basis is None else basis
        return np.asarray(b @ (self.amplitude * np.sin(self.frequency * t + self.phase)))

    def radius(self, dirs: FloatArray, t: float, basis: FloatArray | None = None) -> FloatArray:
        """r(d, t) [m] (shape-space radius) at unit directions (n, 3)."""
        b = harmonic_basis(dirs) if basis is None else basis
        return self.reference_radius(dirs, b) * (1.0 + self.deformation(dirs, t, b))

    def surface_points(self, dirs: FloatArray, t: float) -> FloatArray:
        """World points of the surface at time ``t`` along shape-space directions (n, 3) [m]."""
        d = np.atleast_2d(np.asarray(dirs, dtype=float))
        return np.asarray((d * self.radius(d, t)[:, None]) @ self.matrix.T + self.centre)

    def reference_points(self, dirs: FloatArray) -> FloatArray:
        """World points of the reference surface along shape-space directions (n, 3) [m]."""
        d = np.atleast_2d(np.asarray(dirs, dtype=float))
        return np.asarray((d * self.reference_radius(d)[:, None]) @ self.matrix.T + self.centre)

    def _shape_coords(self, points: FloatArray) -> FloatArray:
        """World points -> shape space (M^-1 (p - c))."""
        p = np.atleast_2d(np.asarray(points, dtype=float)) - self.centre
        return np.asarray((p @ self.rotation) / self.axes)

    def contains(self, points: FloatArray, t: float) -> np.ndarray:
        """(n,) booleans: world points strictly inside the analytic body at time ``t``."""
        q = self._shape_coords(points)
        n = np.linalg.norm(q, axis=1)
        dirs = np.where(n[:, None] > 0, q / np.where(n > 0, n, 1.0)[:, None], [1.0, 0.0, 0.0])
        return np.asarray(n < self.radius(dirs, t))

    # ------------------------------------------------------------------------------- tessellation

    def vertices(self, t: float) -> FloatArray:
        """Tessellation vertices at time ``t`` (on the analytic surface), (n, 3) [m]."""
        r = self.radius(self._dirs, t, self._basis)
        return np.asarray((self._dirs * r[:, None]) @ self.matrix.T + self.centre)

    @property
    def faces(self) -> np.ndarray:
        """(m, 3) outward triangle indices of the tessellation (fixed topology)."""
        return self._faces

    def triangles(self, t: float) -> Triangles:
        """The tessellation at time ``t`` for the mesh kernels."""
        return Triangles.from_mesh(self.vertices(t), self._faces)

    def check_mesh(self, t: float) -> None:
        """Raise ``MeshError`` if the tessellation at ``t`` is not a valid closed solid."""
        validate_mesh(self.vertices(t), self._faces)

    def tessellation_error(self, t: float, *, samples: int = 3) -> float:
        """Largest radial gap [m] between the analytic surface and the tessellation at ``t``.

        Sampled on every face at ``samples`` x ``samples`` barycentric grid points of its corner
        directions (edges included): the direction ``u`` meets the face's plane at shape-space
        parameter ``s`` (a 3x3 solve per sample, exact), the analytic surface at ``r(u, t)``; the
        gap is ``|M u| |s - r(u, t)|`` [m] along that world ray from the centre."""
        k = max(int(samples), 1)
        ij = [(i, j) for i in range(k + 1) for j in range(k + 1 - i)]
        bary = np.array([(i / k, j / k, 1.0 - (i + j) / k) for i, j in ij])  # (q, 3)
        f = self._faces
        r_v = self.radius(self._dirs, t, self._basis)
        corners = self._dirs[f] * r_v[f][:, :, None]  # (m, 3, 3) rows: shape-space corners
        dirs_c = self._dirs[f]  # (m, 3, 3)
        u = np.einsum("qi,mij->mqj", bary, dirs_c)
        u /= np.linalg.norm(u, axis=2, keepdims=True)
        mat = np.transpose(corners, (0, 2, 1))  # columns are the corners
        beta = np.linalg.solve(mat[:, None, :, :], u[..., None])[..., 0]  # (m, q, 3)
        s_plane = 1.0 / beta.sum(axis=2)
        r_true = self.radius(u.reshape(-1, 3), t).reshape(s_plane.shape)
        scale = np.linalg.norm(u.reshape(-1, 3) @ self.matrix.T, axis=1).reshape(s_plane.shape)
        return float((np.abs(s_plane - r_true) * scale).max())

    def volume_centroid(self, t: float) -> tuple[float, FloatArray]:
        """Volume [m^3] and volume centroid [m] of the tessellation at ``t``."""
        return mesh_volume_centroid(self.vertices(t), self._faces)

    def nearest(self, point: FloatArray, t: float) -> tuple[FloatArray, float]:
        """Nearest surface point (world) of the tessellation at ``t`` and its distance [m]
        (unsigned; exact for the mesh, within :meth:`tessellation_error` of the analytic body)."""
        q, d, _ = nearest_on_mesh(np.asarray(point, dtype=float), self.triangles(t))
        return q, d

    def ray_cast(self, origins: FloatArray, directions: FloatArray, t: float) -> FloatArray:
        """Distance [m] along world rays (unit directions) to the tessellation (inf: miss)."""
        hits = ray_triangles(origins, directions, self.triangles(t))
        return np.asarray(hits.min(axis=1))

    def ray_cast_exact(
        self, origin: FloatArray, direction: FloatArray, t: float, *, samples: int = 512
    ) -> float:
        """Distance [m] along one world ray (unit direction) to the *analytic* surface at ``t``:
        first sign change of ``g(s) = |q(s)| - r(q(s)/|q(s)|, t)`` (q in shape space) on a
        ``samples``-point sampling inside the bounding sphere, refined by bisection to 1e-10 m.
        0 when the origin is inside; inf on a miss."""
        o = np.asarray(origin, dtype=float)
        d = np.asarray(direction, dtype=float)
        if bool(self.contains(o[None], t)[0]):
            return 0.0
        rb = self.bounding_radius * (1.0 + 1e-9)
        w = o - self.centre
        b = float(w @ d)
        disc = b * b - (float(w @ w) - rb * rb)
        if disc <= 0:
            return math.inf
        s0, s1 = max(-b - math.sqrt(disc), 0.0), -b + math.sqrt(disc)
        if s1 <= 0:
            return math.inf

        def g(s: FloatArray) -> FloatArray:
            q = self._shape_coords(o[None] + np.atleast_1d(s)[:, None] * d[None])
            n = np.linalg.norm(q, axis=1)
            dirs = q / np.maximum(n, 1e-300)[:, None]
            return np.asarray(n - self.radius(dirs, t))

        s = np.linspace(s0, s1, samples)
        vals = g(s)
        neg = np.flatnonzero(vals < 0)
        if len(neg) == 0:
            return math.inf
        k = int(neg[0])
        if k == 0:
            return float(s0)
        lo, hi = float(s[k - 1]), float(s[k])
        while hi - lo > 1e-10:
            mid = 0.5 * (lo + hi)
            if float(g(np.array([mid]))[0]) < 0:
                hi = mid
            else:
                lo = mid
        return 0.5 * (lo + hi)


@dataclass(frozen=True)
class CompoundBody:
    """A (possibly non-star) obstacle as a union of deforming stars, with an optional inner space.

    Attributes:
        parts: the stars whose union is the solid.
        inner_space: ``(centre (3,), rotation (3, 3), half_extents (3,))`` of a box [m] that holds
            the narrow inner space (Scene 2), or ``None``.
    """

    parts: tuple[DeformingStar, ...]
    inner_space: tuple[FloatArray, FloatArray, FloatArray] | None = None

    def __post_init__(self) -> None:
        if not self.parts:
            raise ValueError("a compound body needs at least one part")

    @property
    def centre(self) -> FloatArray:
        """Fixed reference centre [m]: the mean of the parts' centres."""
        return np.asarray(np.mean([p.centre for p in self.parts], axis=0))

    @property
    def bounding_radius(self) -> float:
        """Radius [m] of a sphere about :attr:`centre` containing the body at every time."""
        c = self.centre
        return max(float(np.linalg.norm(p.centre - c)) + p.bounding_radius for p in self.parts)

    @property
    def boundary_speed(self) -> float:
        """A bound [m/s] on the speed of every surface point (the fastest part's)."""
        return max(p.boundary_speed for p in self.parts)

    def triangles(self, t: float) -> list[Triangles]:
        """The parts' tessellations at time ``t``."""
        return [p.triangles(t) for p in self.parts]

    def contains(self, points: FloatArray, t: float) -> np.ndarray:
        """(n,) booleans: world points inside any part (analytic)."""
        inside = np.zeros(np.atleast_2d(points).shape[0], dtype=bool)
        for p in self.parts:
            inside |= p.contains(points, t)
        return inside

    def nearest(self, point: FloatArray, t: float) -> tuple[FloatArray, float]:
        """Nearest surface point [m] and distance [m] of the union (exact outside every part)."""
        best: tuple[FloatArray, float] | None = None
        for p in self.parts:
            q, d = p.nearest(point, t)
            if best is None or d < best[1]:
                best = (q, d)
        assert best is not None
        return best

    def in_inner_space(self, points: FloatArray) -> np.ndarray:
        """(n,) booleans: world points inside the inner-space box (all False without one)."""
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        if self.inner_space is None:
            return np.zeros(len(pts), dtype=bool)
        c, rot, half = self.inner_space
        local = (pts - c) @ rot
        return np.asarray(np.all(np.abs(local) <= half, axis=1))


Obstacle5 = DeformingStar | CompoundBody
"""An obstacle of the Chapter 5 world."""


def as_compound(body: Obstacle5) -> CompoundBody:
    """Any Chapter 5 obstacle as a compound body (a star is a one-part union)."""
    return body if isinstance(body, CompoundBody) else CompoundBody(parts=(body,))


def random_star(
    rng: np.random.Generator,
    centre: FloatArray,
    base_radius: float,
    *,
    shape_scale: float = 0.3,
    delta_max: float = THESIS_DEFORMATION,
    max_frequency: float = 0.5,
    axes: FloatArray | None = None,
    subdivisions: int = 3,
) -> DeformingStar:
    """A random smooth star with reference-shape coefficients of total size ``shape_scale`` (< 1),
    deformation bound exactly ``delta_max`` (<= 0.1 for the thesis's scenes) split at random over
    the 12 harmonics, and frequencies in [0, ``max_frequency``] [rad/s]."""
    if not 0.0 <= delta_max < 1.0:
        raise ValueError(f"delta_max must be in [0, 1) (got {delta_max!r})")
    if not 0.0 <= shape_scale < 1.0:
        raise ValueError(f"shape_scale must be in [0, 1) (got {shape_scale!r})")
    b = rng.normal(size=N_HARMONICS)
    b *= shape_scale / max(float(np.abs(b).sum()), 1e-12)
    w = rng.dirichlet(np.ones(N_HARMONICS)) * delta_max
    amp = w * rng.choice([-1.0, 1.0], size=N_HARMONICS)
    return DeformingStar(
        centre=np.asarray(centre, dtype=float),
        base_radius=float(base_radius),
        shape=b,
        amplitude=amp,
        frequency=rng.uniform(0.0, max_frequency, N_HARMONICS),
        phase=rng.uniform(0.0, 2 * math.pi, N_HARMONICS),
        axes=np.ones(3) if axes is None else np.asarray(axes, dtype=float),
        subdivisions=subdivisions,
    )


def horseshoe(
    centre: FloatArray,
    *,
    slot_width: float,
    arm_length: float = 2.0,
    arm_thickness: float = 0.6,
    height: float = 1.6,
    yaw: float = 0.0,
    delta_max: float = 0.05,
    frequency: float = 0.3,
    subdivisions: int = 3,
) -> CompoundBody:
    """Scene 2 obstacle: a U-shaped body (two arms on a base) with a slot of ``slot_width`` [m]
    between the arms, opening toward local +x, rotated by ``yaw`` [rad] about z.

    Each part deforms by at most ``delta_max`` of its own centre-to-point length, so the slot
    width stays within ``slot_width +- 2 delta_max arm_thickness / 2`` (:func:`max_slot_width`);
    choose ``slot_width`` below the vehicle's diameter.  ``inner_space`` is the box that stays
    free at all times (the narrow slot minus the arms' largest inward motion).
    """
    c = np.asarray(centre, dtype=float)
    cy, sy = math.cos(yaw), math.sin(yaw)
    rot = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    half_t = 0.5 * arm_thickness
    off_y = 0.5 * slot_width + half_t
    amp = np.zeros(N_HARMONICS)
    amp[[2, 4]] = 0.5 * delta_max  # two smooth l = 2 modes, sum |c_k| = delta_max
    freq = np.full(N_HARMONICS, frequency)
    parts = []
    for k, (lx, ly) in enumerate(((0.0, off_y), (0.0, -off_y))):
        local = np.array([lx, ly, 0.0])
        parts.append(
            DeformingStar(
                centre=c + rot @ local,
                base_radius=1.0,
                amplitude=amp,
                frequency=freq,
                phase=np.full(N_HARMONICS, 0.7 * k),
                axes=np.array([0.5 * arm_length, half_t, 0.5 * height]),
                rotation=rot,
                subdivisions=subdivisions,
            )
        )
    base_x = -0.5 * arm_length + 0.1 * arm_length
    parts.append(
        DeformingStar(
            centre=c + rot @ np.array([base_x, 0.0, 0.0]),
            base_radius=1.0,
            amplitude=amp,
            frequency=freq,
            phase=np.full(N_HARMONICS, 1.3),
            axes=np.array([half_t * 1.2, off_y + half_t, 0.5 * height]),
            rotation=rot,
            subdivisions=subdivisions,
        )
    )
    # the slot is narrowest (the arms thickest) over the middle of the arms; the box stops short
    # of the base (which ends at -0.28 arm_length plus its deformation)
    inner_c = c + rot @ np.array([0.05 * arm_length, 0.0, 0.0])
    # across the slot: the part that stays free however the arms deform
    half = np.array([0.2 * arm_length, 0.5 * slot_width - delta_max * half_t, 0.35 * height])
    return CompoundBody(parts=tuple(parts), inner_space=(inner_c, rot, half))


def max_slot_width(slot_width: float, arm_thickness: float, delta_max: float) -> float:
    """Upper bound [m] on the horseshoe's slot width while its arms deform: each arm surface point
    moves by at most ``delta_max`` times its distance to the arm centre, which is at most the arm's
    half-thickness across the slot (the arm is an ellipsoid-like star, so the inner face moves by
    at most ``delta_max * arm_thickness / 2`` in the slot's direction; the shape matrix is
    axis-aligned with the slot)."""
    return slot_width + 2.0 * delta_max * 0.5 * arm_thickness
