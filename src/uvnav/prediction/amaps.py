"""AMAPS — the "As Minimum As Possible Square" occupancy-count grid of thesis Ch. 4 (Fig. 4.4).

Reference: Y. Zhang, *Algorithms of Real-Time Navigation and Control of Autonomous Unmanned
Vehicles*, UNSW — Chapter 4, §4.2 (Fig. 4.4: "cutting the obstacle with AMAPS"; "with times of
attempts, we get the obstacle deformation with probability distribution ... the darker the color,
the more times the AMAPS was covered by the obstacle") and §4.3 ("we approximately hold that the
centre of the square is the point on the surface of obstacle, denoted r_imin(t)").

The thesis gives the idea, not the update rule.  This implementation:

* **Grid.** Axis-aligned squares of side ``cell`` [m] over a fixed rectangle (``origin``,
  ``shape``); ``counts`` (float32) holds, per square, how often it was seen covered, and
  ``labels`` (int16) which obstacle covered it last (sonar returns are per obstacle, §4.2).
  Memory is the two arrays and nothing else: it does not grow with the length of a run.
* **Covered.** A sonar return at range rho marks the squares along the beam from rho to
  rho + ``hit_depth`` (the sonar sees the surface; the body lies behind it) — each square at most
  once per sweep (``+hit_weight``).
* **Forgetting.** Every sweep multiplies all counts by ``decay`` (exponential forgetting, so the
  map follows a shape that changes), and squares the beams saw *free* (strictly before the
  return, up to one square short of it) lose ``free_weight`` (floored at 0).  Both are
  vectorised, with no per-square Python loop: the decay is a scalar gain g = decay^n kept beside
  the stored array (true count = stored * g; an update adds w / g), folded back into the array
  when g falls below 1e-12, so a sweep costs O(beams x range / cell), not O(grid); squares hit
  several times in one sweep are written by one buffered fancy assignment, so each changes once.
* **r_imin.** The centre of the nearest square whose count reaches ``threshold``
  (:meth:`AmapsGrid.nearest`), searched in a window around the vehicle only.

Squares outside the grid are ignored (a scene larger than the grid loses memory there).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from uvnav.geometry.angles import FloatArray
from uvnav.prediction.amaps_kernels import load_kernel

#: the side of a square [m] a grid may have; the most depth [m] behind a return it marks; the
#: most margin [m] around the start-goal box it covers (larger would only make a huge grid)
CELL_RANGE = (1e-3, 10.0)
MAX_HIT_DEPTH = 10.0
MAX_GRID_MARGIN = 1000.0


@dataclass(frozen=True)
class AmapsConfig:
    """AMAPS parameters.

    Attributes:
        cell: side of a square [m].
        decay: multiplicative forgetting per sweep, in (0, 1].
        threshold: count a square needs to be taken as covered.
        hit_weight: count added to a square seen covered in one sweep.
        free_weight: count removed from a square seen free in one sweep.
        hit_depth: depth [m] behind a return that is marked covered.
        free_step: spacing of the free-space samples along a beam, in squares (1: a square may
            be skipped where a beam only clips its corner, which only delays its clearing).
        free_range: free space is carved only this far [m] from the sonar (the law looks no
            farther than its switching and clearance distances; this bounds the work).
    """

    cell: float = 0.05
    decay: float = 0.99
    threshold: float = 0.5
    hit_weight: float = 1.0
    free_weight: float = 0.35
    hit_depth: float = 0.1
    free_step: float = 1.0
    free_range: float = 3.0

    def __post_init__(self) -> None:
        if not (CELL_RANGE[0] <= self.cell <= CELL_RANGE[1]):
            raise ValueError(
                f"cell must be in [{CELL_RANGE[0]:g}, {CELL_RANGE[1]:g}] m (got {self.cell})"
            )
        if not (0 < self.decay <= 1):
            raise ValueError(f"decay must be in (0, 1] (got {self.decay})")
        if not (self.threshold > 0 and self.hit_weight > 0):
            raise ValueError("threshold and hit_weight must be > 0")
        if not (self.free_range > 0):
            raise ValueError(f"free_range must be > 0 m (got {self.free_range})")
        if not (0 < self.free_step <= 2):
            raise ValueError(f"free_step must be in (0, 2] squares (got {self.free_step})")
        if not (self.free_weight >= 0 and 0 <= self.hit_depth <= MAX_HIT_DEPTH):
            raise ValueError(f"free_weight must be >= 0 and hit_depth in [0, {MAX_HIT_DEPTH:g}] m")


def law_grid(params: Any) -> AmapsConfig:
    """The grid of a law's parameters (``cell``, ``decay``, ``threshold``, ``free_weight``,
    ``hit_depth`` as :class:`AmapsConfig`), with its ``grid_margin`` [m] checked: the one place
    the Chapter 4 laws build it from (their ``__post_init__`` checks it at construction).

    Raises:
        ValueError: a setting out of range (one line).
    """
    if not (0 <= params.grid_margin <= MAX_GRID_MARGIN):
        raise ValueError(
            f"grid_margin must be in [0, {MAX_GRID_MARGIN:g}] m (got {params.grid_margin})"
        )
    return AmapsConfig(
        cell=params.cell,
        decay=params.decay,
        threshold=params.threshold,
        free_weight=params.free_weight,
        hit_depth=params.hit_depth,
    )


class AmapsGrid:
    """The AMAPS count grid over the rectangle ``[x0, x0 + nx cell) x [y0, y0 + ny cell)``.

    Attributes:
        counts: (ny, nx) float32 coverage counts.
        labels: (ny, nx) int16 obstacle that last covered each square (-1: never).
        updates: number of sweeps absorbed.
    """

    def __init__(
        self,
        origin: tuple[float, float],
        shape: tuple[int, int],
        config: AmapsConfig,
        *,
        engine: str = "auto",
    ) -> None:
        if engine not in ("auto", "numpy", "numba"):
            raise ValueError(f"engine must be 'auto', 'numpy' or 'numba' (got {engine!r})")
        self.config = config
        self._kernel = None if engine == "numpy" else load_kernel()
        if engine == "numba" and self._kernel is None:
            raise ImportError("AMAPS engine 'numba' needs numba: pip install 'uvnav[fast]'")
        #: the update path in use: ``"numba"`` (compiled, extra ``fast``) or ``"numpy"``
        self.engine = "numpy" if self._kernel is None else "numba"
        self.x0 = float(origin[0])
        self.y0 = float(origin[1])
        self.nx, self.ny = int(shape[0]), int(shape[1])
        self._stored = np.zeros((self.ny, self.nx), dtype=np.float32)
        self._gain = 1.0
        self.labels = np.full((self.ny, self.nx), -1, dtype=np.int16)
        # compiled path only: per row, the lowest and highest column ever marked covered (the
        # only squares that can pass the threshold; read by the near-squares scan)
        self._row_lo = np.full(self.ny, self.nx, dtype=np.intp)
        self._row_hi = np.full(self.ny, -1, dtype=np.intp)
        self.updates = 0
        self._origin = np.array([self.x0, self.y0])
        self._dims = np.array([self.nx, self.ny], dtype=np.uintp)
        self._samples: FloatArray = np.zeros(0)

    @classmethod
    def covering(
        cls,
        low: FloatArray,
        high: FloatArray,
        config: AmapsConfig,
        *,
        margin: float = 0.0,
        engine: str = "auto",
    ) -> AmapsGrid:
        """A grid covering the box ``[low, high]`` [m] grown by ``margin`` [m] on every side."""
        lo = np.asarray(low, dtype=float) - margin
        hi = np.asarray(high, dtype=float) + margin
        n = np.maximum(np.ceil((hi - lo) / config.cell).astype(int), 1)
        return cls((float(lo[0]), float(lo[1])), (int(n[0]), int(n[1])), config, engine=engine)

    @property
    def counts(self) -> FloatArray:
        """(ny, nx) coverage counts (a new array)."""
        return np.asarray(self._stored * np.float32(self._gain), dtype=float)

    @property
    def nbytes(self) -> int:
        """Memory held by the grid arrays [bytes]."""
        return int(self._stored.nbytes + self.labels.nbytes)

    def cell_of(self, points: FloatArray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Column, row and inside-the-grid flag of each point (N, 2)."""
        p = np.asarray(points, dtype=float)
        c = np.floor((p[:, 0] - self.x0) / self.config.cell).astype(np.intp)
        r = np.floor((p[:, 1] - self.y0) / self.config.cell).astype(np.intp)
        ok = (c >= 0) & (c < self.nx) & (r >= 0) & (r < self.ny)
        return c, r, ok

    def centre_of(self, cols: np.ndarray, rows: np.ndarray) -> FloatArray:
        """World centres (N, 2) [m] of squares."""
        h = self.config.cell
        return np.stack([self.x0 + (cols + 0.5) * h, self.y0 + (rows + 0.5) * h], axis=-1)

    # ------------------------------------------------------------------------------- update
    def update(
        self,
        origin: FloatArray,
        angles: FloatArray,
        ranges: FloatArray,
        hit_ids: np.ndarray,
    ) -> None:
        """Absorb one sonar sweep (vectorised; only the squares the beams touch are read or
        written).

        Args:
            origin: sonar position [m].
            angles: (B,) beam angles [rad].
            ranges: (B,) ranges [m]; NaN beams are skipped; beams with ``hit_ids < 0`` carve free
                space only.
            hit_ids: (B,) obstacle per beam (-1: no return).
        """
        cfg = self.config
        h = cfg.cell
        if cfg.decay < 1.0:
            self._gain *= cfg.decay
            if self._gain < 1e-12:
                self._stored *= np.float32(self._gain)
                self._gain = 1.0
        inv = 1.0 / self._gain
        rr = np.asarray(ranges, dtype=float)
        ang = np.asarray(angles, dtype=float)
        ids = np.asarray(hit_ids)
        ok = np.isfinite(rr)
        if not ok.all():
            rr, ang, ids = rr[ok], ang[ok], ids[ok]
        if len(rr) and self._kernel is not None:
            self._kernel[0](
                self._stored, self.labels, float(origin[0]), float(origin[1]), self.x0, self.y0,
                h, np.cos(ang), np.sin(ang), rr, ids.astype(np.intp, copy=False),
                np.float32(cfg.free_weight * inv), np.float32(cfg.hit_weight * inv),
                cfg.free_step * h, cfg.free_range, cfg.free_weight > 0,
                int(np.floor(cfg.hit_depth / (0.5 * h))) + 1, 0.5 * h, self._row_lo,
                self._row_hi,
            )  # fmt: skip
        elif len(rr):
            # (2, B) beam directions, rows x and y; (2,) sonar offset from the grid origin [m]
            dirs = np.stack([np.cos(ang), np.sin(ang)])
            o = np.asarray(origin, dtype=float)
            dims = self._dims
            view = self._stored.reshape(-1)
            hit = ids >= 0
            if cfg.free_weight > 0:
                self._carve_free(o, dirs, rr, hit, dims, view, inv)
            if hit.any():
                self._mark_hits(o, dirs[:, hit], rr[hit], ids[hit], dims, view, inv)
        self.updates += 1

    def _carve_free(
        self,
        o: FloatArray,
        dirs: FloatArray,
        rr: FloatArray,
        hit: np.ndarray,
        dims: np.ndarray,
        view: np.ndarray,
        inv: float,
    ) -> None:
        """Squares seen free: samples every ``free_step`` squares from the sonar to one square
        short of the return (or to the range without one), at most ``free_range`` away; each
        square loses ``free_weight`` at most once per sweep."""
        cfg = self.config
        h = cfg.cell
        fs = cfg.free_step * h
        n_s = int(np.ceil(min(float(rr.max()), cfg.free_range) / fs)) + 1
        s = self._free_samples(n_s)  # (S,)
        limit = np.minimum(np.where(hit, rr - h, rr), cfg.free_range)  # (B,)
        # (2, B, S) sample positions relative to the grid origin, then square indices
        pos = (o - self._origin)[:, None, None] + s * dirs[:, :, None]
        cell = np.floor(pos / h).astype(np.intp)
        take = s < limit[:, None]
        if not self._holds(o, cfg.free_range):
            # inside the grid: one unsigned compare per axis catches negative indices too
            take &= (cell.view(np.uintp) < dims[:, None, None]).all(axis=0)
        flat = (cell[1] * self.nx + cell[0])[take]
        if len(flat):
            # duplicates read the same old value and write the same new one: once each
            view[flat] = np.maximum(view[flat] - np.float32(cfg.free_weight * inv), 0.0)

    def _mark_hits(
        self,
        o: FloatArray,
        dirs: FloatArray,
        rr: FloatArray,
        ids: np.ndarray,
        dims: np.ndarray,
        view: np.ndarray,
        inv: float,
    ) -> None:
        """Squares seen covered: from each return to ``hit_depth`` behind it, +``hit_weight``
        once per square and sweep; the label of the obstacle written last wins."""
        cfg = self.config
        h = cfg.cell
        n_d = int(np.floor(cfg.hit_depth / (0.5 * h))) + 1
        s = np.arange(n_d) * (0.5 * h)
        # (2, B, D) world points o + (rho + s) d, then their squares
        pts = o[:, None, None] + (rr[:, None] + s)[None] * dirs[:, :, None]
        cell = np.floor((pts - self._origin[:, None, None]) / h).astype(np.intp)
        inside = (cell.view(np.uintp) < dims[:, None, None]).all(axis=0).reshape(-1)
        flat = (cell[1] * self.nx + cell[0]).reshape(-1)[inside]
        view[flat] += np.float32(cfg.hit_weight * inv)  # buffered: +w once per square
        lab = np.repeat(ids, n_d)[inside]
        self.labels.reshape(-1)[flat] = lab.astype(np.int16)

    def _holds(self, point: FloatArray, reach: float) -> bool:
        """True when every square within ``reach`` [m] of ``point`` (plus one square) lies in
        the grid, so that samples up to that distance need no bounds test."""
        h = self.config.cell
        lo = (point - self._origin - reach) / h
        hi = (point - self._origin + reach) / h
        return bool(lo[0] >= 1 and lo[1] >= 1 and hi[0] <= self.nx - 1 and hi[1] <= self.ny - 1)

    def _free_samples(self, n: int) -> FloatArray:
        """The first ``n`` free-space sample distances ``k * free_step * cell`` [m] (cached)."""
        if len(self._samples) < n:
            fs = self.config.free_step * self.config.cell
            self._samples = np.asarray(np.arange(n) * fs, dtype=float)
        return self._samples[:n]

    # -------------------------------------------------------------------------------- queries
    def _window(self, point: FloatArray, radius: float) -> tuple[slice, slice]:
        h = self.config.cell
        px, py, x0, y0 = float(point[0]), float(point[1]), float(self.x0), float(self.y0)
        c0 = max(math.floor((px - radius - x0) / h), 0)
        c1 = min(math.floor((px + radius - x0) / h) + 1, self.nx)
        r0 = max(math.floor((py - radius - y0) / h), 0)
        r1 = min(math.floor((py + radius - y0) / h) + 1, self.ny)
        return slice(r0, max(r1, r0)), slice(c0, max(c1, c0))

    def covered(
        self, point: FloatArray, radius: float
    ) -> tuple[FloatArray, np.ndarray, FloatArray]:
        """Covered squares (count >= threshold) whose centres lie within ``radius`` [m] of
        ``point``, in row-major order: ``(centres (N, 2) [m], labels (N,), distances (N,) [m])``.

        Queries with a smaller radius about the same point are the leading-order subsets of this
        one (``distances <= r``), which is how the law answers all its questions of one decision
        from a single window scan.
        """
        p = np.asarray(point, dtype=float)
        rs, cs = self._window(p, radius)
        level = np.float32(self.config.threshold / self._gain)
        if self._kernel is not None:  # one compiled pass, the same values as below
            return self._kernel[1](
                self._stored, self.labels, self._row_lo, self._row_hi, rs.start, rs.stop,
                cs.start, cs.stop, level, self.x0, self.y0, self.config.cell, float(p[0]),
                float(p[1]), float(radius),
            )  # fmt: skip
        else:
            rows, cols = np.nonzero(self._stored[rs, cs] >= level)
            rows = rows + rs.start
            cols = cols + cs.start
        centres = self.centre_of(cols, rows)
        d = np.hypot(centres[:, 0] - p[0], centres[:, 1] - p[1])
        keep = d <= radius
        return centres[keep], self.labels[rows[keep], cols[keep]].astype(np.intp), d[keep]

    def occupied(self, point: FloatArray, radius: float) -> tuple[FloatArray, np.ndarray]:
        """Centres (N, 2) [m] and labels (N,) of covered squares within ``radius`` [m] of
        ``point`` (count >= threshold)."""
        centres, labels, _ = self.covered(point, radius)
        return centres, labels

    def nearest(self, point: FloatArray, radius: float) -> tuple[float, FloatArray | None, int]:
        """r_imin: ``(distance [m], centre of the nearest covered square, its label)`` within
        ``radius`` [m]; ``(inf, None, -1)`` when none passes the threshold."""
        return nearest_of(*self.covered(point, radius))


def nearest_of(
    centres: FloatArray, labels: np.ndarray, distances: FloatArray
) -> tuple[float, FloatArray | None, int]:
    """The first nearest of covered squares given as :meth:`AmapsGrid.covered` returns them:
    ``(distance [m], centre, label)``, ``(inf, None, -1)`` for none."""
    if len(centres) == 0:
        return np.inf, None, -1
    j = int(np.argmin(distances))
    return float(distances[j]), centres[j], int(labels[j])
