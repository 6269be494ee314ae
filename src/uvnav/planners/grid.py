"""Occupancy grids built from static obstacles, inflated by the robot radius.

Reference: the configuration-space idea of Lozano-Pérez, "Spatial planning: a configuration space
approach", IEEE Trans. Computers 1983 — a disc robot of radius r moves freely where its centre
stays farther than r from every obstacle, so the obstacles are grown by r (Minkowski sum with the
disc) and the robot becomes a point.  Thesis Ch. 1 (§1.2) reviews grid planners (Dijkstra, A*,
D*) on exactly such maps; Ch. 8 names global planning on a map plus local reactive avoidance as
the way the reactive laws are used in practice.

The grid is rasterised with shapely 2's vectorised predicates: the obstacles are buffered by the
inflation radius (round joins: the exact Minkowski sum up to shapely's arc approximation) and a
cell is occupied when its *centre* lies in the grown set (``shapely.contains_xy`` over all cell
centres in one call).  A robot whose centre is at a free cell centre therefore does not touch an
obstacle; between cell centres the search's 8-connected moves add at most half a diagonal
(``resolution / sqrt(2)``) of unseen corner cutting, so callers who need a hard guarantee inflate
by ``radius + resolution / sqrt(2)`` (:func:`safe_inflation`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from uvnav.geometry.angles import FloatArray

#: 8-connected moves (row step, column step)
MOVES: tuple[tuple[int, int], ...] = (
    (-1, 0),
    (1, 0),
    (0, -1),
    (0, 1),
    (-1, -1),
    (-1, 1),
    (1, -1),
    (1, 1),
)


def safe_inflation(radius: float, resolution: float) -> float:
    """Inflation [m] under which straight moves between free cell centres keep the disc of
    ``radius`` [m] off the obstacles: ``radius + resolution / sqrt(2)``."""
    return float(radius) + float(resolution) / math.sqrt(2.0)


@dataclass
class OccupancyGrid:
    """A boolean occupancy grid.

    Attributes:
        occupied: (rows, cols) bool array; ``occupied[r, c]`` is the cell whose centre is
            ``origin + ((c + 0.5) * resolution, (r + 0.5) * resolution)`` (row = y, column = x).
        origin: world coordinates [m] of the grid's lower-left corner, shape (2,).
        resolution: cell side [m].
    """

    occupied: np.ndarray
    origin: FloatArray
    resolution: float

    @property
    def shape(self) -> tuple[int, int]:
        return (int(self.occupied.shape[0]), int(self.occupied.shape[1]))

    def to_cell(self, point: FloatArray | Sequence[float]) -> tuple[int, int]:
        """The (row, col) of the cell containing ``point`` [m], clipped to the grid."""
        p = np.asarray(point, dtype=float)
        c = math.floor((p[0] - self.origin[0]) / self.resolution)
        r = math.floor((p[1] - self.origin[1]) / self.resolution)
        rows, cols = self.shape
        return (min(max(r, 0), rows - 1), min(max(c, 0), cols - 1))

    def to_world(self, cells: np.ndarray | Sequence[tuple[int, int]]) -> FloatArray:
        """Centres [m] of (row, col) ``cells``, shape (n, 2) as (x, y)."""
        rc = np.asarray(cells, dtype=float).reshape(-1, 2)
        return np.column_stack(
            (
                self.origin[0] + (rc[:, 1] + 0.5) * self.resolution,
                self.origin[1] + (rc[:, 0] + 0.5) * self.resolution,
            )
        )

    def inside(self, point: FloatArray | Sequence[float]) -> bool:
        """True when ``point`` [m] lies within the grid's extent."""
        p = np.asarray(point, dtype=float)
        rows, cols = self.shape
        x = (p[0] - self.origin[0]) / self.resolution
        y = (p[1] - self.origin[1]) / self.resolution
        return bool(0 <= x < cols and 0 <= y < rows)

    def cell_centres(self) -> tuple[FloatArray, FloatArray]:
        """x and y [m] of every cell centre, each (rows, cols)."""
        rows, cols = self.shape
        xs = self.origin[0] + (np.arange(cols) + 0.5) * self.resolution
        ys = self.origin[1] + (np.arange(rows) + 0.5) * self.resolution
        gx, gy = np.meshgrid(xs, ys)
        return gx, gy


