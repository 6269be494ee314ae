"""Instantiating episodes: placement, initial motion, seeding, thesis constraints (2.6)-(2.8)."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from uvnav.controllers import ControllerInfo, make_controller
from uvnav.controllers import base as controllers_base
from uvnav.geometry.polygons import polygon_centroid
from uvnav.obstacles import ObstacleField, RandomTurn, rotation_boundary_growth
from uvnav.scenarios import (
    Scenario,
    ScenarioError,
    build_episode,
    check_constraints,
    scenario_from_dict,
    validate_for_controller,
)
from uvnav.sim import run_episode, world_rng

POLYGON = [[-0.6, -0.4], [0.7, -0.5], [0.2, 0.1], [0.6, 0.6], [-0.5, 0.5]]


def scene(*obstacles: dict[str, Any], **extra: Any) -> Scenario:
    data: dict[str, Any] = {
        "name": "t",
        "dt": 0.1,
        "t_max": 40,
        "robot": {"start": [0, 0], "goal": [10, 10], "v_max": 0.707, "u_max": 1.414},
        "obstacles": list(obstacles),
        "controller": {"name": "straight-v1"},
    }
    data.update(extra)
    return scenario_from_dict(data, "t.yaml")


def wanderer(position: list[float], heading: float = 0.0, **motion: Any) -> dict[str, Any]:
    spec = {"type": "random_turn", "speed": [0.1, 0.3], "turn_rate": [-0.1, 0.1], **motion}
    return {
        "body": {"polygon": POLYGON},
        "start": {"position": position, "heading": heading},
        "motion": spec,
    }


def test_polygon_mass_centre_goes_to_start_position() -> None:
    setup = build_episode(scene(wanderer([5.0, 5.5], heading=0.7)), seed=0)
    ob = setup.obstacles[0]
    np.testing.assert_allclose(ob.state.position, [5.0, 5.5])
    outline = ob.world_outline()
    np.testing.assert_allclose(polygon_centroid(outline), [5.0, 5.5], atol=1e-12)
    # the body frame is the YAML polygon re-centred on its centroid, rotated by the heading
    local = np.asarray(POLYGON) - polygon_centroid(np.asarray(POLYGON))
    c, s = np.cos(0.7), np.sin(0.7)
    expected = local @ np.array([[c, -s], [s, c]]).T + [5.0, 5.5]
    assert {tuple(np.round(p, 9)) for p in outline} == {tuple(np.round(p, 9)) for p in expected}


def test_random_turn_course_starts_along_the_heading() -> None:
    heading = 2.0
    setup = build_episode(
        scene(wanderer([5.0, 2.0], heading=heading, turn_rate=[-0.2, 0.2])), seed=3
    )
    ob = setup.obstacles[0]
    assert isinstance(ob.motion, RandomTurn)
    direction = np.arctan2(ob.state.velocity[1], ob.state.velocity[0])
    assert direction == pytest.approx(heading)
    assert np.hypot(*ob.state.velocity) == pytest.approx(0.2)  # middle of the speed range
    new = ob.motion.step(ob.state, 0.0, setup.dt)
    moved = np.arctan2(*(new.position - ob.state.position)[::-1])
    assert abs(moved - heading) <= 0.2 * setup.dt + 1e-12


def test_robot_and_timing_are_copied() -> None:
    sc = scene(dt=0.05, control_period=0.2, goal_tolerance=0.3, t_max=12)
    setup = build_episode(sc, seed=0)
    np.testing.assert_allclose(setup.start, [0.0, 0.0, np.pi / 4])
    np.testing.assert_allclose(setup.goal, [10.0, 10.0])
    assert (setup.spec.v_max, setup.spec.u_max, setup.spec.radius) == (0.707, 1.414, 0.1)
    assert (setup.dt, setup.control_period, setup.t_max, setup.goal_tolerance) == (
        0.05,
        0.2,
        12,
        0.3,
    )
    assert setup.sensing.sensing_range == 5.0 and setup.sensing.lidar is None


def test_lidar_and_estimated_velocities_reach_the_sensing_config() -> None:
    sensing = {
        "range": 3.0,
        "velocities": "estimated",
        "position_noise": 0.01,
        "lidar": {"n_rays": 36},
    }
    setup = build_episode(scene(sensing=sensing), seed=0)
    assert setup.sensing.velocities == "estimated"
    assert setup.sensing.position_noise == 0.01
    assert setup.sensing.lidar is not None and setup.sensing.lidar.n_rays == 36


def _run(sc: Scenario, seed: int) -> Any:
    return run_episode(
        build_episode(sc, seed), make_controller("straight-v1"), np.random.default_rng(seed)
    )


def test_same_scenario_and_seed_give_identical_trajectories() -> None:
    sc = scene(wanderer([5.0, 5.5]), wanderer([3.0, 6.5], heading=1.0), t_max=15)
    a, b = _run(sc, 7).trajectory, _run(sc, 7).trajectory
    for field in (
        "times",
        "robot",
        "commands",
        "obstacle_centres",
        "obstacle_headings",
        "clearance",
    ):
        assert np.array_equal(getattr(a, field), getattr(b, field)), field


def test_different_seeds_and_obstacles_draw_different_paths() -> None:
    sc = scene(wanderer([5.0, 5.5]), wanderer([5.0, 5.5]), t_max=15)
    a, b = _run(sc, 1).trajectory, _run(sc, 2).trajectory
    n = min(len(a.times), len(b.times))
    assert not np.allclose(a.obstacle_centres[:n], b.obstacle_centres[:n])
    # two identical obstacles in one episode get independent child generators
    assert not np.allclose(a.obstacle_centres[:, 0], a.obstacle_centres[:, 1])


def test_obstacle_streams_are_rng_spawn_children() -> None:
    sc = scene(wanderer([5.0, 5.5]), wanderer([3.0, 6.5]))
    setup = build_episode(sc, seed=11)
    children = world_rng(11).spawn(2)
    for ob, child in zip(setup.obstacles, children, strict=True):
        assert isinstance(ob.motion, RandomTurn)
        assert ob.motion.rng.random() == child.random()


def test_constraints_pass_for_a_slow_gently_turning_obstacle() -> None:
    assert check_constraints(scene(wanderer([5.0, 5.5]))) == []


def test_constraint_violations_name_obstacle_and_equation() -> None:
    fast = {
        "body": {"disc": 0.5},
        "start": {"position": [5, 2]},
        "motion": {"type": "constant", "velocity": [0.8, 0.0]},
    }
    spinning = wanderer([5.0, 8.0], turn_rate=[-1.5, 1.5])
    twitchy = wanderer([2.0, 6.0], speed=[0.1, 0.4], turn_rate=[-0.3, 0.3])  # the DESIGN example
    lines = check_constraints(scene(fast, spinning, twitchy))
    assert any(line.startswith("obstacles.0: (2.6)") for line in lines)
    assert any(line.startswith("obstacles.1: (2.7)") for line in lines)
    assert any(line.startswith("obstacles.2: (2.8)") for line in lines)
    assert not any(line.startswith("obstacles.2: (2.6)") for line in lines)


def test_delta_distance_uses_one_second_of_rotation() -> None:
    ok_rate = 0.1
    growth = rotation_boundary_growth(scene(wanderer([5, 5])).obstacles[0].body.to_body(), ok_rate)
    budget = 0.707 - 0.3
    assert growth < budget  # so the slow wanderer passes ...
    assert check_constraints(scene(wanderer([5.0, 5.5], turn_rate=[-ok_rate, ok_rate]))) == []
    # ... and a disc never violates (2.8), whatever its spin
    disc = {
        "body": {"disc": 0.5},
        "start": {"position": [5, 2]},
        "motion": {"type": "constant", "velocity": [0.3, 0.0], "angular_velocity": 1.0},
    }
    assert check_constraints(scene(disc)) == []


def test_validate_for_controller_rejects_fast_obstacles(monkeypatch: pytest.MonkeyPatch) -> None:
    info = ControllerInfo(
        name="test-needs-slow-v1",
        factory=lambda: None,  # type: ignore[arg-type,return-value]
        params_type=None,
        summary="test",
        requires_slower_obstacles=True,
    )
    monkeypatch.setitem(controllers_base._REGISTRY, info.name, info)
    fast = {
        "body": {"disc": 0.5},
        "start": {"position": [5, 2]},
        "motion": {"type": "constant", "velocity": [0.707, 0.0]},
    }
    sc = scene(wanderer([5.0, 5.5]), fast)
    with pytest.raises(ScenarioError) as err:
        validate_for_controller(sc, info.name)
    assert str(err.value).startswith("t.yaml: obstacles.1.motion: speed bound 0.707 m/s >= V_max")
    validate_for_controller(sc, "straight-v1")  # straight-v1 makes no such assumption
    validate_for_controller(scene(wanderer([5.0, 5.5])), info.name)


def test_obstacles_at_time_zero_match_the_field_used_for_validation() -> None:
    setup = build_episode(scene(wanderer([5.0, 5.5])), seed=0)
    field = ObstacleField.from_obstacles(setup.obstacles)
    _, _, inside = field.nearest(np.array([5.0, 5.5]))
    assert inside[0]
