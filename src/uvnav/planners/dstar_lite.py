"""D* Lite: incremental replanning on an 8-connected occupancy grid.

Reference: S. Koenig and M. Likhachev, "D* Lite", AAAI 2002, and "Fast replanning for navigation
in unknown terrain", IEEE Trans. Robotics 21(3), 2005 (Fig. 3, the version with the key modifier
k_m for a moving start).  Thesis Ch. 1 §1.2 reviews Stentz's D* ("Optimal and efficient path
planning for partially-known environments", ICRA 1994); D* Lite is the simpler algorithm with the
same behaviour that replaced it in practice, so it is what "D*" means here.

The search runs backwards from the goal: ``g(u)`` is the cost-to-goal [m], ``rhs(u)`` its
one-step look-ahead ``min_s c(u, s) + g(s)``.  When cells change (a static obstacle is sensed, or
vanishes), only the vertices whose outgoing edges changed get their ``rhs`` recomputed — the
changed cell and its 8 neighbours, since a cell's occupancy enters exactly the edges that touch
it and the diagonal edges that cut its corner, and all their endpoints lie in its 3x3
neighbourhood — and :meth:`DStarLite.compute` repairs only the part of the search tree that the
change makes inconsistent.  The grid graph (costs, corner rule) is that of
:mod:`uvnav.planners.search`, so after any sequence of changes the cost equals A*'s from scratch
(property-tested); ``benchmarks/bench_planners.py`` measures the saving.

Implementation notes: the priority queue is a binary heap with lazy deletion (a dict holds each
open vertex's current key; stale heap entries are skipped), the heuristic is the octile distance
(consistent, as the algorithm requires), and ``rhs`` of a vertex whose ``g`` increased is
recomputed from all its successors rather than by the paper's equality test on floats.
The loop stops only once the start is consistent (``rhs = g``, the basic version's test) and
the smallest key's first component exceeds the start's by more than a rounding tolerance: keys
are float sums along different paths, and a vertex on the start's shortest path whose first key
component ties the start's only up to rounding (its second component is smaller) must still be
expanded for the greedy path extraction to be exact.  Expanding more vertices than the exact
test never breaks the algorithm's invariants, so this costs a few expansions, not correctness.
"""

from __future__ import annotations

import heapq
import math
from collections.abc import Iterable

import numpy as np

from uvnav.planners.search import SQRT2, Cell, GridPath, neighbours

INF = math.inf


