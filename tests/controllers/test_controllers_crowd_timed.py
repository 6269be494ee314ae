"""The route searched over cells and time (uvnav.controllers.crowd_timed)."""

from __future__ import annotations

import numpy as np
import pytest

from uvnav.controllers.crowd_grid import grid_way_point
from uvnav.controllers.crowd_route import CrowdRoute, RouteParams
from uvnav.controllers.crowd_timed import _search, timed_search_py, timed_way_point

START, GOAL = np.array([0.0, 0.0]), np.array([0.0, 5.0])
#: v_max, forecast horizon, sigma, weight, ahead, planned share of v_max, layer, span
ARGS = (1.0, 4.0, 0.6, 3.0, 2.0, 0.8, 0.5, 6.0)


def crossing(y: float = 2.0) -> np.ndarray:
    """Ten people walking +x at 1 m/s in a line across the robot's way (at ``y``), the leader
    at x = 0.3 m: the bodies table (centre, velocity, radius)."""
    return np.array([[x, y, 1.0, 0.0, 0.3] for x in np.arange(-6.0, 0.5, 0.7)])


def test_on_open_ground_the_way_point_lies_ahead_at_the_planned_speed() -> None:
    way = timed_way_point(START, GOAL, np.zeros((0, 5)), *ARGS)
    assert abs(way[0]) <= 0.25 and way[1] == pytest.approx(2.0, abs=0.3)


def test_a_crowd_crossing_in_front_is_passed_behind_not_raced() -> None:
    # the grid (cells timed at their straight-line distance) races the line's leader to the
    # right; the search over time lets the line go by and passes behind it, on the left
    bodies = crossing()
    assert grid_way_point(START, GOAL, bodies, 1.0, 2.0, 0.6, 3.0, 2.0)[0] > 1.0
    way = timed_way_point(START, GOAL, bodies, *ARGS)
    assert way[0] < 0.0 and way[1] < 1.5


def test_the_compiled_search_agrees_with_plain_python() -> None:
    rng = np.random.default_rng(3)
    cost = rng.random((4, 9, 7)) * 3.0
    start, goal = np.array([0, 0]), np.array([8, 6])
    a, b = np.empty((252, 3)), np.empty((252, 3))
    m = timed_search_py(cost, 0.5, 0.8, start, goal, 2.0, a)
    assert _search()(cost, 0.5, 0.8, start, goal, 2.0, b) == m > 0
    np.testing.assert_allclose(a[:m], b[:m])
    assert a[0].tolist() == [0, 0, 0.0] and a[m - 1, :2].tolist() == [8, 6]
    assert np.all(np.diff(a[:m, 2]) > 0)  # time runs on along the path


def test_the_route_searches_over_time_only_when_asked() -> None:
    with pytest.raises(ValueError, match="route_timed"):
        RouteParams(route_timed=-1.0)
    route = CrowdRoute(RouteParams(route_timed=0.8, route_timed_horizon=4.0), 0.1)
    route.reset(limited=True, unicycle=True)
    assert route.grid
