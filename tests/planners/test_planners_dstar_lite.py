"""D* Lite: first plan and every replan after map changes equal A* from scratch."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.planners import DStarLite, astar, path_cost


@settings(max_examples=60, deadline=None)
@given(
    st.integers(3, 14),
    st.integers(3, 14),
    st.floats(0.0, 0.4),
    st.integers(0, 2**31 - 1),
    st.integers(1, 5),
)
def test_replans_equal_astar_from_scratch(rows, cols, density, seed, rounds) -> None:
    rng = np.random.default_rng(seed)
    occ = rng.random((rows, cols)) < density
    start = (int(rng.integers(rows)), int(rng.integers(cols)))
    goal = (int(rng.integers(rows)), int(rng.integers(cols)))
    occ[start] = occ[goal] = False
    planner = DStarLite(occ, start, goal, resolution=0.3)
    for _ in range(rounds):
        planner.compute()
        ref = astar(planner.occupancy(), planner.start, goal, resolution=0.3)
        path = planner.path()
        assert path.found == ref.found
        if ref.found:
            assert planner.cost() == pytest.approx(ref.cost, rel=1e-9, abs=1e-12)
            assert path_cost(path.cells, 0.3) == pytest.approx(ref.cost, rel=1e-9, abs=1e-12)
            assert tuple(path.cells[0]) == planner.start
            assert tuple(path.cells[-1]) == goal
            # the robot advances a few cells along its path
            step = min(len(path.cells) - 1, int(rng.integers(0, 4)))
            planner.move_start((int(path.cells[step][0]), int(path.cells[step][1])))
        # random changes: block and free a few cells (never the robot's cell or the goal)
        k = int(rng.integers(1, 6))
        cells = [(int(rng.integers(rows)), int(rng.integers(cols))) for _ in range(k)]
        cells = [c for c in cells if c not in (planner.start, goal)]
        planner.set_cells(cells, occupied=bool(rng.random() < 0.7))
    planner.compute()
    ref = astar(planner.occupancy(), planner.start, goal, resolution=0.3)
    assert planner.path().found == ref.found
    if ref.found:
        assert planner.cost() == pytest.approx(ref.cost, rel=1e-9, abs=1e-12)


def test_local_change_replans_with_little_work() -> None:
    rng = np.random.default_rng(3)
    occ = rng.random((120, 120)) < 0.2
    occ[5, 5] = occ[115, 110] = False
    planner = DStarLite(occ, (5, 5), (115, 110))
    planner.compute()
    path = planner.path()
    # the robot advances 10 cells, then a 3x3 obstacle appears on its path 5 cells ahead
    planner.move_start(tuple(int(v) for v in path.cells[10]))
    r, c = (int(v) for v in path.cells[15])
    planner.set_cells([(r + dr, c + dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1)])
    before = planner.expanded
    planner.compute()
    ref = astar(planner.occupancy(), planner.start, (115, 110))
    assert planner.cost() == pytest.approx(ref.cost)
    assert path_cost(planner.path().cells) == pytest.approx(ref.cost)
    assert planner.expanded - before < ref.expanded / 5


def test_wall_across_the_path_raises_the_cost() -> None:
    occ = np.zeros((120, 120), dtype=bool)
    occ[20:100, 60] = True
    planner = DStarLite(occ, (60, 5), (60, 115))
    before = planner.compute()
    r, c = (int(v) for v in planner.path().cells[4])
    planner.set_cells([(r + dr, c) for dr in range(-12, 13)])
    assert planner.compute() > before
    assert planner.cost() == pytest.approx(astar(planner.occupancy(), (60, 5), (60, 115)).cost)


def test_unreachable_goal_and_goal_blocked() -> None:
    occ = np.zeros((6, 6), dtype=bool)
    occ[:, 3] = True
    p = DStarLite(occ, (0, 0), (5, 5))
    assert p.compute() == float("inf")
    assert not p.path().found
    p.set_cells([(2, 3)], occupied=False)
    p.compute()
    assert p.path().found
    p.set_cells([(5, 5)])
    assert p.compute() == float("inf")
