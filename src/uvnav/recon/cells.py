"""Clipped lattice cells and their sample points (thesis Ch. 7 §7.3.1, Fig. 7.2(b)).

Thesis: Y. Zhang, Ch. 7 (J. Zhang and Y. Zhang, ICCAR 2020).  Stage 1 assigns each waypoint the
part of D nearest to it: its Voronoi cell among the waypoints, clipped to D.  On the lattice of
:mod:`.lattice` that is the hexagon of circumradius R around the vertex, clipped to D (a point of
D lies in a hexagon whose vertex is a waypoint, because that hexagon meets D); the cells
partition D.  Shapely computes them (GEOS Voronoi diagram, ``ordered=True`` keeps the waypoints'
order) and samples them for the altitude rule and the coverage checks.

Units: lengths [m].
"""

from __future__ import annotations

import math

import numpy as np
import shapely
from shapely.geometry import MultiPoint, Polygon

FloatArray = np.ndarray


def clipped_cells(xy: FloatArray, area: Polygon) -> list[Polygon]:
    """Each waypoint's Voronoi cell among the waypoints ``xy`` (N, 2) [m], clipped to D.

    One waypoint gets all of D.  Empty cells (a waypoint whose cell misses D) are empty polygons.
    """
    xy = np.asarray(xy, dtype=float)
    if len(xy) == 1:
        return [area]
    xmin, ymin, xmax, ymax = area.bounds
    pad = 10.0 * max(xmax - xmin, ymax - ymin, 1.0)
    frame = shapely.box(xmin - pad, ymin - pad, xmax + pad, ymax + pad)
    vor = shapely.voronoi_polygons(MultiPoint(xy), extend_to=frame, ordered=True)
    parts = list(shapely.get_parts(vor))
    if len(parts) != len(xy):  # duplicate waypoints: GEOS merges their cells
        raise ValueError("waypoints: two waypoints share a position")
    cells = shapely.intersection(np.asarray(parts, dtype=object), area)
    return [Polygon() if c.is_empty else c for c in cells]


def sample_polygon(
    poly: Polygon, step: float, *, anchor: tuple[float, float] = (0.0, 0.0)
) -> FloatArray:
    """Points (m, 2) [m] of a polygon: its vertices, its boundary every ``step`` and the nodes of
    the grid ``anchor + step·(i, j)`` inside it (closed: boundary points count)."""
    if poly.is_empty:
        return np.zeros((0, 2))
    ring = shapely.segmentize(poly.boundary, step)
    edge = shapely.get_coordinates(ring)
    return np.vstack([edge, grid_points(poly, step, anchor=anchor)])


def grid_points(poly: Polygon, step: float, *, anchor: tuple[float, float]) -> FloatArray:
    """Nodes (m, 2) [m] of the grid ``anchor + step·(i, j)`` inside the closed polygon."""
    if not step > 0:
        raise ValueError(f"step: must be > 0, got {step}")
    xmin, ymin, xmax, ymax = poly.bounds
    i0, i1 = math.ceil((xmin - anchor[0]) / step), math.floor((xmax - anchor[0]) / step)
    j0, j1 = math.ceil((ymin - anchor[1]) / step), math.floor((ymax - anchor[1]) / step)
    X, Y = np.meshgrid(
        anchor[0] + step * np.arange(i0, i1 + 1), anchor[1] + step * np.arange(j0, j1 + 1)
    )
    keep = shapely.contains_xy(poly, X, Y) | shapely.intersects_xy(poly.boundary, X, Y)
    return np.column_stack([X[keep], Y[keep]])


def random_points(area: Polygon, n: int, rng: np.random.Generator) -> FloatArray:
    """``n`` points (n, 2) [m] uniform in D (rejection from its bounding box)."""
    xmin, ymin, xmax, ymax = area.bounds
    out: list[FloatArray] = []
    got = 0
    while got < n:
        p = rng.uniform((xmin, ymin), (xmax, ymax), size=(2 * (n - got) + 16, 2))
        p = p[shapely.contains_xy(area, p[:, 0], p[:, 1])]
        out.append(p)
        got += len(p)
    return np.vstack(out)[:n]
