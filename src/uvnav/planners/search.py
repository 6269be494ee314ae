"""Shortest paths on an 8-connected occupancy grid: Dijkstra and A*.

References: E. W. Dijkstra, "A note on two problems in connexion with graphs", Numerische
Mathematik 1959; P. E. Hart, N. J. Nilsson, B. Raphael, "A formal basis for the heuristic
determination of minimum cost paths", IEEE Trans. SSC 1968 (A*).  Thesis Ch. 1 §1.2 reviews both
as the classical global planners a reactive law is paired with (Ch. 8).

Graph: one vertex per free cell; moves to the 8 neighbours cost ``resolution`` (straight) or
``resolution * sqrt(2)`` (diagonal) [m]; a diagonal move is allowed only when both cells it cuts
the corner of are free (no squeezing between two occupied cells touching at a corner).  The same
graph is used by :mod:`uvnav.planners.dstar_lite`.

Dijkstra is scipy's ``scipy.sparse.csgraph.dijkstra`` on the grid graph built with vectorised
numpy shifts (a well-kept, compiled implementation; it is also the independent oracle of the
property tests).  A* has no scipy counterpart, so it is written here: a binary heap (``heapq``)
with lazy deletion over flat cell indices, with the Euclidean or octile heuristic — both are
consistent on this graph, so the first expansion of the goal is optimal and A*'s cost equals
Dijkstra's (property-tested).
"""

from __future__ import annotations

import functools
import heapq
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from uvnav.planners.grid import MOVES

SQRT2 = math.sqrt(2.0)
Cell = tuple[int, int]
Heuristic = Literal["euclidean", "octile", "zero"]


@dataclass(frozen=True)
class GridPath:
    """A planned path.

    Attributes:
        cells: (n, 2) int array of (row, col) from start to goal; empty (0, 2) when no path.
        cost: path length [m] (``inf`` when no path).
        expanded: number of vertex expansions the search made (its work).
    """

    cells: np.ndarray
    cost: float
    expanded: int

    @property
    def found(self) -> bool:
        return math.isfinite(self.cost)


def _no_path(expanded: int) -> GridPath:
    return GridPath(np.zeros((0, 2), dtype=int), math.inf, expanded)


def heuristic_fn(kind: Heuristic, resolution: float) -> Callable[[int, int, int, int], float]:
    """h((r, c), (gr, gc)) [m] for ``kind``: ``euclidean``, ``octile`` or ``zero`` (Dijkstra)."""
    res = float(resolution)
    if kind == "euclidean":
        return lambda r, c, gr, gc: res * math.hypot(r - gr, c - gc)
    if kind == "octile":

        def octile(r: int, c: int, gr: int, gc: int) -> float:
            dr = abs(r - gr)
            dc = abs(c - gc)
            return res * (max(dr, dc) + (SQRT2 - 1.0) * min(dr, dc))

        return octile
    if kind == "zero":
        return lambda r, c, gr, gc: 0.0
    raise ValueError(f"unknown heuristic {kind!r}; known: euclidean, octile, zero")


