"""Stage 2 of thesis Ch. 7 (§7.3.2): waypoint order — clusters, TSP (OR-Tools) and spiral orders.

Thesis: Y. Zhang, Ch. 7 (J. Zhang and Y. Zhang, ICCAR 2020).  The chapter clusters the waypoints
("manually or using a cluster analysis algorithm"), visits each cluster in a "clustered
spiral-alternating" order (its ref. [7.13]; the spiral of ref. [7.12], Semsch et al.) and returns
to the first waypoint p1.  Here:

* :func:`kmeans_clusters` — k-means (scikit-learn, fixed ``random_state``) on the waypoints' x, y;
* :func:`tsp_order` — a closed tour by OR-Tools' routing solver (path-cheapest-arc start, then
  local search to a local optimum — reproducible — or guided local search under a time limit);
* :func:`spiral_order` — the spiral: convex layers are peeled from the outside in ("onion
  peeling", scipy's Qhull), each layer is walked counter-clockwise starting next to where the
  previous layer ended, the innermost points are taken nearest-first.  This is the order the
  thesis's spiral idea gives; it is compared with the TSP in the plan's report;
* several UAVs: one cluster each (thesis scenario 1, Fig. 7.4(c));
* :func:`merge_tours` — thesis scenario 2 (Fig. 7.4(d)): one UAV, "we reserve one trajectory and
  regenerate the other".  The chapter gives no rule; we keep the first tour unchanged and splice
  the second one into it where it costs least (two edges removed, two added — the classical
  two-cycle merge), so the first UAV's order survives and the second cycle is regenerated as a
  detour from it.

Distances are 3D Euclidean between waypoints [m].
"""

from __future__ import annotations

import numpy as np
import shapely

FloatArray = np.ndarray
IntArray = np.ndarray


def kmeans_clusters(xy: FloatArray, k: int, *, seed: int = 0) -> IntArray:
    """Cluster labels (N,) in 0..k-1 by k-means on the waypoints' (x, y) [m].

    Labels are renumbered so that cluster 0 holds the waypoint with the smallest (x, y)
    lexicographically (stable across runs and platforms).
    """
    xy = np.asarray(xy, dtype=float)
    if k < 1:
        raise ValueError(f"uavs: need at least 1 UAV/cluster, got {k}")
    if k > len(xy):
        raise ValueError(f"uavs: {k} clusters for only {len(xy)} waypoints")
    if k == 1:
        return np.zeros(len(xy), dtype=np.intp)
    try:
        from sklearn.cluster import KMeans
    except ImportError as exc:  # pragma: no cover - depends on the extra
        raise ImportError(
            "k-means clustering needs scikit-learn: pip install 'uvnav[recon]'"
        ) from exc
    km = KMeans(n_clusters=k, n_init=10, random_state=seed).fit(xy[:, :2])
    labels = np.asarray(km.labels_, dtype=np.intp)
    first = [int(np.lexsort((xy[labels == c, 1], xy[labels == c, 0]))[0]) for c in range(k)]
    keys = [tuple(xy[labels == c][f, :2]) for c, f in enumerate(first)]
    rank = np.argsort(np.array(keys, dtype=[("x", float), ("y", float)]), order=("x", "y"))
    remap = np.empty(k, dtype=np.intp)
    remap[rank] = np.arange(k)
    return remap[labels]


def distance_matrix(pts: FloatArray) -> FloatArray:
    """Euclidean distances (N, N) [m] between points (N, d)."""
    p = np.asarray(pts, dtype=float)
    return np.asarray(np.linalg.norm(p[:, None, :] - p[None, :, :], axis=2), dtype=float)


def tour_length(pts: FloatArray, order: IntArray, *, closed: bool = True) -> float:
    """Length [m] of visiting ``pts[order]`` (and back to the start if ``closed``)."""
    p = np.asarray(pts, dtype=float)[np.asarray(order, dtype=np.intp)]
    if len(p) < 2:
        return 0.0
    seg = np.linalg.norm(np.diff(p, axis=0), axis=1).sum()
    if closed:
        seg += float(np.linalg.norm(p[-1] - p[0]))
    return float(seg)