def empty_grid(
    bounds: tuple[float, float, float, float] | Sequence[float], resolution: float
) -> OccupancyGrid:
    """A free grid covering ``bounds = (xmin, ymin, xmax, ymax)`` [m] with cells of ``resolution``
    [m] (the extent is rounded up to whole cells).

    Raises:
        ValueError: empty bounds or a non-positive resolution.
    """
    xmin, ymin, xmax, ymax = (float(b) for b in bounds)
    if not (resolution > 0 and math.isfinite(resolution)):
        raise ValueError(f"resolution must be a positive number of metres (got {resolution!r})")
    if not (xmax > xmin and ymax > ymin):
        raise ValueError(f"bounds need xmin < xmax and ymin < ymax (got {list(bounds)})")
    cols = max(1, math.ceil((xmax - xmin) / resolution - 1e-9))
    rows = max(1, math.ceil((ymax - ymin) / resolution - 1e-9))
    return OccupancyGrid(
        np.zeros((rows, cols), dtype=bool), np.array([xmin, ymin]), float(resolution)
    )


def inflated_geometry(
    polygons: Sequence[FloatArray] = (),
    discs: Sequence[tuple[float, float, float]] = (),
    *,
    inflate: float = 0.0,
) -> object:
    """The union of ``polygons`` ((n, 2) vertices [m]) and ``discs`` ((x, y, radius) [m]) grown by
    ``inflate`` [m], as one shapely geometry (empty when there is nothing)."""
    import shapely

    geoms = [shapely.Polygon(np.asarray(p, dtype=float)) for p in polygons if len(p) >= 3]
    geoms += [shapely.Point(x, y).buffer(r, quad_segs=16) for x, y, r in discs]
    if not geoms:
        return shapely.Polygon()
    grown = shapely.buffer(np.asarray(geoms, dtype=object), inflate, quad_segs=16)
    return shapely.union_all(grown)


def rasterize(
    grid: OccupancyGrid,
    polygons: Sequence[FloatArray] = (),
    discs: Sequence[tuple[float, float, float]] = (),
    *,
    inflate: float = 0.0,
) -> np.ndarray:
    """Boolean (rows, cols) mask of the cells whose centre lies in the obstacles grown by
    ``inflate`` [m] (see :func:`inflated_geometry`).  Only the cells inside the grown set's
    bounding box are tested (one vectorised ``shapely.contains_xy`` call)."""
    import shapely

    mask = np.zeros(grid.shape, dtype=bool)
    geom = inflated_geometry(polygons, discs, inflate=inflate)
    if shapely.is_empty(geom):
        return mask
    xmin, ymin, xmax, ymax = shapely.bounds(geom)
    res = grid.resolution
    rows, cols = grid.shape
    c0 = max(0, math.floor((xmin - grid.origin[0]) / res - 0.5))
    c1 = min(cols, math.ceil((xmax - grid.origin[0]) / res + 0.5))
    r0 = max(0, math.floor((ymin - grid.origin[1]) / res - 0.5))
    r1 = min(rows, math.ceil((ymax - grid.origin[1]) / res + 0.5))
    if c1 <= c0 or r1 <= r0:
        return mask
    xs = grid.origin[0] + (np.arange(c0, c1) + 0.5) * res
    ys = grid.origin[1] + (np.arange(r0, r1) + 0.5) * res
    gx, gy = np.meshgrid(xs, ys)
    shapely.prepare(geom)
    mask[r0:r1, c0:c1] = shapely.contains_xy(geom, gx, gy)
    return mask


def occupancy_grid(
    bounds: tuple[float, float, float, float] | Sequence[float],
    resolution: float,
    polygons: Sequence[FloatArray] = (),
    discs: Sequence[tuple[float, float, float]] = (),
    *,
    inflate: float = 0.0,
) -> OccupancyGrid:
    """Grid over ``bounds`` [m] with the static obstacles grown by ``inflate`` [m] marked."""
    grid = empty_grid(bounds, resolution)
    grid.occupied |= rasterize(grid, polygons, discs, inflate=inflate)
    return grid