def grid_edges(
    occupied: np.ndarray, resolution: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """All directed edges of the grid graph as (source, target, cost [m]) flat-index arrays.

    Vectorised: one boolean shift per move, no Python loop over cells.
    """
    occ = np.asarray(occupied, dtype=bool)
    rows, cols = occ.shape
    free = ~occ
    idx = np.arange(rows * cols).reshape(rows, cols)
    srcs, dsts, ws = [], [], []
    for dr, dc in MOVES:
        r0, r1 = max(0, -dr), rows - max(0, dr)
        c0, c1 = max(0, -dc), cols - max(0, dc)
        if r1 <= r0 or c1 <= c0:
            continue
        ok = free[r0:r1, c0:c1] & free[r0 + dr : r1 + dr, c0 + dc : c1 + dc]
        if dr and dc:  # diagonal: both corner cells free
            ok &= free[r0 + dr : r1 + dr, c0:c1] & free[r0:r1, c0 + dc : c1 + dc]
        s = idx[r0:r1, c0:c1][ok]
        srcs.append(s)
        dsts.append(s + dr * cols + dc)
        ws.append(np.full(s.shape, resolution * (SQRT2 if dr and dc else 1.0)))
    if not srcs:
        empty = np.zeros(0, dtype=int)
        return empty, empty, np.zeros(0)
    return np.concatenate(srcs), np.concatenate(dsts), np.concatenate(ws)


def _check_cells(occupied: np.ndarray, *cells: Cell) -> None:
    rows, cols = occupied.shape
    for r, c in cells:
        if not (0 <= r < rows and 0 <= c < cols):
            raise ValueError(f"cell {(r, c)} is outside the {rows}x{cols} grid")


def dijkstra(occupied: np.ndarray, start: Cell, goal: Cell, *, resolution: float = 1.0) -> GridPath:
    """Shortest 8-connected path from ``start`` to ``goal`` (row, col) by scipy's Dijkstra.

    ``expanded`` is the number of vertices with a finite distance (scipy searches them all when
    given no ``limit``).
    """
    occ = np.asarray(occupied, dtype=bool)
    _check_cells(occ, start, goal)
    if occ[start] or occ[goal]:
        return _no_path(0)
    from scipy.sparse import csr_matrix

    src, dst, w = grid_edges(occ, resolution)
    n = occ.size
    return _csgraph_path(csr_matrix((w, (src, dst)), shape=(n, n)), occ.shape, start, goal)


def costed_dijkstra(
    cell_cost: np.ndarray, start: Cell, goal: Cell, *, weight: float = 1.0,
    resolution: float = 1.0,
) -> GridPath:  # fmt: skip
    """Cheapest 8-connected path from ``start`` to ``goal`` (row, col) over a grid of free cells
    that each cost something (``cell_cost``, >= 0): a move costs its length [m] times ``1 +
    weight * (mean of its two cells' costs)``; scipy's Dijkstra on :func:`grid_edges`' graph.
    ``cost`` is the path's cost in those units.

    >>> cost = np.zeros((3, 3)); cost[1, :2] = 10.0  # a costly wall with a gap at one end
    >>> costed_dijkstra(cost, (0, 0), (2, 0)).cells.tolist()
    [[0, 0], [0, 1], [1, 2], [2, 1], [2, 0]]
    """
    cost = np.asarray(cell_cost, dtype=float)
    _check_cells(cost, start, goal)
    src, dst, length, indptr = _open_grid(cost.shape[0], cost.shape[1], float(resolution))
    flat = cost.ravel()
    w = length * (1.0 + weight * 0.5 * (flat[src] + flat[dst]))
    return _csgraph_path(_csr(w, dst, indptr), cost.shape, start, goal)


@functools.lru_cache(maxsize=8)
def _open_grid(
    rows: int, cols: int, resolution: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`grid_edges` of a grid of free cells, in the order of a CSR matrix (by source,
    then target): sources, targets, lengths [m] and the row pointers; kept per shape, since a
    planner searches the same grid over and over (sorting the edges was half a search)."""
    src, dst, length = grid_edges(np.zeros((rows, cols), dtype=bool), resolution)
    order = np.lexsort((dst, src))
    indptr = np.searchsorted(src[order], np.arange(rows * cols + 1))
    out = (src[order], dst[order], length[order], indptr)
    for a in out:
        a.flags.writeable = False
    return out


def _csr(w: np.ndarray, dst: np.ndarray, indptr: np.ndarray) -> Any:
    """The sparse graph of edge costs ``w`` to ``dst`` in CSR order (``indptr``: row pointers)."""
    from scipy.sparse import csr_matrix

    n = len(indptr) - 1
    return csr_matrix((w, dst, indptr), shape=(n, n))


def _csgraph_path(graph: Any, shape: tuple[int, ...], start: Cell, goal: Cell) -> GridPath:
    """scipy's Dijkstra on the sparse ``graph`` of a grid of ``shape``, from ``start`` to
    ``goal``."""
    from scipy.sparse.csgraph import dijkstra as sp_dijkstra

    cols = shape[1]
    s, g = start[0] * cols + start[1], goal[0] * cols + goal[1]
    dist, pred = sp_dijkstra(graph, directed=True, indices=s, return_predecessors=True)
    expanded = int(np.isfinite(dist).sum())
    if not np.isfinite(dist[g]):
        return _no_path(expanded)
    chain = [g]
    while chain[-1] != s:
        chain.append(int(pred[chain[-1]]))
    flat = np.asarray(chain[::-1])
    return GridPath(np.column_stack((flat // cols, flat % cols)), float(dist[g]), expanded)


def neighbours(
    free: Sequence[bool], rows: int, cols: int, u: int, resolution: float
) -> list[tuple[int, float]]:
    """Graph neighbours of flat cell ``u`` with their move costs [m] (empty for an occupied
    cell); ``free`` is the flattened free mask."""
    if not free[u]:
        return []
    r, c = divmod(u, cols)
    out: list[tuple[int, float]] = []
    diag = resolution * SQRT2
    for dr, dc in MOVES:
        nr, nc = r + dr, c + dc
        if not (0 <= nr < rows and 0 <= nc < cols):
            continue
        v = nr * cols + nc
        if not free[v]:
            continue
        if dr and dc:
            if not (free[r * cols + nc] and free[nr * cols + c]):
                continue
            out.append((v, diag))
        else:
            out.append((v, resolution))
    return out


def astar(
    occupied: np.ndarray,
    start: Cell,
    goal: Cell,
    *,
    resolution: float = 1.0,
    heuristic: Heuristic = "octile",
) -> GridPath:
    """Shortest 8-connected path from ``start`` to ``goal`` (row, col) by A*.

    Args:
        occupied: (rows, cols) bool occupancy.
        start: start cell.
        goal: goal cell.
        resolution: cell side [m] (scales the costs).
        heuristic: ``"octile"`` (the exact free-grid distance, tightest), ``"euclidean"``, or
            ``"zero"`` (plain Dijkstra order).

    Raises:
        ValueError: a cell outside the grid or an unknown heuristic.
    """
    occ = np.asarray(occupied, dtype=bool)
    _check_cells(occ, start, goal)
    h = heuristic_fn(heuristic, resolution)
    rows, cols = occ.shape
    if occ[start] or occ[goal]:
        return _no_path(0)
    free = (~occ).ravel().tolist()
    s = start[0] * cols + start[1]
    g_idx = goal[0] * cols + goal[1]
    gr, gc = goal
    inf = math.inf
    dist: dict[int, float] = {s: 0.0}
    parent: dict[int, int] = {s: s}
    closed: set[int] = set()
    heap: list[tuple[float, float, int]] = [(h(start[0], start[1], gr, gc), 0.0, s)]
    expanded = 0
    while heap:
        _, gu, u = heapq.heappop(heap)
        if u in closed or gu > dist.get(u, inf):
            continue
        closed.add(u)
        expanded += 1
        if u == g_idx:
            break
        for v, w in neighbours(free, rows, cols, u, resolution):
            nd = gu + w
            if nd < dist.get(v, inf):
                dist[v] = nd
                parent[v] = u
                vr, vc = divmod(v, cols)
                heapq.heappush(heap, (nd + h(vr, vc, gr, gc), nd, v))
    if g_idx not in closed:
        return _no_path(expanded)
    chain = [g_idx]
    while chain[-1] != s:
        chain.append(parent[chain[-1]])
    flat = np.asarray(chain[::-1])
    return GridPath(np.column_stack((flat // cols, flat % cols)), dist[g_idx], expanded)


def path_cost(cells: np.ndarray, resolution: float = 1.0) -> float:
    """Length [m] of a cell path (sum of its straight and diagonal moves)."""
    c = np.asarray(cells, dtype=float).reshape(-1, 2)
    if len(c) < 2:
        return 0.0
    return float(np.hypot(*np.diff(c, axis=0).T).sum() * resolution)
