"""Visibility-graph shortest paths: exact on known cases, never through obstacles, never longer
than the grid path."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.planners import astar, grown_obstacles, occupancy_grid, path_cost, visibility_path


def _box(x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])


def test_square_in_the_way_known_length() -> None:
    path = visibility_path((0, 0), (4, 0), [_box(1, -1, 3, 1)])
    # over a corner: two diagonals of length sqrt(2) plus the 2 m edge
    assert path.cost == pytest.approx(2 * math.sqrt(2) + 2)
    assert len(path.points) == 4


def test_free_is_straight_and_blocked_is_none() -> None:
    p = visibility_path((0, 0), (3, 4), [])
    assert p.cost == pytest.approx(5.0) and len(p.points) == 2
    ring = [_box(-2, -2, 2, -1.5), _box(-2, 1.5, 2, 2), _box(-2, -2, -1.5, 2), _box(1.5, -2, 2, 2)]
    assert not visibility_path((0, 0), (5, 5), ring).found
    assert not visibility_path((0, -1.7), (5, 5), ring).found  # start inside


@settings(max_examples=10, deadline=None)
@given(st.integers(0, 2**31 - 1), st.integers(1, 5), st.floats(0.0, 0.3))
def test_path_clear_and_not_longer_than_grid(seed, k, inflate) -> None:
    rng = np.random.default_rng(seed)
    polys = []
    for _ in range(k):
        c = rng.uniform(1.5, 8.5, size=2)
        w = rng.uniform(0.3, 1.2, size=2)
        polys.append(_box(c[0] - w[0], c[1] - w[1], c[0] + w[0], c[1] + w[1]))
    start, goal = np.array([0.2, 0.2]), np.array([9.8, 9.8])
    path = visibility_path(start, goal, polys, inflate=inflate)
    obstacles = grown_obstacles(polys, inflate)
    if not path.found:
        return
    line = shapely.LineString(path.points)
    assert not shapely.relate_pattern(line, obstacles, "T********")
    assert path.cost >= float(np.hypot(*(goal - start))) - 1e-9
    # a grid path (grid inflated more: its free space lies inside the polygon free space)
    res = 0.1
    grid = occupancy_grid((0, 0, 10, 10), res, polys, inflate=inflate + 1e-6)
    s, g = grid.to_cell(start), grid.to_cell(goal)
    if grid.occupied[s] or grid.occupied[g]:
        return
    gp = astar(grid.occupied, s, g, resolution=res)
    if gp.found:
        pts = grid.to_world(gp.cells)
        full = path_cost(gp.cells, res) + np.hypot(*(pts[0] - start)) + np.hypot(*(pts[-1] - goal))
        assert path.cost <= full + 1e-6
