"""The built-in scenario library: the thesis's Chapter-2 scenes, loadable, valid and meaningful."""

from __future__ import annotations

import numpy as np
import pytest
from shapely.geometry import Polygon

from uvnav.controllers import make_controller
from uvnav.scenarios import (
    ConstantMotion,
    Scenario,
    build_episode,
    builtin_text,
    check_constraints,
    list_builtin,
    load_scenario,
)
from uvnav.sim import run_episode

THESIS = [
    "thesis-ch2-one-obstacle",
    "thesis-ch2-six-obstacles",
    "thesis-ch2-fig2-9-changing-direction",
    "thesis-ch2-fig2-10-comparison",
]
DIAGONAL = np.array([1.0, 1.0]) / np.sqrt(2.0)


def lateral(point: np.ndarray) -> float:
    """Signed distance [m] of ``point`` from the I->T line y = x (positive to the upper left)."""
    return float((point[1] - point[0]) / np.sqrt(2.0))


def along(point: np.ndarray) -> float:
    return float(np.dot(point, DIAGONAL))


def straight_status(sc: Scenario, seed: int) -> str:
    setup = build_episode(sc, seed)
    return run_episode(
        setup, make_controller("straight-v1"), np.random.default_rng(seed), record=False
    ).status


#: static walls and rooms (issue 9), checked in tests/controllers/test_controllers_hybrid.py
WALLED = ("corridor", "office-floor")


def test_thesis_experiments_come_first() -> None:
    names = list_builtin()
    assert set(THESIS) <= set(names)
    n_thesis = sum(n.startswith("thesis-") for n in names)
    assert all(n.startswith("thesis-") for n in names[:n_thesis])
    assert not any(n.startswith("thesis-") for n in names[n_thesis:])
    assert names[n_thesis:] == sorted(names[n_thesis:])


@pytest.mark.parametrize("name", list_builtin())
def test_every_builtin_loads_builds_and_obeys_the_constraints(name: str) -> None:
    sc = load_scenario(name)
    if getattr(sc, "dim", 2) == 3:
        pytest.skip("3D scene: tests/scenarios/test_scenarios_schema3d.py")
    assert sc.name == name
    assert sc.description
    setup = build_episode(sc, seed=0)
    if sc.crowd is not None:  # real pedestrians: (2.6)-(2.8) are warnings, see test_..._pedestrians
        assert "do not react to the robot" in sc.description
        assert all("warning only" in w for w in check_constraints(sc))
        assert len(setup.obstacles) > len(sc.obstacles)
        return
    assert check_constraints(sc) == []
    assert len(setup.obstacles) == len(sc.obstacles)
    if name in WALLED:  # issue 9's walled scenes: their own start and goal
        return
    r = sc.robot
    assert (r.start, r.goal, r.v_max, r.u_max) == ((0.0, 0.0), (10.0, 10.0), 0.707, 1.414)
    assert builtin_text(name).lstrip().startswith("#")  # a commented file, not a dump


@pytest.mark.parametrize("name", THESIS)
def test_thesis_scenes_put_an_obstacle_in_the_way(name: str) -> None:
    """Driving straight at V_max collides: the scene really tests obstacle avoidance."""
    sc = load_scenario(name)
    assert all(straight_status(sc, seed) == "collision" for seed in range(3))


def test_open_field_is_free_for_the_straight_law() -> None:
    assert straight_status(load_scenario("open-field"), seed=0) == "success"


def test_one_obstacle_scene_matches_fig_2_7() -> None:
    sc = load_scenario("thesis-ch2-one-obstacle")
    assert len(sc.obstacles) == 1
    ob = sc.obstacles[0]
    assert ob.body.polygon is not None and ob.motion.type == "random_turn"
    poly = Polygon(ob.body.polygon)
    assert poly.convex_hull.area > poly.area + 1e-6  # non-convex
    assert ob.start is not None
    centre = np.asarray(ob.start.position)
    assert abs(lateral(centre)) < 1.0 and 5.0 < along(centre) < 9.0  # near the middle of the path
    assert (sc.dt, sc.goal_tolerance) == (0.1, 0.1)


def test_six_obstacle_scene_matches_fig_2_8() -> None:
    sc = load_scenario("thesis-ch2-six-obstacles")
    assert len(sc.obstacles) == 6
    offsets = []
    for ob in sc.obstacles:
        assert ob.body.polygon is not None
        poly = Polygon(ob.body.polygon)
        assert poly.is_valid and poly.convex_hull.area > poly.area + 1e-6
        assert ob.start is not None
        offsets.append(
            (abs(lateral(np.asarray(ob.start.position))), along(np.asarray(ob.start.position)))
        )
    in_way = sorted(a for d, a in offsets if d < 1.0)
    away = [d for d, _ in offsets if d >= 1.0]
    assert len(in_way) == 3 and len(away) == 3
    assert all(d >= 3.0 for d in away)
    assert in_way[0] < 4.5 < in_way[1] < 7.5 < in_way[2]  # at different distances along the path
    assert {ob.motion.type for ob in sc.obstacles} == {"random_turn", "constant", "waypoints"}


def test_fig_2_10_scene_is_one_constant_velocity_disc() -> None:
    sc = load_scenario("thesis-ch2-fig2-10-comparison")
    assert len(sc.obstacles) == 1
    ob = sc.obstacles[0]
    assert ob.body.disc is not None
    assert isinstance(ob.motion, ConstantMotion) and ob.motion.angular_velocity == 0.0
    assert np.hypot(*ob.motion.velocity) == pytest.approx(0.25, abs=1e-6)
    assert (sc.dt, sc.goal_tolerance) == (0.05, 0.05)
    assert "not fitted" in sc.description


def test_fig_2_9_discs_change_direction_and_cross_the_path() -> None:
    sc = load_scenario("thesis-ch2-fig2-9-changing-direction")
    assert len(sc.obstacles) >= 3
    assert all(ob.body.disc is not None for ob in sc.obstacles)
    setup = build_episode(sc, seed=0)
    n_turning = n_crossing = 0
    for ob in setup.obstacles:
        state, t = ob.state, 0.0
        headings, sides = [], []
        for _ in range(int(sc.t_max / sc.dt)):
            state = ob.motion.step(state, t, sc.dt)
            t += sc.dt
            if np.hypot(*state.velocity) > 1e-9:
                headings.append(np.arctan2(state.velocity[1], state.velocity[0]))
            if 0.0 < along(state.position) < 14.0:
                sides.append(np.sign(lateral(state.position)))
        course = np.unwrap(headings)
        n_turning += bool(np.ptp(course) > np.pi / 2)
        n_crossing += bool(len(set(sides) - {0.0}) == 2)
    assert n_turning >= 3  # Savkin-Wang's constant-velocity assumption is broken
    assert n_crossing >= 2  # several cross the robot's straight path
