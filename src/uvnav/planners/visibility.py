"""Exact shortest paths among polygons: the visibility graph.

References: T. Lozano-Pérez and M. A. Wesley, "An algorithm for planning collision-free paths
among polyhedral obstacles", CACM 22(10), 1979; M. de Berg et al., *Computational Geometry*,
ch. 15.  Thesis Ch. 1 §1.2 reviews roadmap planners of this kind beside the grid searches.

A shortest path of a point among polygonal obstacles in the plane is a polyline whose interior
vertices are obstacle vertices, and each of its segments meets no obstacle interior; so the
shortest path in the graph whose vertices are start, goal and the obstacle vertices, and whose
edges are the mutually visible pairs, is the exact shortest path.  For a disc robot the obstacles
are first grown by its radius; the growth uses mitred joins (``shapely.buffer(...,
join_style="mitre")``), which contains the exact Minkowski sum (round corners) — the path is
exact for the grown polygons and conservative for the disc (it keeps at least ``inflate`` from
the original obstacles).

Visibility of all candidate pairs is tested in one vectorised shapely call:
``shapely.relate_pattern(segment, obstacles, "T********")`` is true when the segment's interior
meets the obstacles' interior, so segments that run along an edge or touch a vertex are visible.
The graph is searched with ``scipy.sparse.csgraph.dijkstra``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from uvnav.geometry.angles import FloatArray


@dataclass(frozen=True)
class PolylinePath:
    """A path as world points.

    Attributes:
        points: (n, 2) vertices [m] from start to goal; empty (0, 2) when no path.
        cost: length [m] (``inf`` when no path).
    """

    points: FloatArray
    cost: float

    @property
    def found(self) -> bool:
        return bool(np.isfinite(self.cost))


def grown_obstacles(polygons: Sequence[FloatArray], inflate: float = 0.0) -> object:
    """Union of ``polygons`` ((n, 2) vertices [m]) grown by ``inflate`` [m] with mitred joins."""
    import shapely

    geoms = [shapely.Polygon(np.asarray(p, dtype=float)) for p in polygons if len(p) >= 3]
    if not geoms:
        return shapely.Polygon()
    arr = np.asarray(geoms, dtype=object)
    if inflate > 0:
        arr = shapely.buffer(arr, inflate, join_style="mitre", mitre_limit=10.0)
    return shapely.union_all(arr)


def _vertices(geom: object) -> FloatArray:
    import shapely

    rings = shapely.get_rings(shapely.get_parts(geom))
    pts = [np.asarray(shapely.get_coordinates(r))[:-1] for r in rings]
    return np.concatenate(pts) if pts else np.zeros((0, 2))


def visibility_path(
    start: FloatArray | Sequence[float],
    goal: FloatArray | Sequence[float],
    polygons: Sequence[FloatArray],
    *,
    inflate: float = 0.0,
) -> PolylinePath:
    """Exact shortest path from ``start`` to ``goal`` [m] around ``polygons`` grown by
    ``inflate`` [m]; no path (``cost = inf``) when start or goal lies inside a grown obstacle or
    the goal is enclosed."""
    import shapely
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import dijkstra

    s = np.asarray(start, dtype=float)
    g = np.asarray(goal, dtype=float)
    obstacles = grown_obstacles(polygons, inflate)
    no_path = PolylinePath(np.zeros((0, 2)), float("inf"))
    if not shapely.is_empty(obstacles):
        shapely.prepare(obstacles)
        if shapely.contains_xy(obstacles, s[0], s[1]) or shapely.contains_xy(obstacles, g[0], g[1]):
            return no_path
    verts = _vertices(obstacles) if not shapely.is_empty(obstacles) else np.zeros((0, 2))
    nodes = np.vstack((s, g, verts))
    n = len(nodes)
    i, j = np.triu_indices(n, k=1)
    seg = np.stack((nodes[i], nodes[j]), axis=1)
    lengths = np.hypot(*(seg[:, 1] - seg[:, 0]).T)
    if shapely.is_empty(obstacles):
        visible = np.ones(len(i), dtype=bool)
    else:
        lines = shapely.linestrings(seg)
        visible = ~shapely.relate_pattern(lines, obstacles, "T********")
    keep = visible & (lengths > 0)
    graph = csr_matrix((lengths[keep], (i[keep], j[keep])), shape=(n, n))
    dist, pred = dijkstra(graph, directed=False, indices=0, return_predecessors=True)
    if not np.isfinite(dist[1]):
        return no_path
    chain = [1]
    while chain[-1] != 0:
        chain.append(int(pred[chain[-1]]))
    return PolylinePath(nodes[chain[::-1]], float(dist[1]))
