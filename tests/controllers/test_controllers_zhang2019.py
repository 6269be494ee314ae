"""Behaviour and geometry of the thesis's Chapter 2 law (``zhang2019-v1``)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from uvnav.controllers import ControllerParamsError, make_controller
from uvnav.controllers.zhang2019 import Zhang2019Controller, group_around
from uvnav.dynamics import UnicycleSpec
from uvnav.obstacles import (
    ConstantVelocity,
    Obstacle,
    ObstacleField,
    ObstacleState,
    PolygonBody,
)
from uvnav.scenarios import build_episode, list_builtin, load_scenario
from uvnav.sensors import Observation, sense_obstacles
from uvnav.sim import EpisodeSetup, run_episode, run_rng

SPEC = UnicycleSpec(v_max=0.707, u_max=1.414, radius=0.1)
GOAL = np.array([10.0, 0.0])
THESIS_SCENES = [name for name in list_builtin() if name.startswith("thesis-ch2-")]


def observe(pose: list[float], obstacles: list[Obstacle], *, time: float = 0.0) -> Observation:
    fld = ObstacleField.from_obstacles(obstacles)
    p = np.asarray(pose, dtype=float)
    return Observation(
        time=time, pose=p, speed=SPEC.v_max, goal=GOAL, obstacles=sense_obstacles(p[:2], fld)
    )


def disc(x: float, y: float, r: float = 0.5, v: tuple[float, float] = (0.0, 0.0)) -> Obstacle:
    return Obstacle.moving_disc((x, y), r, v)


def fresh() -> Zhang2019Controller:
    ctrl = make_controller("zhang2019-v1")
    assert isinstance(ctrl, Zhang2019Controller)
    ctrl.reset(SPEC, GOAL, np.random.default_rng(0))
    return ctrl


@pytest.mark.parametrize("scene", THESIS_SCENES)
def test_reaches_target_without_collision_on_every_thesis_scene(scene: str) -> None:
    setup = build_episode(load_scenario(scene), 0)
    result = run_episode(setup, make_controller("zhang2019-v1"), run_rng(0), record=False)
    assert result.status == "success"
    assert result.metrics.min_clearance > 0.05  # never closer than 5 cm to any obstacle
    assert result.metrics.limit_violations == 0


def test_fig_2_10_path_no_longer_than_savkin_wang() -> None:
    """Thesis Fig. 2.10: on the constant-velocity disc scene the thesis's law is not longer."""
    scenario = load_scenario("thesis-ch2-fig2-10-comparison")
    lengths = {}
    for name in ("zhang2019-v1", "savkin-wang2013-v1"):
        res = run_episode(
            build_episode(scenario, 0), make_controller(name), run_rng(0), record=False
        )
        assert res.status == "success"
        lengths[name] = res.metrics.path_length
    assert lengths["zhang2019-v1"] <= lengths["savkin-wang2013-v1"]
    assert lengths["zhang2019-v1"] >= math.hypot(10, 10) - 0.1  # no shorter than the straight line


def test_direction_tag_follows_the_side_of_the_mass_centre() -> None:
    ctrl = fresh()
    pos = np.zeros(2)
    assert ctrl.direction_tag(pos, np.array([3.0, 0.4])) == 1  # left of L_T: circle it CCW
    assert ctrl.direction_tag(pos, np.array([3.0, -0.4])) == -1


@pytest.mark.parametrize("tag", [1, -1])
def test_steering_passes_outside_a_static_disc_on_the_tagged_side(tag: int) -> None:
    ctrl = fresh()
    centre = np.array([1.2, 0.0])
    obs = observe([0.0, 0.0, 0.0], [disc(*centre, r=0.5)])
    group = group_around(obs.obstacles[0], obs.obstacles, 0.5, 1.0)
    ctrl._tag = tag
    angle = ctrl.steering_angle(obs, group)
    # '+' passes clockwise of the obstacle as seen from the robot, '-' counter-clockwise
    assert np.sign(angle) == -tag
    # the steering ray clears the disc by at least the robot radius plus the margin
    direction = np.array([math.cos(angle), math.sin(angle)])
    along = float(direction @ centre)
    lateral = abs(float(direction[0] * centre[1] - direction[1] * centre[0]))
    assert along > 0 and lateral >= 0.5 + SPEC.radius + ctrl.params.safety_margin - 1e-9
    # r*_min is on the boundary, rotated from r_min toward the passing side
    r_star = ctrl.forecast_centre(obs.position, group, tag)
    assert abs(math.hypot(*(r_star - centre)) - 0.5) < 1e-9
    assert np.sign(math.atan2(r_star[1], r_star[0])) == -tag


def test_follows_a_long_static_wall_without_touching_it() -> None:
    wall = PolygonBody.from_vertices(
        np.array(
            [[0.0, 0.0], [6.0, 0.0], [6.0, 0.4], [3.2, 0.4], [3.0, 1.5], [2.8, 0.4], [0.0, 0.4]]
        )
    )
    ob = Obstacle(
        wall, ObstacleState(np.array([5.0, 0.3]) + wall.offset * 0), ConstantVelocity(np.zeros(2))
    )
    ob.state = ObstacleState(np.array([5.0, 0.0]))
    setup = EpisodeSetup(
        spec=SPEC, start=np.array([0.0, 0.5, 0.0]), goal=GOAL, obstacles=[ob], t_max=90.0
    )
    res = run_episode(setup, make_controller("zhang2019-v1"), run_rng(1), record=False)
    assert res.status == "success"
    assert res.metrics.min_clearance > 0.0