def rotate_to_start(order: IntArray, start: int) -> IntArray:
    """The same cyclic order beginning at ``start``."""
    order = np.asarray(order, dtype=np.intp)
    k = int(np.flatnonzero(order == start)[0])
    return np.roll(order, -k)


def tsp_order(
    pts: FloatArray,
    *,
    start: int = 0,
    metaheuristic: str = "greedy",
    time_limit_s: float = 30.0,
    scale: float = 1000.0,
) -> IntArray:
    """Closed TSP tour (order of indices, beginning at ``start``) by OR-Tools routing.

    Args:
        pts: Points (N, d) [m].
        start: Index of p1, where the tour begins and ends.
        metaheuristic: ``"greedy"`` — path-cheapest-arc then local search (2-opt, Or-opt,
            relocate, exchange...) to a local optimum: reproducible, the default;
            ``"gls"`` — guided local search until ``time_limit_s`` (better on hard instances, but
            ended by the clock, so not bit-reproducible).
        time_limit_s: Wall-clock cap [s] (for ``"greedy"`` only a safety cap).
        scale: Distances are rounded to integers after multiplying by this [1/m].
    """
    n = len(pts)
    if n <= 3:
        return rotate_to_start(np.arange(n, dtype=np.intp), start) if n else np.zeros(0, np.intp)
    try:
        from ortools.constraint_solver import pywrapcp, routing_enums_pb2
    except ImportError as exc:  # pragma: no cover - depends on the extra
        raise ImportError("the TSP needs OR-Tools: pip install 'uvnav[recon]'") from exc
    metas = {
        "greedy": routing_enums_pb2.LocalSearchMetaheuristic.GREEDY_DESCENT,
        "gls": routing_enums_pb2.LocalSearchMetaheuristic.GUIDED_LOCAL_SEARCH,
    }
    if metaheuristic not in metas:
        raise ValueError(f"metaheuristic: unknown {metaheuristic!r} (use 'greedy' or 'gls')")
    D = np.rint(distance_matrix(pts) * scale).astype(np.int64)
    manager = pywrapcp.RoutingIndexManager(n, 1, int(start))
    routing = pywrapcp.RoutingModel(manager)
    cb = routing.RegisterTransitMatrix(D.tolist())
    routing.SetArcCostEvaluatorOfAllVehicles(cb)
    params = pywrapcp.DefaultRoutingSearchParameters()
    params.first_solution_strategy = routing_enums_pb2.FirstSolutionStrategy.PATH_CHEAPEST_ARC
    params.local_search_metaheuristic = metas[metaheuristic]
    params.time_limit.FromMilliseconds(int(time_limit_s * 1000))
    sol = routing.SolveWithParameters(params)
    if sol is None:  # pragma: no cover - routing always finds a TSP tour
        raise RuntimeError("OR-Tools found no tour")
    order = []
    idx = routing.Start(0)
    while not routing.IsEnd(idx):
        order.append(manager.IndexToNode(idx))
        idx = sol.Value(routing.NextVar(idx))
    return np.asarray(order, dtype=np.intp)


