"""Dijkstra / A* on the grid: agreement, optimality, heuristics."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.planners import astar, dijkstra, grid_edges, path_cost
from uvnav.planners.search import MOVES, costed_dijkstra


@st.composite
def grids(draw: st.DrawFn) -> tuple[np.ndarray, tuple[int, int], tuple[int, int]]:
    rows = draw(st.integers(2, 14))
    cols = draw(st.integers(2, 14))
    density = draw(st.floats(0.0, 0.45))
    seed = draw(st.integers(0, 2**31 - 1))
    rng = np.random.default_rng(seed)
    occ = rng.random((rows, cols)) < density
    start = (draw(st.integers(0, rows - 1)), draw(st.integers(0, cols - 1)))
    goal = (draw(st.integers(0, rows - 1)), draw(st.integers(0, cols - 1)))
    occ[start] = False
    occ[goal] = False
    return occ, start, goal


def _valid_moves(occ: np.ndarray, cells: np.ndarray) -> bool:
    for (r0, c0), (r1, c1) in itertools.pairwise(cells):
        dr, dc = int(r1 - r0), int(c1 - c0)
        if (dr, dc) not in MOVES or occ[r1, c1]:
            return False
        if dr and dc and (occ[r0 + dr, c0] or occ[r0, c0 + dc]):
            return False
    return True


@settings(max_examples=50, deadline=None)
@given(grids(), st.sampled_from(["octile", "euclidean", "zero"]), st.floats(0.05, 2.0))
def test_astar_cost_equals_dijkstra(case, heuristic, res) -> None:
    occ, start, goal = case
    a = astar(occ, start, goal, resolution=res, heuristic=heuristic)
    d = dijkstra(occ, start, goal, resolution=res)
    assert a.found == d.found
    if d.found:
        assert a.cost == pytest.approx(d.cost, rel=1e-9, abs=1e-12)
        assert path_cost(a.cells, res) == pytest.approx(a.cost, rel=1e-9, abs=1e-12)
        assert tuple(a.cells[0]) == start and tuple(a.cells[-1]) == goal
        assert _valid_moves(occ, a.cells) and _valid_moves(occ, d.cells)


def test_free_grid_cost_is_octile_distance() -> None:
    occ = np.zeros((30, 40), dtype=bool)
    res = astar(occ, (2, 3), (25, 37), resolution=0.5)
    dr, dc = 23, 34
    assert res.cost == pytest.approx(0.5 * (max(dr, dc) + (math.sqrt(2) - 1) * min(dr, dc)))


def test_octile_expands_fewer_than_dijkstra_order() -> None:
    occ = np.zeros((60, 60), dtype=bool)
    occ[10:50, 30] = True
    a = astar(occ, (30, 5), (30, 55), heuristic="octile")
    z = astar(occ, (30, 5), (30, 55), heuristic="zero")
    assert a.cost == pytest.approx(z.cost)
    assert a.expanded < z.expanded / 2


def test_wall_blocks_and_no_corner_squeeze() -> None:
    occ = np.zeros((5, 5), dtype=bool)
    occ[:, 2] = True
    assert not astar(occ, (0, 0), (0, 4)).found
    assert not dijkstra(occ, (0, 0), (0, 4)).found
    # two cells touching at a corner: the diagonal between them is closed
    occ = np.zeros((2, 2), dtype=bool)
    occ[0, 1] = occ[1, 0] = True
    assert not astar(occ, (0, 0), (1, 1)).found
    assert len(grid_edges(occ, 1.0)[0]) == 0


def test_bad_inputs() -> None:
    occ = np.zeros((3, 3), dtype=bool)
    with pytest.raises(ValueError, match="outside"):
        astar(occ, (0, 0), (5, 5))
    with pytest.raises(ValueError, match="heuristic"):
        astar(occ, (0, 0), (2, 2), heuristic="manhattan")  # type: ignore[arg-type]


@settings(max_examples=60, deadline=None)
@given(st.tuples(st.integers(0, 9), st.integers(0, 7)), st.tuples(st.integers(0, 9),
       st.integers(0, 7)), st.integers(0, 2**32 - 1))  # fmt: skip
def test_costed_dijkstra_is_connected_cheapest_and_octile_on_free_ground(
    start: tuple[int, int], goal: tuple[int, int], seed: int
) -> None:
    cost = np.random.default_rng(seed).uniform(0.0, 3.0, (10, 8))
    path = costed_dijkstra(cost, start, goal, weight=2.0)
    cells = [tuple(c) for c in path.cells.tolist()]
    assert cells[0] == start and cells[-1] == goal
    steps = np.abs(np.diff(path.cells, axis=0))
    assert (steps.max(axis=1) == 1).all() if len(steps) else start == goal
    moves = np.hypot(*np.diff(path.cells, axis=0).T)
    mean = 0.5 * (cost[tuple(path.cells[:-1].T)] + cost[tuple(path.cells[1:].T)])
    assert path.cost == pytest.approx(float((moves * (1.0 + 2.0 * mean)).sum()))
    straight = costed_dijkstra(cost, start, goal, weight=0.0)  # no cost: the shortest
    assert straight.cost == pytest.approx(dijkstra(np.zeros((10, 8), bool), start, goal).cost)
    assert (
        path.cost
        <= float(
            (
                np.hypot(*np.diff(straight.cells, axis=0).T)
                * (
                    1.0
                    + 2.0
                    * 0.5
                    * (cost[tuple(straight.cells[:-1].T)] + cost[tuple(straight.cells[1:].T)])
                )
            ).sum()
        )
        + 1e-9
    )