def test_static_obstacle_head_on_is_avoided() -> None:
    setup = EpisodeSetup(
        spec=SPEC, start=np.array([0.0, 0.0, 0.0]), goal=GOAL, obstacles=[disc(5.0, 0.0, r=0.8)]
    )
    res = run_episode(setup, make_controller("zhang2019-v1"), run_rng(2))
    assert res.status == "success"
    assert res.metrics.min_clearance > 0.1
    assert res.metrics.mode_switches >= 2  # M1 -> M2 -> M1
    assert res.trajectory is not None and "M2" in res.trajectory.modes


def test_literal_speed_law_is_selectable_and_slower_near_obstacles() -> None:
    fast = fresh()
    slow = make_controller("zhang2019-v1", speed_law="tangent", turn_slowdown=False)
    slow.reset(SPEC, GOAL, np.random.default_rng(0))
    obs = observe([0.0, 0.0, 0.0], [disc(0.9, 0.3, r=0.4)])
    cmd_fast, cmd_slow = fast.act(obs), slow.act(obs)
    assert slow.mode == fast.mode == "M2"
    d_min = obs.obstacles[0].distance
    assert cmd_slow.v == pytest.approx(
        max(d_min, slow.params.min_speed)
    )  # ||l_J|| = d_min for v_i = 0
    assert cmd_slow.v < cmd_fast.v or cmd_fast.v < SPEC.v_max


@pytest.mark.parametrize(
    ("bad", "message"),
    [
        ({"alpha0": 2.0}, "alpha0"),
        ({"switch_distance": -1.0}, "switch_distance"),
        ({"speed_law": "warp"}, "speed_law"),
        ({"nope": 1}, "unknown"),
    ],
)
def test_bad_parameters_are_rejected_with_the_field_name(
    bad: dict[str, object], message: str
) -> None:
    with pytest.raises(ControllerParamsError, match=message):
        make_controller("zhang2019-v1", **bad)


def test_coincident_polygon_points_do_not_break_the_law() -> None:
    square = PolygonBody.from_vertices(
        np.array([[0, 0], [1, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    )
    ob = Obstacle(square, ObstacleState(np.array([1.0, 0.0])), ConstantVelocity(np.zeros(2)))
    ctrl = fresh()
    cmd = ctrl.act(observe([0.0, 0.0, 0.0], [ob]))
    assert math.isfinite(cmd.v) and math.isfinite(cmd.u)


def _pairwise_group(first: object, readings: tuple, gap: float, horizon: float) -> list[int]:
    """The single-linkage group by the plain pairwise scan (the definition), as obstacle ids."""
    from uvnav.controllers.zhang2019 import body_gap

    pool = [rd for rd in readings if rd.obstacle_id != first.obstacle_id]  # type: ignore[attr-defined]
    members, frontier = [first], [first]
    while frontier and pool:
        cur = frontier.pop()
        linked = [
            rd for rd in pool
            if body_gap(cur, rd) < gap + (cur.speed + rd.speed) * horizon  # type: ignore[attr-defined]
        ]  # fmt: skip
        pool = [rd for rd in pool if rd not in linked]
        members += linked
        frontier += linked
    members.sort(key=lambda m: m.distance)  # type: ignore[attr-defined]
    return [m.obstacle_id for m in members]  # type: ignore[attr-defined]


@pytest.mark.parametrize("seed", range(6))
def test_the_grouping_is_the_pairwise_single_linkage_in_the_same_order(seed: int) -> None:
    """Crowds of moving discs and squares: the array-pruned grouping gives the members, and
    their order, of the plain pairwise scan."""
    rng = np.random.default_rng(seed)
    bodies: list[Obstacle] = []
    for _ in range(60):
        x, y = rng.uniform(-6, 6, 2)
        v = tuple(rng.uniform(-0.5, 0.5, 2))
        if rng.random() < 0.7:
            bodies.append(disc(float(x), float(y), float(rng.uniform(0.1, 0.4)), v))  # type: ignore[arg-type]
        else:
            square = np.array([[-0.3, -0.3], [0.3, -0.3], [0.3, 0.3], [-0.3, 0.3]])
            bodies.append(
                Obstacle(
                    PolygonBody(square),
                    ObstacleState(np.array([x, y]), velocity=np.array(v)),
                    ConstantVelocity(np.array(v)),
                )
            )
    obs = observe([0.0, 0.0, 0.0], bodies)
    sizes = []
    for first in obs.obstacles[:5]:
        got = group_around(first, obs.obstacles, 0.4, 1.0)
        assert [m.obstacle_id for m in got.members] == _pairwise_group(
            first, obs.obstacles, 0.4, 1.0
        )
        sizes.append(len(got.members))
    assert max(sizes) >= 5  # groups of several bodies, not singletons only


@pytest.mark.parametrize("heading", [0.0, 1e-12, -4e-10, 6e-10, 1e-9, 2e-9, 0.3, -2.0, math.pi])
@pytest.mark.parametrize("x", [0.0, 9.9, 9.999])
def test_m1_command_is_the_law_with_the_distance_to_the_target(heading: float, x: float) -> None:
    """M1 skips the distance to T when T is straight ahead; the command is the one computed
    with it (approach_speed and the heading law of note 10), bit for bit."""
    from uvnav.controllers.base import approach_speed, heading_rate_toward
    from uvnav.geometry.angles import wrap_scalar

    ctrl = fresh()
    obs = observe([x, 0.0, heading], [])
    gx, gy = float(GOAL[0]) - x, float(GOAL[1])
    beta = wrap_scalar(float(np.arctan2(gy, gx)) - heading)
    v = approach_speed(SPEC.v_max, SPEC.u_max, float(np.hypot(gx, gy)), beta)
    cmd = ctrl.approach_command(obs, 0.1)
    assert (cmd.v, cmd.u) == (v, heading_rate_toward(beta, SPEC.u_max, 0.1))
    assert type(cmd.v) is float and type(cmd.u) is float