class DStarLite:
    """D* Lite planner on a boolean occupancy grid (row, col cells; costs in metres).

    Args:
        occupied: (rows, cols) bool occupancy (copied).
        start: the robot's cell.
        goal: the goal cell.
        resolution: cell side [m].

    Use: :meth:`compute` (the first call plans from scratch), then per robot step
    :meth:`move_start` and, when the map changes, :meth:`set_cells`, then :meth:`compute` again and
    :meth:`path`.  ``expanded`` counts every expansion since construction (the work measure of
    the benchmark).
    """

    def __init__(
        self, occupied: np.ndarray, start: Cell, goal: Cell, *, resolution: float = 1.0
    ) -> None:
        occ = np.asarray(occupied, dtype=bool)
        self.rows, self.cols = (int(n) for n in occ.shape)
        for r, c in (start, goal):
            if not (0 <= r < self.rows and 0 <= c < self.cols):
                raise ValueError(f"cell {(r, c)} is outside the {self.rows}x{self.cols} grid")
        self.resolution = float(resolution)
        self._free: list[bool] = (~occ).ravel().tolist()
        n = self.rows * self.cols
        self._g = [INF] * n
        self._rhs = [INF] * n
        self._start = self._flat(start)
        self._last = self._start
        self._goal = self._flat(goal)
        self._km = 0.0
        self._open: dict[int, tuple[float, float]] = {}
        self._heap: list[tuple[float, float, int]] = []
        self.expanded = 0
        # neighbour lists, cached; a change of cell c invalidates those of its 3x3 neighbourhood
        self._nbr: dict[int, list[tuple[int, float]]] = {}
        self._eps = 1e-9 * self.resolution
        self._rhs[self._goal] = 0.0 if self._free[self._goal] else INF
        if self._free[self._goal]:
            self._push(self._goal)

    # --------------------------------------------------------------------------------- helpers

    def _flat(self, cell: Cell) -> int:
        return int(cell[0]) * self.cols + int(cell[1])

    def _h(self, a: int, b: int) -> float:
        ar, ac = divmod(a, self.cols)
        br, bc = divmod(b, self.cols)
        dr, dc = abs(ar - br), abs(ac - bc)
        return self.resolution * (max(dr, dc) + (SQRT2 - 1.0) * min(dr, dc))

    def _key(self, u: int) -> tuple[float, float]:
        m = min(self._g[u], self._rhs[u])
        return (m + self._h(self._start, u) + self._km, m)

    def _push(self, u: int) -> None:
        k = self._key(u)
        self._open[u] = k
        heapq.heappush(self._heap, (k[0], k[1], u))

    def _top(self) -> tuple[float, float, int]:
        heap = self._heap
        while heap:
            k1, k2, u = heap[0]
            if self._open.get(u) == (k1, k2):
                return k1, k2, u
            heapq.heappop(heap)
        return INF, INF, -1

    def _succ(self, u: int) -> list[tuple[int, float]]:
        nb = self._nbr.get(u)
        if nb is None:
            nb = neighbours(self._free, self.rows, self.cols, u, self.resolution)
            self._nbr[u] = nb
        return nb

    def _update_vertex(self, u: int) -> None:
        if u != self._goal:
            best = INF
            g = self._g
            for v, w in self._succ(u):
                val = w + g[v]
                if val < best:
                    best = val
            self._rhs[u] = best
        if self._g[u] != self._rhs[u]:
            self._push(u)
        else:
            self._open.pop(u, None)

    # ----------------------------------------------------------------------------------- API

    @property
    def start(self) -> Cell:
        r, c = divmod(self._start, self.cols)
        return (r, c)

    @property
    def goal(self) -> Cell:
        r, c = divmod(self._goal, self.cols)
        return (r, c)

    def occupancy(self) -> np.ndarray:
        """The current (rows, cols) bool occupancy."""
        return ~np.asarray(self._free, dtype=bool).reshape(self.rows, self.cols)

    def compute(self) -> float:
        """Repair the search until the start is consistent; returns its cost-to-goal [m]."""
        s = self._start
        g, rhs = self._g, self._rhs
        eps = self._eps
        while True:
            k1, k2, u = self._top()
            ks = self._key(s)
            # k1 ties (within float rounding) are all processed, whatever k2: see module notes
            if not (k1 <= ks[0] + eps or rhs[s] != g[s]):
                break
            if u < 0:
                break
            k_new = self._key(u)
            if (k1, k2) < k_new:
                self._push(u)
                continue
            heapq.heappop(self._heap)
            del self._open[u]
            self.expanded += 1
            if g[u] > rhs[u]:
                g[u] = rhs[u]
                gu = g[u]
                for v, w in self._succ(u):  # the graph is undirected: pred = succ
                    if v != self._goal and w + gu < rhs[v]:
                        rhs[v] = w + gu
                        if g[v] != rhs[v]:
                            self._push(v)
                        else:
                            self._open.pop(v, None)
            else:
                g[u] = INF
                self._update_vertex(u)
                for v, _ in self._succ(u):
                    self._update_vertex(v)
        return g[s] if rhs[s] >= g[s] else rhs[s]

    def move_start(self, cell: Cell) -> None:
        """The robot is now in ``cell`` (updates the key modifier k_m, paper Fig. 3)."""
        new = self._flat(cell)
        if new == self._start:
            return
        self._km += self._h(self._last, new)
        self._last = new
        self._start = new

    def set_cells(self, cells: Iterable[Cell], occupied: bool = True) -> int:
        """Mark ``cells`` occupied (or free); returns how many actually changed.  Call
        :meth:`compute` afterwards."""
        changed: list[int] = []
        for cell in cells:
            r, c = int(cell[0]), int(cell[1])
            if not (0 <= r < self.rows and 0 <= c < self.cols):
                continue
            u = r * self.cols + c
            if self._free[u] == (not occupied):
                continue
            changed.append(u)
        if not changed:
            return 0
        # outgoing edges of an occupied vertex vanish: collect the affected vertices first
        affected: set[int] = set()
        for u in changed:
            self._free[u] = not occupied
            r, c = divmod(u, self.cols)
            for dr in (-1, 0, 1):
                for dc in (-1, 0, 1):
                    nr, nc = r + dr, c + dc
                    if 0 <= nr < self.rows and 0 <= nc < self.cols:
                        affected.add(nr * self.cols + nc)
        for u in affected:
            self._nbr.pop(u, None)
        for u in affected:
            if u == self._goal:
                self._rhs[u] = 0.0 if self._free[u] else INF
                if self._g[u] != self._rhs[u]:
                    self._push(u)
                else:
                    self._open.pop(u, None)
            else:
                self._update_vertex(u)
        return len(changed)

    def cost(self) -> float:
        """Current cost-to-goal of the start [m] (valid after :meth:`compute`)."""
        return min(self._g[self._start], self._rhs[self._start])

    def path(self, max_len: int | None = None) -> GridPath:
        """Greedy descent of ``c + g`` from the start to the goal (the optimal path after
        :meth:`compute`); an empty path when the goal is unreachable."""
        cost = self.cost()
        empty = GridPath(np.zeros((0, 2), dtype=int), INF, self.expanded)
        if not math.isfinite(cost):
            return empty
        u = self._start
        chain = [u]
        limit = max_len if max_len is not None else self.rows * self.cols
        while u != self._goal and len(chain) <= limit:
            best, nxt = INF, -1
            for v, w in self._succ(u):
                val = w + self._g[v]
                if val < best:
                    best, nxt = val, v
            if nxt < 0:
                return empty
            u = nxt
            chain.append(u)
        if u != self._goal:
            return empty
        flat = np.asarray(chain)
        return GridPath(np.column_stack((flat // self.cols, flat % self.cols)), cost, self.expanded)
