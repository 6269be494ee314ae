"""The route layer around the crowd (uvnav.controllers.crowd_route) and the v2 laws that use it."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers.crowd_route import (
    CUT,
    SPACING,
    CrowdRoute,
    RouteParams,
    fan_way_points,
    moving_bodies,
    nearest,
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


def test_a_route_period_holds_the_last_search_until_it_runs_out() -> None:
    """With ``route_period`` the fan is searched again only once the period has passed (or the
    way point is reached): in between, a crowd that walks off the way does not move the aim."""
    route = CrowdRoute(RouteParams(route_weight=2.0, route_period=0.75), 0.1)
    first = route.aim(np.zeros(2), GOAL, stream(-1.0, 0.0), 1.0, 0.0).copy()
    assert not np.array_equal(first, GOAL)
    gone = [person(0, 0.0, 30.0, 1.0, 0.0)]  # the way is clear now
    assert np.array_equal(route.aim(np.zeros(2), GOAL, gone, 1.0, 0.5), first)
    assert route.aim(np.zeros(2), GOAL, gone, 1.0, 0.75) is GOAL  # searched again
    every = CrowdRoute(ON, 0.1)  # period 0: every decision searches
    every.aim(np.zeros(2), GOAL, stream(-1.0, 0.0), 1.0, 0.0)
    assert every.aim(np.zeros(2), GOAL, gone, 1.0, 0.25) is GOAL
    # a way point reached, or the goal within DIRECT_WITHIN, ends the hold at once
    route.reset()
    way = route.aim(np.zeros(2), GOAL, stream(-1.0, 0.0), 1.0, 0.0).copy()
    assert route.aim(way, GOAL, gone, 1.0, 0.25) is GOAL
    near = np.array([0.5, 0.0])
    assert route.aim(np.zeros(2), near, stream(-1.0, 0.0), 1.0, 0.3) is near


def test_route_bodies_keeps_the_nearest_walking_people() -> None:
    crowd = [*stream(-1.0, 0.0), person(9, 0.0, 30.0, 1.0, 0.0)]
    table = moving_bodies(crowd, 0.1)
    two = nearest(table, np.zeros(2), 2)
    assert two[:, :2].tolist() == [[2.0, 0.0], [3.0, 0.5]]
    assert nearest(table, np.zeros(2), 0) is table
    assert nearest(table, np.zeros(2), len(table)) is table
    # only the far walker kept: the direct route is clear of it
    far_only = CrowdRoute(RouteParams(route_weight=2.0, route_bodies=1), 0.1)
    assert far_only.aim(np.zeros(2), GOAL, [person(0, 0.0, 30.0, 1.0, 0.0)], 1.0) is GOAL
    # the nearest walks off the way, the stream behind it blocks it: costed only with all
    aside = [person(8, 0.5, -1.0, 0.0, -1.0), *stream(-1.0, 0.0)]
    one = CrowdRoute(RouteParams(route_weight=2.0, route_bodies=1), 0.1)
    assert one.aim(np.zeros(2), GOAL, aside, 1.0) is GOAL
    assert not np.array_equal(CrowdRoute(ON, 0.1).aim(np.zeros(2), GOAL, aside, 1.0), GOAL)
    with pytest.raises(ValueError, match="route_bodies must be an integer >= 0"):
        RouteParams(route_bodies=-1)
    with pytest.raises(ValueError, match="route_period must be a number >= 0"):
        RouteParams(route_period=-0.5)


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


def every_pair_costs(position: np.ndarray, goal: np.ndarray, ways: np.ndarray,
                     bodies: np.ndarray, p: RouteParams) -> np.ndarray:  # fmt: skip
    """The exposure of every sample over every body, nothing culled, in the kernel's order
    (samples in turn, bodies in turn): what :func:`route_costs_py` must give."""
    far, sigma, out = (CUT * p.route_sigma) ** 2, p.route_sigma, np.zeros(len(ways))
    for k, way in enumerate(ways):
        length, cost = 0.0, 0.0
        for a, b in ((position, way), (way, goal)):
            d = b - a
            size = math.sqrt(d[0] * d[0] + d[1] * d[1])
            n = max(math.ceil(size / SPACING), 1)
            for j in range(n):
                s = a + d * ((j + 0.5) / n)
                t = min((length + size / n * (j + 0.5)) / 1.0, p.route_horizon)
                for c in bodies:
                    e = s - c[:2] - c[2:4] * t
                    gap = math.sqrt(e[0] * e[0] + e[1] * e[1]) - c[4]
                    if gap <= 0.0:
                        cost += size / n
                    elif gap * gap < far:
                        cost += size / n * math.exp(-0.5 * (gap / sigma) ** 2)
            length += size
        out[k] = length + p.route_weight * cost
    return out


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(0, 30), sigma=st.sampled_from([0.3, 0.8]))
def test_culling_samples_out_of_reach_changes_no_bit(seed: int, n: int, sigma: float) -> None:
    """The kernel visits each body's samples within its reach only; the pairs it skips add
    nothing, so its costs are those of every pair, to the bit."""
    rng = np.random.default_rng(seed)
    bodies = np.column_stack([rng.uniform(-10, 10, (n, 2)), rng.uniform(-1.5, 1.5, (n, 2)),
                              rng.uniform(0.2, 0.6, n)])  # fmt: skip
    position, goal = rng.uniform(-8, 8, 2), rng.uniform(-8, 8, 2)
    ways = np.vstack((fan_way_points(position, goal, 4.0), position[None]))  # a leg of no length
    p = RouteParams(route_weight=2.0, route_sigma=sigma)
    got = np.empty(len(ways))
    route_costs_py(position[0], position[1], ways, goal[0], goal[1], bodies, 1.0, sigma,
                   p.route_horizon, 2.0, got)  # fmt: skip
    assert np.array_equal(got, every_pair_costs(position, goal, ways, bodies, p))


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


def test_both_v2_laws_route_by_default_the_unicycle_less_often_over_fewer_walkers() -> None:
    holo, uni = Zhang2019HolonomicV2Params(), Zhang2019V2Params()
    assert holo.route_weight > 0 and uni.route_weight > 0
    assert (holo.route_period, holo.route_bodies) == (0.0, 0)  # every decision, every walker
    assert (uni.route_period, uni.route_bodies) == (0.75, 12)
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
