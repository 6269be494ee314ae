"""random_ch2_scenario: deterministic, valid, non-convex, in the way but clear of start and goal."""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import Point, Polygon

from uvnav.scenarios import RandomTurnMotion, check_constraints, random_ch2_scenario
from uvnav.scenarios.generators import is_convex, is_star_about, random_star_polygon

SEEDS = range(25)
V_MAX = 0.707


def placed(ob) -> Polygon:  # type: ignore[no-untyped-def]
    body = ob.body.to_body()
    c, s = np.cos(ob.start.heading), np.sin(ob.start.heading)
    world = body.vertices @ np.array([[c, -s], [s, c]]).T + np.asarray(ob.start.position)
    return Polygon(world)


def test_deterministic_in_seed() -> None:
    for seed in (0, 1, 17):
        assert random_ch2_scenario(seed) == random_ch2_scenario(seed)
    assert random_ch2_scenario(0) != random_ch2_scenario(1)


def test_obstacle_count_is_drawn_in_1_to_6_unless_given() -> None:
    counts = {len(random_ch2_scenario(seed).obstacles) for seed in SEEDS}
    assert counts <= set(range(1, 7)) and len(counts) >= 3
    assert len(random_ch2_scenario(3, n_obstacles=6).obstacles) == 6
    assert random_ch2_scenario(3, n_obstacles=0).obstacles == []


def test_robot_matches_chapter_2() -> None:
    sc = random_ch2_scenario(4)
    r = sc.robot
    assert (r.start, r.goal, r.v_max, r.u_max, r.radius) == ((0, 0), (10, 10), 0.707, 1.414, 0.1)
    assert r.initial_heading() == pytest.approx(np.pi / 4)
    assert sc.t_max == 120 and sc.controller.name == "zhang2019-v1"


@pytest.mark.parametrize("seed", SEEDS)
def test_obstacles_are_valid_nonconvex_in_the_way_and_clear(seed: int) -> None:
    sc = random_ch2_scenario(seed)
    assert check_constraints(sc) == []
    polys = []
    for ob in sc.obstacles:
        verts = np.asarray(ob.body.polygon)
        assert 5 <= len(verts) <= 9
        shape = Polygon(verts)
        assert shape.is_valid
        assert shape.convex_hull.area > shape.area + 1e-9  # at least one reflex vertex
        body = ob.body.to_body()
        radii = np.hypot(body.vertices[:, 0], body.vertices[:, 1])
        assert radii.min() >= 0.3 - 1e-9 and radii.max() <= 0.9 + 1e-9
        assert is_star_about(body.vertices, np.zeros(2))
        world = placed(ob)
        polys.append(world)
        assert world.distance(Point(0, 0)) >= 1.5
        assert world.distance(Point(10, 10)) >= 1.5
        centre = np.asarray(ob.start.position)
        assert 2.0 - 1e-9 <= float(centre @ [1, 1]) / np.sqrt(2) <= 12.0 + 1e-9
        assert abs(float(centre[1] - centre[0]) / np.sqrt(2)) <= 2.0 + 1e-9
        m = ob.motion
        assert isinstance(m, RandomTurnMotion)
        assert 0.05 <= m.speed[0] <= m.speed[1] <= 0.5 * V_MAX + 1e-9
        assert -0.3 <= m.turn_rate[0] <= m.turn_rate[1] <= 0.3
        assert m.arena == (-3, -3, 13, 13)
    for i in range(len(polys)):
        for j in range(i + 1, len(polys)):
            assert not polys[i].intersects(polys[j])


def test_star_polygon_helpers() -> None:
    rng = np.random.default_rng(0)
    for _ in range(20):
        v = random_star_polygon(rng)
        assert not is_convex(v)
        assert is_star_about(v, np.zeros(2)) or is_star_about(v, v.mean(axis=0))
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    assert is_convex(square) and is_convex(square[::-1])
    dart = np.array([[0, 0], [2, 1], [0, 2], [0.5, 1]], dtype=float)
    assert not is_convex(dart)
