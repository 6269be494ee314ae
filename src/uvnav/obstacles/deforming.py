"""Shape-changing obstacles for the underwater scenes of thesis Ch. 4 (§4.2, Figs. 4.2 and 4.4).

Reference: Y. Zhang, *Algorithms of Real-Time Navigation and Control of Autonomous Unmanned
Vehicles*, UNSW — Chapter 4, §4.2 (originally: Y. Zhang and J. Zhang, "A Navigation Algorithm for
UUVs to Avoid Shape Changeable Obstacles", ICCAE 2022).

The chapter asks for obstacles (fish, seaweed) whose boundary is a smooth closed curve, whose
*mass centre is known and never changes*, whose *area is fixed*, and whose shape "should not change
suddenly" ("anything cannot change from square to round in one second").  No model is given; this
module supplies one:

* :class:`DeformingStar` — a star-shaped body with a time-varying Fourier radius

      r_raw(phi, t) = r0 (1 + sum_k a_k(t) cos(k phi) + b_k(t) sin(k phi)),
      a_k(t) = A_k sin(m_k w0 t + psi_k),  b_k(t) = B_k sin(n_k w0 t + chi_k),

  sampled at ``n_vertices`` fixed angles phi_j (so vertex j is a material label that moves
  continuously).  Each instant the sampled polygon is *renormalised*: shifted so that its area
  centroid is the fixed mass centre and scaled by sqrt(A / A_raw(t)) so that its (polygon) area is
  exactly the fixed area A.  Positivity: sum_k |A_k| + |B_k| <= 0.6 keeps r_raw >= 0.4 r0.
* **Bounded rate of change.**  The integer multipliers m_k, n_k make the deformation periodic with
  period 2 pi / w0, and every vertex velocity scales linearly with w0.  :meth:`DeformingStar.create`
  measures max_j |dp_j / d(w0 t)| over one period on a fine phase grid (central differences, 720
  phases) and sets w0 so that the largest vertex speed is ``max_rate / 1.1`` — the 10 % covers what
  the grid could miss.  Hence every boundary point moves (relative to the mass centre) at most
  ``max_rate`` [m/s], and two outlines dt apart are within Hausdorff distance ``max_rate * dt``.
  The property tests check this and the area to 1e-6.
* :func:`trap_polygon` — the Fig. 4.2(b) shape: a thick "C" whose deep inner space opens through a
  mouth narrower than the vehicle (the case the chapter excludes, which a navigation law must
  detect as unsafe rather than enter).  It is rigid (:class:`RigidShape`): a deforming trap would
  only add noise to the test that the vehicle never enters it.
* Optional translation: every shape has a constant ``velocity`` [m/s] of its mass centre (0 by
  default; the chapter's obstacles stay in place, "a moving obstacle" is mentioned for Fig. 4.9).

Why not shapely: the outlines are computed every integration step for every obstacle; a few numpy
operations per body (precomputed cos/sin tables) are far cheaper than building geometry objects.
The existing kernels :func:`~uvnav.geometry.polygons.polygon_area` and
:func:`~uvnav.geometry.polygons.polygon_centroid` are reused.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.geometry.polygons import polygon_area, polygon_centroid

#: margin between the calibrated rate and the requested bound (see module docstring)
RATE_MARGIN = 1.1
_CALIBRATION_PHASES = 720
#: largest total relative amplitude sum_k |A_k| + |B_k|
MAX_RELATIVE_AMPLITUDE = 0.6


def _area_centroid(v: FloatArray) -> tuple[float, FloatArray]:
    return polygon_area(v), polygon_centroid(v)


@dataclass(frozen=True)
class DeformingStar:
    """A star-shaped body of fixed area and mass centre whose Fourier radius changes over time.

    Build with :meth:`create` (it calibrates ``omega0`` to the rate bound); the fields are the
    model's constants.

    Attributes:
        centre: mass centre at t = 0 [m], (2,).
        area: the fixed area A [m^2].
        r0: mean raw radius [m] (only the shape matters after renormalisation).
        amplitudes: (K, 2) relative amplitudes (A_k, B_k) of harmonic k = 1..K.
        multipliers: (K, 2) integer frequency multipliers (m_k, n_k).
        phases: (K, 2) phases (psi_k, chi_k) [rad].
        omega0: base angular frequency w0 [rad/s] (0: a rigid shape).
        max_rate: guaranteed bound on every boundary point's speed relative to the mass centre
            [m/s].
        velocity: constant velocity of the mass centre [m/s], (2,).
        n_vertices: number of boundary samples.
    """

    centre: FloatArray
    area: float
    r0: float
    amplitudes: FloatArray
    multipliers: FloatArray
    phases: FloatArray
    omega0: float
    max_rate: float
    velocity: FloatArray = field(default_factory=lambda: np.zeros(2))
    n_vertices: int = 96

    # ---------------------------------------------------------------------------- construction
    @classmethod
    def create(
        cls,
        centre: FloatArray | tuple[float, float],
        area: float,
        amplitudes: FloatArray,
        *,
        max_rate: float,
        multipliers: FloatArray | None = None,
        phases: FloatArray | None = None,
        velocity: FloatArray | tuple[float, float] = (0.0, 0.0),
        n_vertices: int = 96,
        calibrate: bool = True,
    ) -> DeformingStar:
        """A deforming star whose boundary points move at most ``max_rate`` [m/s].

        Args:
            centre: fixed mass centre [m].
            area: fixed area [m^2] (> 0).
            amplitudes: (K, 2) relative Fourier amplitudes; sum of absolute values <= 0.6.
            max_rate: bound on the boundary speed relative to the mass centre [m/s] (>= 0).
            multipliers: (K, 2) positive integers (default: all 1).
            phases: (K, 2) phases [rad] (default: 0).
            velocity: translation of the mass centre [m/s].
            n_vertices: boundary samples (>= 8).
            calibrate: False skips the rate calibration (w0 = 1 rad/s, rate *not* bounded): a
                cheap preview of the shapes for placement tests.

        Raises:
            ValueError: invalid area, amplitudes, rate or sample count.
        """
        amp = np.atleast_2d(np.asarray(amplitudes, dtype=float))
        if amp.ndim != 2 or amp.shape[1] != 2:
            raise ValueError("amplitudes must have shape (K, 2)")
        if not (area > 0 and np.isfinite(area)):
            raise ValueError(f"area must be a positive number of m^2 (got {area!r})")
        if not (max_rate >= 0 and np.isfinite(max_rate)):
            raise ValueError(f"max_rate must be a number >= 0 m/s (got {max_rate!r})")
        if float(np.abs(amp).sum()) > MAX_RELATIVE_AMPLITUDE + 1e-12:
            raise ValueError(
                f"sum of |amplitudes| must be <= {MAX_RELATIVE_AMPLITUDE} (star shape, r > 0)"
            )
        if n_vertices < 8:
            raise ValueError("n_vertices must be >= 8")
        k = len(amp)
        mult = np.ones((k, 2)) if multipliers is None else np.asarray(multipliers, dtype=float)
        ph = np.zeros((k, 2)) if phases is None else np.asarray(phases, dtype=float)
        if mult.shape != (k, 2) or ph.shape != (k, 2):
            raise ValueError("multipliers and phases must have the shape of amplitudes")
        if np.any(mult < 1) or np.any(mult != np.round(mult)):
            raise ValueError("multipliers must be positive integers (periodic deformation)")
        r0 = float(np.sqrt(area / np.pi))
        proto = cls(
            centre=np.asarray(centre, dtype=float),
            area=float(area),
            r0=r0,
            amplitudes=amp,
            multipliers=mult,
            phases=ph,
            omega0=1.0,
            max_rate=float(max_rate),
            velocity=np.asarray(velocity, dtype=float),
            n_vertices=int(n_vertices),
        )
        if not calibrate:
            return proto
        peak = proto.peak_phase_speed()
        omega0 = 0.0 if peak <= 0.0 or max_rate == 0.0 else max_rate / (RATE_MARGIN * peak)
        return cls(
            centre=proto.centre,
            area=proto.area,
            r0=r0,
            amplitudes=amp,
            multipliers=mult,
            phases=ph,
            omega0=float(omega0),
            max_rate=float(max_rate),
            velocity=proto.velocity,
            n_vertices=int(n_vertices),
        )

    @classmethod
    def random(
        cls,
        rng: np.random.Generator,
        centre: FloatArray | tuple[float, float],
        area: float,
        *,
        max_rate: float,
        n_harmonics: int = 4,
        roughness: float = 0.35,
        velocity: FloatArray | tuple[float, float] = (0.0, 0.0),
        n_vertices: int = 96,
        calibrate: bool = True,
    ) -> DeformingStar:
        """A random deforming star (seeded): harmonics 2..n_harmonics+1 (harmonic 1 is only a
        shift, which the renormalisation removes), total relative amplitude ``roughness``
        (<= 0.6), integer frequency multipliers in 1..3, uniform phases."""
        k = int(n_harmonics)
        raw = rng.uniform(0.2, 1.0, size=(k, 2)) / np.arange(1, k + 1)[:, None]
        amp = raw * min(roughness, MAX_RELATIVE_AMPLITUDE) / raw.sum()
        amp = np.vstack([np.zeros((1, 2)), amp])  # k = 1 row: no first harmonic
        mult = np.vstack([np.ones((1, 2)), rng.integers(1, 4, size=(k, 2)).astype(float)])
        ph = np.vstack([np.zeros((1, 2)), rng.uniform(0.0, 2.0 * np.pi, size=(k, 2))])
        return cls.create(
            centre,
            area,
            amp,
            max_rate=max_rate,
            multipliers=mult,
            phases=ph,
            velocity=velocity,
            n_vertices=n_vertices,
            calibrate=calibrate,
        )

    # -------------------------------------------------------------------------------- geometry
    @property
    def angles(self) -> FloatArray:
        """The fixed sample angles phi_j [rad], (n_vertices,)."""
        return np.linspace(0.0, 2.0 * np.pi, self.n_vertices, endpoint=False)

    @cached_property
    def _tables(self) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """cos(k phi_j), sin(k phi_j) (K, n) and cos(phi_j), sin(phi_j) (n,)."""
        phi = self.angles
        harm = np.arange(1, len(self.amplitudes) + 1)[:, None] * phi[None, :]
        return np.cos(harm), np.sin(harm), np.cos(phi), np.sin(phi)

    def _raw_at_phase(self, theta: FloatArray) -> FloatArray:
        """Raw (un-normalised) vertices for phases ``theta`` = w0 t, shape (P, n, 2)."""
        th = np.atleast_1d(np.asarray(theta, dtype=float))
        cos_t, sin_t, cphi, sphi = self._tables
        arg = self.multipliers[None, :, :] * th[:, None, None] + self.phases[None, :, :]
        ab = self.amplitudes[None, :, :] * np.sin(arg)  # (P, K, 2)
        r = self.r0 * (1.0 + ab[:, :, 0] @ cos_t + ab[:, :, 1] @ sin_t)  # (P, n)
        out = np.empty((*r.shape, 2))
        out[..., 0] = r * cphi
        out[..., 1] = r * sphi
        return out

    def _normalise(self, raw: FloatArray) -> FloatArray:
        """Local vertices (mass centre at the origin, area exactly ``area``), shape (P, n, 2)."""
        x, y = raw[..., 0], raw[..., 1]
        xn, yn = np.roll(x, -1, axis=-1), np.roll(y, -1, axis=-1)
        cross = x * yn - xn * y
        a = 0.5 * cross.sum(axis=-1)  # (P,)
        cx = ((x + xn) * cross).sum(axis=-1) / (6.0 * a)
        cy = ((y + yn) * cross).sum(axis=-1) / (6.0 * a)
        scale = np.sqrt(self.area / a)
        out = np.empty_like(raw)
        out[..., 0] = (x - cx[:, None]) * scale[:, None]
        out[..., 1] = (y - cy[:, None]) * scale[:, None]
        return out

    def local_outline(self, t: float) -> FloatArray:
        """Vertices (n, 2) [m] relative to the mass centre at time ``t`` [s], counter-clockwise."""
        return self._normalise(self._raw_at_phase(np.array([self.omega0 * t])))[0]

    def centre_at(self, t: float) -> FloatArray:
        """Mass centre [m] at time ``t`` [s]."""
        return np.asarray(self.centre + self.velocity * t, dtype=float)

    def outline(self, t: float) -> FloatArray:
        """World vertices (n, 2) [m] at time ``t`` [s]."""
        return self.local_outline(t) + self.centre_at(t)

    def outlines(self, times: FloatArray) -> FloatArray:
        """World vertices (T, n, 2) [m] at many times (vectorised)."""
        ts = np.asarray(times, dtype=float)
        loc = self._normalise(self._raw_at_phase(self.omega0 * ts))
        return loc + (self.centre[None, :] + ts[:, None] * self.velocity[None, :])[:, None, :]

    def peak_phase_speed(self) -> float:
        """max_j |d p_j / d theta| over one period (theta = w0 t) [m/rad], on a fine phase grid."""
        th = np.linspace(0.0, 2.0 * np.pi, _CALIBRATION_PHASES, endpoint=False)
        h = 1e-5
        plus = self._normalise(self._raw_at_phase(th + h))
        minus = self._normalise(self._raw_at_phase(th - h))
        speed = np.hypot(*(plus - minus).transpose(2, 0, 1)) / (2.0 * h)
        return float(speed.max())

    @cached_property
    def bounding_radius(self) -> float:
        """A radius [m] about the mass centre containing the body at every time: the largest
        vertex distance over 256 phases of a period, plus 5 % for what lies between them."""
        th = np.linspace(0.0, 2.0 * np.pi, 256, endpoint=False)
        loc = self._normalise(self._raw_at_phase(th))
        return float(np.hypot(loc[..., 0], loc[..., 1]).max()) * 1.05


@dataclass(frozen=True)
class RigidShape:
    """A polygon of fixed shape (e.g. the Fig. 4.2(b) trap), optionally translating.

    Attributes:
        local: (n, 2) vertices relative to the mass centre [m], counter-clockwise.
        centre: mass centre at t = 0 [m].
        velocity: mass-centre velocity [m/s].
    """

    local: FloatArray
    centre: FloatArray
    velocity: FloatArray = field(default_factory=lambda: np.zeros(2))
    max_rate: float = 0.0

    @classmethod
    def from_vertices(
        cls, vertices: FloatArray, velocity: FloatArray | tuple[float, float] = (0.0, 0.0)
    ) -> RigidShape:
        """Re-centre world ``vertices`` on their area centroid (counter-clockwise order)."""
        v = np.asarray(vertices, dtype=float)
        area, c = _area_centroid(v)
        if abs(area) < 1e-12:
            raise ValueError("polygon has zero area")
        loc = v - c
        if area < 0:
            loc = loc[::-1].copy()
        return cls(local=loc, centre=c, velocity=np.asarray(velocity, dtype=float))

    @property
    def area(self) -> float:
        return polygon_area(self.local)

    def centre_at(self, t: float) -> FloatArray:
        return np.asarray(self.centre + self.velocity * t, dtype=float)

    def local_outline(self, t: float) -> FloatArray:
        return self.local

    def outline(self, t: float) -> FloatArray:
        return self.local + self.centre_at(t)

    @property
    def bounding_radius(self) -> float:
        return float(np.hypot(self.local[:, 0], self.local[:, 1]).max())


ShapeChanging = DeformingStar | RigidShape


def trap_polygon(
    centre: FloatArray | tuple[float, float],
    *,
    outer: float = 1.5,
    inner: float = 1.0,
    mouth: float = 0.15,
    facing: float = 0.0,
    n_arc: int = 48,
) -> FloatArray:
    """The Fig. 4.2(b) shape: a thick "C" (annulus sector) with a deep inner space.

    The inner space is a disc of radius ``inner`` [m] (its depth seen through the mouth is about
    2 ``inner``, far more than the distance a to the lips: a << b in the thesis's words); it opens
    through a straight mouth of width ``mouth`` [m] centred on direction ``facing`` [rad].  Pick
    ``mouth`` below the vehicle's diameter to make the case the chapter calls unavoidable.

    Returns:
        (m, 2) counter-clockwise world vertices [m] of the simple polygon (not star-shaped).
    """
    if not (0 < mouth < 2 * inner < 2 * outer):
        raise ValueError("need 0 < mouth < 2 inner < 2 outer")
    c = np.asarray(centre, dtype=float)
    half_in = float(np.arcsin(mouth / (2.0 * inner)))
    half_out = float(np.arcsin(mouth / (2.0 * outer)))
    # outer arc CCW from facing + half_out to facing + 2 pi - half_out
    a_out = np.linspace(facing + half_out, facing + 2 * np.pi - half_out, n_arc)
    # inner arc back CW from facing + 2 pi - half_in to facing + half_in
    a_in = np.linspace(facing + 2 * np.pi - half_in, facing + half_in, n_arc)
    pts_out = np.stack([outer * np.cos(a_out), outer * np.sin(a_out)], axis=-1)
    pts_in = np.stack([inner * np.cos(a_in), inner * np.sin(a_in)], axis=-1)
    return np.asarray(np.concatenate([pts_out, pts_in]) + c, dtype=float)


def trap_inner_space(
    centre: FloatArray | tuple[float, float], *, inner: float = 1.0, n: int = 64
) -> FloatArray:
    """Polygon (n, 2) [m] of the trap's inner space (the disc the vehicle must never enter)."""
    a = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return np.stack([inner * np.cos(a), inner * np.sin(a)], axis=-1) + np.asarray(centre)


def outlines_at(shapes: list[ShapeChanging], t: float) -> list[FloatArray]:
    """World outlines of every shape at time ``t`` [s]."""
    return [s.outline(t) for s in shapes]
