"""The grid route around the crowd (uvnav.controllers.crowd_grid) and the limited v2 using it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers.base import make_law
from uvnav.controllers.crowd_grid import (
    CELL,
    REACH,
    _exposure,
    exposure_map_py,
    grid_bodies,
    grid_way_point,
)
from uvnav.controllers.crowd_route import CrowdRoute, RouteParams
from uvnav.dynamics.unicycle import UnicycleSpec
from uvnav.geometry.kernels3d import compiled
from uvnav.sensors.observation import ObstacleReading

LIMITED = UnicycleSpec(v_max=1.0, u_max=2.0, radius=0.3, accel_max=1.0, turn_accel_max=2.0)


def person(k: int, x: float, y: float, vx: float = 0.0, vy: float = 0.0) -> ObstacleReading:
    """A disc of radius 0.3 m seen from the origin."""
    c, r = np.array([x, y]), 0.3
    d = float(np.hypot(x, y))
    return ObstacleReading(k, max(d - r, 0.0), c * (1.0 - r / max(d, 1e-9)), c,
                           np.array([vx, vy]), 0.0, np.zeros((0, 2)), r, r)  # fmt: skip


def wall(gap_y: float) -> np.ndarray:
    """People standing shoulder to shoulder across x = 3 m, from y = -6 to 6 m, but for a gap
    about ``gap_y``: the bodies table (centre, velocity, radius)."""
    ys = [y for y in np.arange(-6.0, 6.01, 0.5) if abs(y - gap_y) > 1.0]
    return np.array([[3.0, y, 0.0, 0.0, 0.3] for y in ys])


def test_a_cell_costs_by_where_a_walker_will_be_when_the_robot_gets_there() -> None:
    out = np.zeros((1, 1))
    walker = np.array([[2.0, 2.0, 0.0, -1.0, 0.3]])  # walks down onto the cell in 2 s
    exposure_map_py(1.875, -0.125, 0.0, 0.0, walker, 1.0, 2.0, 0.5, out)  # cell at (2, 0)
    assert out[0, 0] == pytest.approx(1.0)  # reached at t = 2 s, when the walker is there
    exposure_map_py(1.875, -0.125, 0.0, 0.0, walker, 1.0, 0.5, 0.5, out)  # forecast capped
    assert out[0, 0] == pytest.approx(math.exp(-0.5 * ((1.5 - 0.3) / 0.5) ** 2))


def test_the_way_point_heads_for_the_gap_in_a_wall_of_people() -> None:
    for gap_y in (-3.0, 3.0):
        way = grid_way_point(np.zeros(2), np.array([6.0, 0.0]), wall(gap_y), 1.0, 2.0, 0.6,
                             3.0, 2.0)  # fmt: skip
        assert np.sign(way[1]) == np.sign(gap_y) and abs(way[1]) > 0.5
        assert math.hypot(*way) == pytest.approx(2.0, abs=2 * CELL)


def test_on_open_ground_the_way_point_lies_ahead_on_the_line_and_far_goals_are_cut() -> None:
    far = np.array([[0.0, 40.0, 0.0, 0.0, 0.3]])
    way = grid_way_point(np.zeros(2), np.array([30.0, 0.0]), far, 1.0, 2.0, 0.6, 3.0, 2.0)
    assert way[0] == pytest.approx(2.0, abs=CELL) and abs(way[1]) <= CELL
    way = grid_way_point(np.zeros(2), np.array([30.0, 0.0]), far, 1.0, 2.0, 0.6, 3.0, 99.0)
    assert way.tolist() == pytest.approx([REACH, 0.0])  # the path is shorter: its (sub)goal


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_compiled_map_agrees_with_plain_python(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(0, 40))
    bodies = np.column_stack([rng.uniform(-9, 9, (n, 2)), rng.uniform(-1.5, 1.5, (n, 2)),
                              rng.uniform(0.2, 0.5, n)])  # fmt: skip
    ref, got = np.empty((12, 9)), np.empty((12, 9))
    exposure_map_py(-1.5, -1.0, 0.3, -0.2, bodies, 1.0, 2.0, 0.6, ref)
    with compiled(True):
        _exposure()(-1.5, -1.0, 0.3, -0.2, bodies, 1.0, 2.0, 0.6, got)
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-15)  # libm vs LLVM: last digits
    np.testing.assert_allclose(
        ref, _every_body(-1.5, -1.0, 0.3, -0.2, bodies, ref.shape), rtol=1e-12, atol=1e-15
    )  # the culled bodies add nothing


def _every_body(x0: float, y0: float, px: float, py: float, bodies: np.ndarray,
                shape: tuple[int, ...]) -> np.ndarray:  # fmt: skip
    """The exposure map's formula over every cell and every body (numpy, no culling; v = 1
    m/s, horizon 2 s, sigma 0.6 m)."""
    cx = x0 + (np.arange(shape[0]) + 0.5) * CELL
    cy = y0 + (np.arange(shape[1]) + 0.5) * CELL
    gx, gy = np.meshgrid(cx, cy, indexing="ij")
    t = np.minimum(np.hypot(gx - px, gy - py), 2.0)[..., None]
    gap = np.hypot(gx[..., None] - bodies[:, 0] - bodies[:, 2] * t,
                   gy[..., None] - bodies[:, 1] - bodies[:, 3] * t) - bodies[:, 4]  # fmt: skip
    each = np.where(gap <= 0.0, 1.0, np.exp(-0.5 * (np.maximum(gap, 0.0) / 0.6) ** 2))
    return np.where(gap < 5.0 * 0.6, each, 0.0).sum(axis=-1)


def test_the_route_plans_on_the_grid_only_for_a_limited_vehicle() -> None:
    goal = np.array([6.0, 0.0])
    people = [person(k, 3.0, y) for k, y in enumerate(np.arange(-6.0, 6.01, 0.5))
              if abs(y - 3.0) > 1.0]  # fmt: skip
    route = CrowdRoute(RouteParams(), 0.1)
    route.reset(limited=True)
    aim = route.aim(np.zeros(2), goal, people, 1.0)
    assert aim[1] > 0.5  # toward the gap, standing people counted
    route.reset(limited=False)
    assert route.aim(np.zeros(2), goal, people, 1.0) is goal  # the fan is off by default
    off = CrowdRoute(RouteParams(route_grid_weight=0.0), 0.1)
    off.reset(limited=True)
    assert off.aim(np.zeros(2), goal, people, 1.0) is goal
    route.reset(limited=True)
    assert route.aim(np.zeros(2), goal, (), 1.0) is goal
    assert route.aim(np.array([5.5, 0.0]), goal, people, 1.0) is goal  # within 1 m of it


def slab(k: int, y0: float, y1: float) -> ObstacleReading:
    """A static wall 0.2 m thick across x = 3 m from ``y0`` to ``y1`` [m], seen from the
    origin."""
    outline = np.array([[3.0, y0], [3.2, y0], [3.2, y1], [3.0, y1]])
    c = outline.mean(axis=0)
    bound = float(np.hypot(*(outline - c).T).max())
    return ObstacleReading(k, 3.0, np.array([3.0, 0.0]), c, np.zeros(2), 0.0, outline, 0.0,
                           bound)  # fmt: skip


def test_a_wall_costs_along_its_outline_and_the_route_heads_for_its_doorway() -> None:
    """A wall with a doorway, as two polygons: the route plans round their outlines (read as
    discs along them, not as their bounding discs, which put the doorway at y = -2 m inside
    both) and heads for the doorway, on either side."""
    route = CrowdRoute(RouteParams(), 0.1)
    route.reset(limited=True)
    for gap in (-2.0, 2.0):
        walls = (slab(0, -8.0, gap - 0.8), slab(1, gap + 0.8, 8.0))
        bodies = grid_bodies(walls)
        assert np.abs(bodies[:, 0] - 3.1).max() <= 0.1 + 1e-9  # on the outlines
        aim = route.aim(np.zeros(2), np.array([6.0, 0.0]), walls, 1.0)
        assert np.sign(aim[1]) == np.sign(gap) and abs(aim[1]) > 1.0, gap


def test_zhang2019_v2_plans_the_grid_route_with_acceleration_limits_or_when_asked() -> None:
    ideal = UnicycleSpec(v_max=1.0, u_max=2.0, radius=0.3)
    law = make_law("zhang2019-v2")
    law.reset(LIMITED, np.array([6.0, 0.0]), np.random.default_rng(0))
    assert law._route.grid
    law.reset(ideal, np.zeros(2), np.random.default_rng(0))
    assert not law._route.grid
    law = make_law("zhang2019-v2", route_grid="all")
    law.reset(ideal, np.zeros(2), np.random.default_rng(0))
    assert law._route.grid
    holonomic = make_law("zhang2019-holonomic-v2", route_grid="all")
    holonomic.reset(ideal, np.zeros(2), np.random.default_rng(0))
    assert not holonomic._route.grid  # the fan, whatever route_grid says
    with pytest.raises(ValueError, match="route_grid_weight"):
        make_law("zhang2019-v2", route_grid_weight=-1.0)
    with pytest.raises(ValueError, match="route_grid must be one of limited, all"):
        make_law("zhang2019-v2", route_grid="some")


def test_the_grid_way_point_is_held_for_route_grid_period() -> None:
    """With ``route_grid_period`` the grid is searched again only once it has passed: the way point
    found at t = 0 is kept at t = 0.5 s although the people moved; at t = 1 s it is searched
    again."""
    goal = np.array([6.0, 0.0])
    route = CrowdRoute(RouteParams(route_grid_period=1.0), 0.1)
    route.reset(limited=True, unicycle=True)
    gap_left = [person(k, 3.0, y) for k, y in enumerate(np.arange(-6.0, 6.01, 0.5))
                if abs(y - 3.0) > 1.0]  # fmt: skip
    gap_right = [person(k, 3.0, y) for k, y in enumerate(np.arange(-6.0, 6.01, 0.5))
                 if abs(y + 3.0) > 1.0]  # fmt: skip
    first = route.aim(np.zeros(2), goal, gap_left, 1.0, 0.0)
    assert first[1] > 0.5
    assert route.aim(np.zeros(2), goal, gap_right, 1.0, 0.5) is first
    assert route.aim(np.zeros(2), goal, gap_right, 1.0, 1.0)[1] < -0.5
