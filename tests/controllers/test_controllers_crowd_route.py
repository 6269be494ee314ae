"""The route layer around the crowd (uvnav.controllers.crowd_route) and the v2 laws that use it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers.crowd_route import (
    CrowdRoute,
    RouteParams,
    fan_way_points,
    route_costs,
    route_costs_py,
)
from uvnav.controllers.zhang2019_v2 import Zhang2019HolonomicV2Params, Zhang2019V2Params
from uvnav.geometry.kernels3d import compiled
from uvnav.sensors.observation import ObstacleReading

GOAL = np.array([12.0, 0.0])
ON = RouteParams(route_weight=2.0)
point = st.tuples(st.floats(-8.0, 8.0), st.floats(-8.0, 8.0)).map(np.array)


def person(k: int, x: float, y: float, vx: float, vy: float, r: float = 0.3) -> ObstacleReading:
    """A disc of radius ``r`` seen from the origin."""
    c = np.array([x, y])
    d = float(np.hypot(x, y))
    return ObstacleReading(k, max(d - r, 0.0), c * (1.0 - r / max(d, 1e-9)), c,
                           np.array([vx, vy]), 0.0, np.zeros((0, 2)), r, r)  # fmt: skip


def stream(vx: float, vy: float) -> list[ObstacleReading]:
    """Eight people on and around the direct line 2-5 m ahead, all at (vx, vy)."""
    spots = [(2.0, 0.0), (3.0, 0.5), (3.0, -0.5), (4.0, 0.0), (4.0, 1.0), (4.0, -1.0),
             (5.0, 0.5), (5.0, -0.5)]  # fmt: skip
    return [person(k, x, y, vx, vy) for k, (x, y) in enumerate(spots)]


def test_people_walking_on_the_way_are_gone_around() -> None:
    route = CrowdRoute(ON, 0.1)
    aim = route.aim(np.zeros(2), GOAL, stream(-1.0, 0.0), 1.0)
    assert not np.array_equal(aim, GOAL)
    assert abs(aim[1]) > 1.0  # well off the direct line
    assert math.hypot(*aim) == pytest.approx(ON.route_lookahead)


def test_a_clear_way_people_standing_or_the_layer_off_keep_the_goal() -> None:
    walking_far = [person(0, 0.0, 30.0, 1.0, 0.0)]
    assert CrowdRoute(ON, 0.1).aim(np.zeros(2), GOAL, walking_far, 1.0) is GOAL
    assert CrowdRoute(ON, 0.1).aim(np.zeros(2), GOAL, stream(0.0, 0.0), 1.0) is GOAL
    assert CrowdRoute(ON, 0.1).aim(np.zeros(2), GOAL, (), 1.0) is GOAL
    assert CrowdRoute(RouteParams(), 0.1).aim(np.zeros(2), GOAL, stream(-1.0, 0.0), 1.0) is GOAL
    near = np.array([0.5, 0.0])
    assert CrowdRoute(ON, 0.1).aim(np.zeros(2), near, stream(-1.0, 0.0), 1.0) is near


def test_the_way_point_is_held_until_another_is_clearly_better() -> None:
    route = CrowdRoute(ON, 0.1)
    first = route.aim(np.zeros(2), GOAL, stream(-1.0, 0.0), 1.0).copy()
    # a step on, the same stream: the held way point wins over its neighbours in the fan
    again = route.aim(np.array([0.1, 0.0]), GOAL, stream(-1.0, 0.0), 1.0)
    assert np.array_equal(again, first)
    route.reset()
    assert route.way is None


@settings(max_examples=60, deadline=None)
@given(position=point, goal=point)
def test_routes_are_no_shorter_than_the_direct_one(position: np.ndarray, goal: np.ndarray) -> None:
    ways = fan_way_points(position, goal, 4.0)
    assert np.array_equal(ways[0], goal)
    length = route_costs(position, goal, ways, np.zeros((0, 5)), 1.0, RouteParams(route_weight=1.0))
    direct = math.dist(position, goal)
    assert length[0] == pytest.approx(direct, abs=1e-9)
    assert (length >= direct - 1e-9).all()
    assert np.allclose(
        length[1:], np.hypot(*(ways[1:] - position).T) + np.hypot(*(goal - ways[1:]).T)
    )


@settings(max_examples=60, deadline=None)
@given(centre=point, velocity=st.tuples(st.floats(-1.5, 1.5), st.floats(-1.5, 1.5)))
def test_a_person_costs_one_per_metre_walked_through_them_and_nothing_far_off(
    centre: np.ndarray, velocity: tuple[float, float]
) -> None:
    """A 0.1 m route through a (large) person's centre at t = 0 pays 0.1 m of exposure; one
    100 m away pays none."""
    body = np.array([[*centre, *velocity, 0.3]])
    ways = centre + np.array([[0.1, 0.0], [100.1, 100.0]])
    starts = (centre, centre + 100.0)
    for start, way in zip(starts, ways, strict=True):
        bare = route_costs(start, way, way[None], body, 1e6, RouteParams(route_weight=0.0))
        paid = route_costs(start, way, way[None], body, 1e6, RouteParams(route_weight=1.0))
        near = math.dist(start, centre) < 1.0
        assert paid[0] - bare[0] == pytest.approx(0.1 if near else 0.0, abs=1e-9)


@pytest.mark.parametrize("enabled", [True, False])
def test_compiled_and_python_route_costs_agree(enabled: bool) -> None:
    rng = np.random.default_rng(3)
    bodies = np.column_stack((rng.uniform(-6, 6, (30, 2)), rng.uniform(-1, 1, (30, 2)),
                              rng.uniform(0.3, 0.5, 30)))  # fmt: skip
    position, goal = np.array([0.0, -6.0]), np.array([0.0, 6.0])
    ways = fan_way_points(position, goal, 4.0)
    with compiled(enabled):
        got = route_costs(position, goal, ways, bodies, 1.0, ON)
    want = np.empty(len(ways))
    sigma, horizon, weight = ON.route_sigma, ON.route_horizon, ON.route_weight
    route_costs_py(0.0, -6.0, ways, 0.0, 6.0, bodies, 1.0, sigma, horizon, weight, want)
    assert np.allclose(got, want, rtol=1e-12, atol=1e-12)


def test_holonomic_v2_routes_by_default_the_unicycle_does_not() -> None:
    assert Zhang2019HolonomicV2Params().route_weight > 0
    assert Zhang2019V2Params().route_weight == 0
    with pytest.raises(ValueError, match="route_sigma must be a number > 0"):
        Zhang2019V2Params(route_sigma=0.0)
    with pytest.raises(ValueError, match="route_weight must be a number >= 0"):
        Zhang2019HolonomicV2Params(route_weight=-1.0)


def test_the_route_keeps_the_robot_out_of_the_harder_crowds_way() -> None:
    """crowd-dynamic cases 0-3 (20 walking humans, 5 m sensing): with the route the robot
    intrudes on the humans' forecasts less than steering for the goal itself."""
    from uvnav.scenarios.catalog import generate
    from uvnav.scenarios.episodes import run_scene

    def intrusion(weight: float) -> float:
        runs = [run_scene(generate("crowd-dynamic", s, {}), "zhang2019-holonomic-v2",
                          {"route_weight": weight}) for s in range(4)]  # fmt: skip
        return float(np.mean([o.metrics["intrusion_ratio"] for o in runs]))

    assert intrusion(2.0) < 0.5 * intrusion(0.0)
