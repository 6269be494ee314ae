"""``zhang2019-v2`` on a unicycle with acceleration limits: every command within the window the
vehicle can reach in one period, the turn rate it tracks equal to the vehicle's, the paths it
checks equal to the vehicle's motion, and scenes where the law planning as if the vehicle were
ideal collides or orbits the goal while the planning law arrives."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import replace
from typing import Any

import numpy as np
import pytest

from uvnav.controllers.base import controller_info
from uvnav.controllers.zhang2019_limits import RampModel, rollout, turn_command
from uvnav.controllers.zhang2019_v2 import Zhang2019V2, Zhang2019V2Params
from uvnav.core import BaseProbe
from uvnav.dynamics.unicycle import Unicycle, UnicycleCommand, UnicycleSpec
from uvnav.scenarios import scenario_from_dict
from uvnav.scenarios.build import build_episode
from uvnav.scenarios.catalog import kinds
from uvnav.scenarios.crowdnav import crowdnav_scenario
from uvnav.sim.run import run_episode

ACCEL, TURN_ACCEL, DT, PERIOD = 1.0, 2.0, 0.05, 0.25


class IdealPlanning(Zhang2019V2):
    """v2 told that its vehicle is ideal (the law before it planned with the limits), steering
    for the goal itself (the ideal unicycle's route off)."""

    def __init__(self) -> None:
        super().__init__(Zhang2019V2Params(route_weight=0.0))

    def reset(self, spec: UnicycleSpec, goal: np.ndarray, rng: np.random.Generator) -> None:
        ideal = dataclasses.replace(spec, accel_max=math.inf, turn_accel_max=math.inf)
        super().reset(ideal, goal, rng)


class Window(BaseProbe):
    """Records, at every decision, the vehicle's speed and turn rate and the command held."""

    def __init__(self) -> None:
        self.rows: list[tuple[float, float, float, float, float, float]] = []

    def on_decision(self, world: Any, agent: int, law: Any, obs: Any, applied: Any) -> None:
        body = world.body
        self.rows.append((obs.time, obs.speed, body.speed(), body.turn_rate(), applied.v,
                          applied.u))  # fmt: skip


def run(case: int, law: Zhang2019V2, n_humans: int = 5, probe: Window | None = None) -> Any:
    scn = crowdnav_scenario(case, dt=DT, accel_max=ACCEL, turn_accel_max=TURN_ACCEL,
                            n_humans=n_humans)  # fmt: skip
    probes = [probe] if probe else []
    rng = kinds()["nav2d"].episode_rng(case)
    return run_episode(build_episode(scn, case), law, rng, record=False, vehicle="unicycle",
                       probes=probes)  # fmt: skip


@pytest.mark.parametrize("case", [0, 7, 12])
def test_every_command_is_reachable_within_one_period(case: int) -> None:
    probe = Window()
    law = Zhang2019V2()
    run(case, law, probe=probe)
    rows = np.array(probe.rows)
    assert len(rows) > 10
    t, obs_v, v, u, cmd_v, cmd_u = rows.T
    assert np.allclose(obs_v, v)  # the odometry the law reads is the vehicle's speed
    _, u_cmd = law._turn  # the law's own record of the last command
    assert u_cmd == pytest.approx(cmd_u[-1])
    periods = np.diff(t)
    assert np.allclose(periods, PERIOD)
    tol = 1e-9
    assert np.all(np.abs(cmd_v - v) <= ACCEL * PERIOD + tol)
    assert np.all(np.abs(cmd_u - u) <= TURN_ACCEL * PERIOD + tol)
    # the vehicle reached every command within its period: the next decision finds it there
    assert np.allclose(v[1:], cmd_v[:-1], atol=1e-9)
    assert np.allclose(u[1:], cmd_u[:-1], atol=1e-9)


def test_the_ideal_planning_law_issues_commands_out_of_reach() -> None:
    probe = Window()
    run(7, IdealPlanning(), probe=probe)
    _, _, v, u, cmd_v, cmd_u = np.array(probe.rows).T
    assert np.any(np.abs(cmd_v - v) > ACCEL * PERIOD + 1e-6)
    assert np.any(np.abs(cmd_u - u) > TURN_ACCEL * PERIOD + 1e-6)


def test_planning_with_the_limits_avoids_the_collision_the_ideal_plan_drives_into() -> None:
    before = run(12, IdealPlanning(), n_humans=2)
    assert before.status == "collision" and before.metrics.collision_by == "robot"
    after = run(12, Zhang2019V2(), n_humans=2)
    assert after.status == "success"


def behind(kinematics: str) -> Any:
    """An empty scene whose goal lies behind the robot (3 m back, 0.5 m aside), 12 s."""
    robot = {"start": [0, 0], "heading": 0.0, "goal": [-3.0, 0.5], "v_max": 1.0,
             "u_max": math.pi, "radius": 0.3, "kinematics": kinematics, "accel_max": ACCEL,
             "turn_accel_max": TURN_ACCEL}  # fmt: skip
    return scenario_from_dict({"name": "behind", "dt": DT, "control_period": PERIOD, "t_max": 12,
                               "robot": robot, "obstacles": [],
                               "controller": {"name": "zhang2019-v2"}}, "behind.yaml")  # fmt: skip


@pytest.mark.parametrize("kinematics", ["turn-then-move", "arc"])
def test_the_goal_is_reached_not_orbited(kinematics: str) -> None:
    """The ideal plan turns at rates the vehicle cannot brake in time, overshoots its heading
    onto the goal and circles it (turn-then-move) or arrives late; the planning law turns onto
    it and arrives within 5.5 s."""

    def go(law: Zhang2019V2) -> Any:
        return run_episode(build_episode(behind(kinematics), 0), law, np.random.default_rng(0),
                           record=False, vehicle="unicycle")  # fmt: skip

    ideal, planned = go(IdealPlanning()), go(Zhang2019V2())
    assert planned.status == "success" and planned.metrics.time_to_goal < 5.5
    assert ideal.status == "timeout" or ideal.metrics.time_to_goal > 8.0


def test_the_checked_path_is_the_path_the_vehicle_drives() -> None:
    spec = UnicycleSpec(1.0, math.pi, 0.3, kinematics="arc", accel_max=ACCEL,
                        turn_accel_max=TURN_ACCEL)  # fmt: skip
    model = RampModel(1.0, math.pi, ACCEL, TURN_ACCEL, PERIOD)
    aim, speed = np.array([1.2]), np.array([0.8])
    times, xy, speeds = rollout(np.zeros(3), 0.3, 0.0, aim, speed, model, 3.0, DT)
    car = Unicycle(spec)
    car._v = 0.3  # the state the rollout starts from
    x, y, th, u_now = 0.0, 0.0, 0.0, 0.0
    for i in range(len(times) - 1):
        if i % round(PERIOD / DT) == 0:  # the law's steering, as the rollout plays it
            beta = math.remainder(1.2 - th, 2.0 * math.pi)
            v_cmd = min(max(0.8 * max(math.cos(beta), 0.0), car.speed() - ACCEL * PERIOD),
                        car.speed() + ACCEL * PERIOD)  # fmt: skip
            u_cmd = float(turn_command(np.array([beta]), np.array([u_now]), model)[0])
            car.hold(UnicycleCommand(v_cmd, u_cmd))
        x, y, th, _, _ = car.move(x, y, th, DT, False, PERIOD)
        u_now = car.turn_rate()
    # the rollout integrates each substep at its mean speed and turn rate, the vehicle at the
    # values it reached: a few centimetres apart after 3 s
    assert math.hypot(xy[0, -1, 0] - x, xy[0, -1, 1] - y) < 0.05
    assert speeds[0, -1] == pytest.approx(car.speed())


def test_the_checked_path_of_a_turn_then_move_vehicle_is_the_path_it_drives() -> None:
    """With ``turn_first`` the rollout turns at each decision and moves straight, as the
    turn-then-move vehicle does: the same positions, integrated at the same step."""
    spec = UnicycleSpec(1.0, math.pi, 0.3, kinematics="turn-then-move", accel_max=ACCEL,
                        turn_accel_max=TURN_ACCEL)  # fmt: skip
    model = RampModel(1.0, math.pi, ACCEL, TURN_ACCEL, PERIOD, turn_first=True)
    times, xy, _ = rollout(np.zeros(3), 0.3, 0.4, np.array([-1.5]), np.array([0.8]), model,
                           3.0, DT)  # fmt: skip
    car = Unicycle(spec)
    car._v, car._u = 0.3, 0.4  # the state the rollout starts from
    x, y, th = 0.0, 0.0, 0.0
    for i in range(len(times) - 1):
        decision = i % round(PERIOD / DT) == 0
        if decision:  # the law's steering, as the rollout plays it
            beta = math.remainder(-1.5 - th, 2.0 * math.pi)
            v_cmd = min(max(0.8 * max(math.cos(beta), 0.0), car.speed() - ACCEL * PERIOD),
                        car.speed() + ACCEL * PERIOD)  # fmt: skip
            u_cmd = float(turn_command(np.array([beta]), np.array([car.turn_rate()]), model)[0])
            car.hold(UnicycleCommand(v_cmd, u_cmd))
        x, y, th, _, _ = car.move(x, y, th, DT, decision, PERIOD)
        # the rollout moves at each substep's mean speed, the vehicle at the speed it reached
        gap = math.hypot(xy[0, i + 1, 0] - x, xy[0, i + 1, 1] - y)
        assert gap < 0.5 * ACCEL * DT * DT * (i + 1)
    arc = rollout(np.zeros(3), 0.3, 0.4, np.array([-1.5]), np.array([0.8]),
                  replace(model, turn_first=False), 3.0, DT)[1]  # fmt: skip
    assert math.hypot(*(arc[0, -1] - xy[0, -1])) > 0.02  # what the arcs got wrong


def test_turn_command_brakes_the_turn_before_the_heading_is_reached() -> None:
    model = RampModel(1.0, math.pi, ACCEL, TURN_ACCEL, PERIOD)
    u = turn_command(np.array([0.3, 0.3]), np.array([1.5, 0.0]), model)
    # turning at 1.5 rad/s with 0.3 rad to go: slow down (by the window's most, 0.5 rad/s)
    assert u[0] == pytest.approx(1.0)
    # from rest: no faster than a turn that can still be stopped within 0.3 rad
    assert 0.0 < u[1] <= math.sqrt(2.0 * TURN_ACCEL * 0.3)


def test_the_law_declares_that_it_plans_with_the_limits() -> None:
    assert controller_info("zhang2019-v2").acceleration_limits
    assert not controller_info("zhang2019-holonomic-v2").acceleration_limits


def test_the_spread_look_ahead_keeps_clear_of_a_human_who_turns_into_the_robot() -> None:
    # 20 humans, the local law alone (no grid route): checked against constant velocities
    # alone, the robot is walked into by a human whose path others bend; with each reach
    # growing 0.1 m/s of look-ahead it arrives
    alone = Zhang2019V2Params(route_grid_weight=0.0, route_weight=0.0)
    still = run(3, Zhang2019V2(replace(alone, limited_spread=0.0)), n_humans=20)
    assert still.status == "collision" and still.metrics.collision_by == "pedestrian"
    assert run(3, Zhang2019V2(alone), n_humans=20).status == "success"


def ideal_path(case: int, params: Zhang2019V2Params, n_humans: int = 5) -> np.ndarray:
    """The robot's path on CrowdNav's circle ``case``, the ideal unicycle driven by v2."""
    scn = crowdnav_scenario(case, dt=DT, n_humans=n_humans)
    res = run_episode(build_episode(scn, case), Zhang2019V2(params),
                      kinds()["nav2d"].episode_rng(case), vehicle="unicycle")  # fmt: skip
    assert res.trajectory is not None
    return np.asarray(res.trajectory.robot)


def test_the_ideal_vehicle_checked_in_a_straight_line_does_not_read_the_spread() -> None:
    a, b = (ideal_path(7, Zhang2019V2Params(limited_spread=s, rollout_paths=False))
            for s in (0.0, 0.5))  # fmt: skip
    assert np.array_equal(a, b)


def test_a_capped_spread_lets_the_robot_reach_a_goal_beside_standing_people() -> None:
    # 20 humans, CrowdNav's case 9: the humans stand at their goals round the ring, two of them
    # beside the robot's goal; with every body's reach growing 0.1 m/s of look-ahead the paths
    # toward the goal touch them within min_ttc, and the robot creeps in and runs out of time;
    # standing bodies grown by at most 0.05 m and the paths checked until the goal (the
    # defaults on a vehicle with acceleration limits), it arrives
    uncapped = Zhang2019V2Params(still_cap=0.0, goal_horizon=0.0)
    assert run(9, Zhang2019V2(uncapped), n_humans=20).status == "timeout"
    assert run(9, Zhang2019V2(), n_humans=20).status == "success"


def test_the_ideal_unicycle_does_not_read_the_cap_or_the_goal_horizon() -> None:
    # 20 humans, case 7: read on the ideal unicycle, the cap and the goal horizon change its
    # path; it checks its rolled-out paths as before
    a, b = (ideal_path(7, Zhang2019V2Params(still_cap=cap, goal_horizon=horizon), n_humans=20)
            for cap, horizon in ((0.0, 0.0), (0.05, 1.0)))  # fmt: skip
    assert np.array_equal(a, b)


def test_the_cap_and_the_goal_horizon_default_to_the_tuned_values_and_are_not_negative() -> None:
    p = Zhang2019V2Params()
    assert p.still_cap == 0.05 and p.goal_horizon == 1.0
    for name in ("still_cap", "goal_horizon"):
        with pytest.raises(ValueError, match=name):
            replace(p, **{name: -0.1})
