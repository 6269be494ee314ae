"""Samples for the Chapter 5 network: sonar readings R(t) with *true-geometry* targets.

Thesis Chapter 5 §5.3-5.4 (Y. Zhang and J. Zhang, ICCAE 2022): the BPNN's nine inputs are the
sonar readings after the adaptive coefficient, its two outputs "the minimum distance between the
robot and the obstacle, and the marked number of sensor which achieved the minimum distance"
(Fig. 5.4); the thesis trains on 50 and on 150 "groups of data" obtained "in advance".

The thesis does not say how its data were made.  Here (docs/thesis-notes.md) the targets are the
*true* geometry, so that the network must learn more than min/argmin of its inputs:

* distance: ``d* = ||c_r - q*|| - rho``, the gap between the vehicle's spherical hull (radius rho)
  and the obstacle, with ``q*`` the obstacle's nearest surface point (exact on the tessellation);
* sensor: the 1-based index of the sensor whose beam axis points closest (in angle) to ``q*``
  (:func:`~uvnav.sensors.sonar_array.nearest_beam`).

The baseline the network must beat is kept beside them: ``min_i R_i`` and ``argmin_i R_i + 1``.
Every reading is ``>= d*`` (a sensor sits on the hull), with equality only when ``q*`` lies in a
beam, so the baseline is biased high by the array's angular gaps.

The thesis's own targets are kept too (``targets("readings")``, :func:`reading_targets`): the
minimum of the network's nine inputs and the 1-based number of the input that holds it — a label
computed from the inputs themselves, as §5.4 describes ("the outputs are minimum distance among the
nine sensors and the sensor ... which achieved the minimum distance").  The inputs are the adapted
readings ``k_i R_i``, so these differ from the raw min/argmin baseline where the coefficient
reorders the readings.

Sampling (pure numpy, one seeded Generator): an obstacle from
:func:`~uvnav.obstacles.deforming3d.random_star` (base radius, reference shape and a deformation of
at most 10 %, a random time), a vehicle at a random direction and hull gap from it, its heading
toward the obstacle's centre turned away by up to ``max_off_angle``; a sample is kept only when at
least one sensor has an echo (the obstacle is in the array's view, as in the thesis's scenes).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.obstacles.deforming3d import random_star
from uvnav.sensors.sonar_array import (
    N_SONARS,
    SonarArray,
    adapted_ranges,
    nearest_beam,
    sonar_scan,
)
from uvnav.validation import MAX_COORDINATE, coordinate_problem


@dataclass(frozen=True)
class SonarSampling:
    """How samples are drawn.

    Attributes:
        radius_range: obstacle base radius R0 range [m].
        shape_scale: largest reference-shape size sum |b_k| (< 1).
        delta_max: deformation bound (thesis: 0.1).
        gap_range: hull-to-obstacle-centre-sphere gap range [m] (the vehicle is placed at
            ``R0 + rho + gap`` from the centre; the true gap then follows the shape).
        max_off_angle: largest angle between the heading and the direction to the obstacle
            centre [rad].
        time_range: obstacle time range [s] (phase of the deformation).
    """

    radius_range: tuple[float, float] = (0.8, 2.0)
    shape_scale: float = 0.35
    delta_max: float = 0.1
    gap_range: tuple[float, float] = (0.5, 5.0)
    max_off_angle: float = math.radians(50.0)
    time_range: tuple[float, float] = (0.0, 60.0)


#: what the network is trained to output: ``"geometry"`` (the true nearest distance and the beam
#: nearest to it, ours) or ``"readings"`` (min/argmin of the network's own inputs, the thesis's)
TARGET_KINDS: tuple[str, ...] = ("geometry", "readings")


def reading_targets(inputs: FloatArray) -> FloatArray:
    """The thesis's targets (§5.4, Fig. 5.4) of inputs ``(n, 9)``: ``(n, 2)`` — the least input
    [m] and the 1-based number of the input that holds it (the first one on a tie)."""
    x = np.atleast_2d(np.asarray(inputs, dtype=float))
    return np.stack([x.min(axis=1), np.argmin(x, axis=1) + 1.0], axis=1)


@dataclass(frozen=True)
class SonarDataset:
    """Samples as arrays (n rows).

    Attributes:
        ranges: raw readings R(t) [m], (n, 9).
        inputs: adapted readings k_i R_i [m], (n, 9) — the network's inputs.
        target_distance: true hull-to-obstacle distance [m], (n,).
        target_index: true 1-based sensor index, (n,).
        baseline_distance: min_i R_i [m], (n,).
        baseline_index: argmin_i R_i + 1, (n,).
    """

    ranges: FloatArray
    inputs: FloatArray
    target_distance: FloatArray
    target_index: np.ndarray
    baseline_distance: FloatArray
    baseline_index: np.ndarray

    def __len__(self) -> int:
        return int(self.ranges.shape[0])

    def targets(self, kind: str = "geometry") -> FloatArray:
        """(n, 2): distance [m] and sensor index, the network's outputs (Fig. 5.4).

        Args:
            kind: ``"geometry"`` (the true nearest distance and sensor) or ``"readings"``
                (min/argmin of :attr:`inputs`, the thesis's set-up; :data:`TARGET_KINDS`).

        Raises:
            ValueError: another ``kind``.
        """
        if kind == "readings":
            return reading_targets(self.inputs)
        if kind != "geometry":
            raise ValueError(f"targets: {kind!r} (must be one of {', '.join(TARGET_KINDS)})")
        return np.stack([self.target_distance, self.target_index.astype(float)], axis=1)

    def baseline(self) -> FloatArray:
        """(n, 2): the min/argmin baseline in the same layout as :meth:`targets`."""
        return np.stack([self.baseline_distance, self.baseline_index.astype(float)], axis=1)

    def arrays(self) -> dict[str, np.ndarray]:
        """Named arrays (for saving)."""
        return {
            "ranges": self.ranges,
            "inputs": self.inputs,
            "target_distance": self.target_distance,
            "target_index": self.target_index,
            "baseline_distance": self.baseline_distance,
            "baseline_index": self.baseline_index,
        }

    @staticmethod
    def from_arrays(arrays: dict[str, np.ndarray]) -> SonarDataset:
        """Inverse of :meth:`arrays`.

        Raises:
            ValueError: a missing array, inconsistent shapes, a value that is not a finite
                number (NaN, ±inf), or a sensor index outside 1..9 (one line naming the array
                and the row).
        """
        need = (
            "ranges",
            "inputs",
            "target_distance",
            "target_index",
            "baseline_distance",
            "baseline_index",
        )
        for name in need:
            if name not in arrays:
                raise ValueError(f"dataset misses the array {name!r}")
        n = np.asarray(arrays["ranges"]).shape[0] if np.ndim(arrays["ranges"]) else 0
        if n == 0:
            raise ValueError("dataset array 'ranges' has no samples (0 rows)")
        for name in need:
            a = np.asarray(arrays[name])
            want = (n, N_SONARS) if name in ("ranges", "inputs") else (n,)
            if a.shape != want:
                raise ValueError(f"dataset array {name!r} has shape {a.shape}, expected {want}")
            _check_finite(name, a)
        for name in ("target_index", "baseline_index"):
            a = np.asarray(arrays[name], dtype=float)
            bad = np.flatnonzero((a != np.round(a)) | (a < 1) | (a > N_SONARS))
            if len(bad):
                value = float(a[bad[0]])
                raise ValueError(
                    f"dataset array {name!r}, row {int(bad[0])}: {value:g} is not a sensor "
                    f"number 1..{N_SONARS}"
                )
        return SonarDataset(
            ranges=np.asarray(arrays["ranges"], dtype=float),
            inputs=np.asarray(arrays["inputs"], dtype=float),
            target_distance=np.asarray(arrays["target_distance"], dtype=float),
            target_index=np.asarray(arrays["target_index"]).astype(np.int64),
            baseline_distance=np.asarray(arrays["baseline_distance"], dtype=float),
            baseline_index=np.asarray(arrays["baseline_index"]).astype(np.int64),
        )


def _check_finite(name: str, a: np.ndarray) -> None:
    """Raise a one-line :class:`ValueError` at the first entry of ``a`` that is not a finite
    number within :data:`uvnav.validation.MAX_COORDINATE` (distances [m]; the indices 1..9 are
    checked by the caller).

    Raises:
        ValueError: a non-numeric array, or a NaN/±inf or out-of-range entry (naming the array,
            row and column).
    """
    if not (np.issubdtype(a.dtype, np.number) or a.dtype == np.bool_):
        raise ValueError(f"dataset array {name!r} has dtype {a.dtype}, expected numbers")
    if np.issubdtype(a.dtype, np.integer) or a.dtype == np.bool_:
        return
    bad = np.argwhere(~(np.abs(a) <= MAX_COORDINATE))
    if len(bad):
        where = bad[0]
        cell = f"row {int(where[0])}" + (f", column {int(where[1])}" if len(where) > 1 else "")
        problem = coordinate_problem(float(a[tuple(where)]))
        raise ValueError(f"dataset array {name!r}, {cell}: {problem}")


def _random_unit(rng: np.random.Generator) -> FloatArray:
    v = rng.normal(size=3)
    return np.asarray(v / np.linalg.norm(v))


def _tilt(rng: np.random.Generator, axis: FloatArray, max_angle: float) -> FloatArray:
    """``axis`` turned by an angle uniform on the spherical cap of half-angle ``max_angle``."""
    cos_t = rng.uniform(math.cos(max_angle), 1.0)
    sin_t = math.sqrt(max(0.0, 1.0 - cos_t * cos_t))
    perp = _random_unit(rng)
    perp = perp - float(perp @ axis) * axis
    perp /= np.linalg.norm(perp)
    return np.asarray(cos_t * axis + sin_t * perp)


def sample_sonar_dataset(
    n: int,
    rng: np.random.Generator,
    *,
    array: SonarArray | None = None,
    sampling: SonarSampling | None = None,
    subdivisions: int = 3,
    max_tries: int = 20,
    on_sample: Callable[[int], None] | None = None,
) -> SonarDataset:
    """``n`` samples (module docstring) drawn with ``rng``; noise/dropout come from ``array``.

    ``on_sample(k)`` is called after the k-th sample is kept (progress bars).

    Raises:
        ValueError: ``n < 1``, or no echo in ``max_tries * n`` draws (a sampling that never puts
            the obstacle in view).
    """
    if n < 1:
        raise ValueError(f"number of samples must be >= 1 (got {n})")
    arr = array or SonarArray()
    smp = sampling or SonarSampling()
    rows: list[tuple[FloatArray, float, int]] = []
    tries = 0
    while len(rows) < n:
        tries += 1
        if tries > max_tries * n:
            raise ValueError("sampling found no obstacle in the sonar array's view")
        r0 = float(rng.uniform(*smp.radius_range))
        body = random_star(
            rng,
            np.zeros(3),
            r0,
            shape_scale=smp.shape_scale,
            delta_max=smp.delta_max,
            subdivisions=subdivisions,
        )
        t = float(rng.uniform(*smp.time_range))
        u = _random_unit(rng)
        gap = float(rng.uniform(*smp.gap_range))
        position = u * (r0 + arr.hull_radius + gap)
        heading = _tilt(rng, -u, smp.max_off_angle)
        tri = body.triangles(t)
        scan = sonar_scan(arr, position, heading, tri, rng)
        if not scan.echo.any():
            continue
        q, d = body.nearest(position, t)
        rows.append((scan.ranges, d - arr.hull_radius, nearest_beam(arr, position, heading, q)))
        if on_sample is not None:
            on_sample(len(rows))
    ranges = np.stack([r[0] for r in rows])
    return SonarDataset(
        ranges=ranges,
        inputs=adapted_ranges(arr, ranges),
        target_distance=np.array([r[1] for r in rows]),
        target_index=np.array([r[2] for r in rows], dtype=np.int64),
        baseline_distance=ranges.min(axis=1),
        baseline_index=np.argmin(ranges, axis=1).astype(np.int64) + 1,
    )