def spiral_order(pts: FloatArray, *, start: int = 0) -> IntArray:
    """Spiral order (outside in, counter-clockwise) by convex-layer peeling; begins at ``start``.

    A layer is every remaining point on the convex hull's boundary (collinear points included),
    ordered along it counter-clockwise from the point nearest to where the previous layer ended.
    """
    from scipy.spatial import ConvexHull, QhullError
    from shapely.geometry import LinearRing

    p = np.asarray(pts, dtype=float)[:, :2]
    remaining = np.arange(len(p))
    order: list[int] = []
    last = p[start]
    scale = float(np.ptp(p, axis=0).max()) if len(p) > 1 else 1.0
    while len(remaining):
        layer = remaining
        if len(remaining) >= 3:
            try:
                hull = ConvexHull(p[remaining])
                ring = LinearRing(p[remaining][hull.vertices])
                q = p[remaining]
                dist = shapely.distance(ring, shapely.points(q))
                on = dist <= 1e-9 * max(scale, 1.0)
                layer = remaining[on]
                pos = shapely.line_locate_point(ring, shapely.points(p[layer]))
                layer = layer[np.argsort(pos, kind="stable")]
            except QhullError:  # collinear rest: walk it nearest-first from `last`
                layer = remaining[np.argsort(np.linalg.norm(p[remaining] - last, axis=1))]
        k = int(np.argmin(np.linalg.norm(p[layer] - last, axis=1)))
        layer = np.roll(layer, -k)
        order.extend(int(i) for i in layer)
        last = p[layer[-1]]
        remaining = np.setdiff1d(remaining, layer, assume_unique=True)
    return rotate_to_start(np.asarray(order, dtype=np.intp), start)


def merge_tours(pts: FloatArray, keep: IntArray, other: IntArray) -> IntArray:
    """One closed tour: ``keep`` unchanged, ``other`` spliced in at the cheapest pair of edges.

    Removes edge (a_i, a_i+1) of ``keep`` and edge (b_j, b_j+1) of ``other`` and joins
    a_i → b_j+1 … b_j → a_i+1 (or the mirrored orientation), minimising the added length.
    The result begins at ``keep[0]`` (p1).
    """
    p = np.asarray(pts, dtype=float)
    A = np.asarray(keep, dtype=np.intp)
    B = np.asarray(other, dtype=np.intp)
    if len(B) == 0:
        return A
    if len(A) == 0:
        return B
    a0, a1 = A, np.roll(A, -1)
    b0, b1 = B, np.roll(B, -1)

    def d(u: IntArray, v: IntArray) -> FloatArray:
        return np.asarray(np.linalg.norm(p[u][:, None, :] - p[v][None, :, :], axis=2))

    base = (
        np.linalg.norm(p[a0] - p[a1], axis=1)[:, None]
        + np.linalg.norm(p[b0] - p[b1], axis=1)[None, :]
    )
    fwd = d(a0, b1) + d(b0, a1).T - base  # a_i -> b_{j+1} ... b_j -> a_{i+1}
    rev = d(a0, b0) + d(b1, a1).T - base  # a_i -> b_j ... (backwards) b_{j+1} -> a_{i+1}
    if fwd.min() <= rev.min():
        i, j = np.unravel_index(int(np.argmin(fwd)), fwd.shape)
        insert = np.roll(B, -(j + 1))  # b_{j+1}, ..., b_j
    else:
        i, j = np.unravel_index(int(np.argmin(rev)), rev.shape)
        insert = np.roll(B, -(j + 1))[::-1]  # b_j, ..., b_{j+1}
    return np.concatenate([A[: i + 1], insert, A[i + 1 :]]).astype(np.intp)


def cluster_tours(
    pts: FloatArray,
    labels: IntArray,
    *,
    method: str = "tsp",
    metaheuristic: str = "greedy",
    time_limit_s: float = 30.0,
) -> list[IntArray]:
    """One closed tour per cluster (global indices), each beginning at the cluster's p1.

    p1 of a cluster is its waypoint with the smallest (x, y) lexicographically.
    ``method``: ``"tsp"`` (OR-Tools) or ``"spiral"``.
    """
    p = np.asarray(pts, dtype=float)
    tours = []
    for c in range(int(labels.max()) + 1 if len(labels) else 0):
        idx = np.flatnonzero(labels == c)
        sub = p[idx]
        s = int(np.lexsort((sub[:, 1], sub[:, 0]))[0])
        if method == "tsp":
            o = tsp_order(sub, start=s, metaheuristic=metaheuristic, time_limit_s=time_limit_s)
        elif method == "spiral":
            o = spiral_order(sub, start=s)
        else:
            raise ValueError(f"tour method: unknown {method!r} (use 'tsp' or 'spiral')")
        tours.append(idx[o])
    return tours
