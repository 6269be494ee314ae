"""The crowd observation of learned laws (goal frame, k nearest, masking) and ``crowd-ppo-v1``."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers.base import ControllerParamsError, make_law
from uvnav.controllers.crowd_features import (
    HUMAN_DIM,
    POS_SCALE,
    action_velocity,
    crowd_features,
    crowd_vector,
    split_vector,
    vector_size,
)
from uvnav.sensors.observation import Observation, ObstacleReading

pytest.importorskip("safetensors")

coord = st.floats(-20.0, 20.0, allow_nan=False)
vel = st.floats(-2.0, 2.0, allow_nan=False)
human = st.tuples(coord, coord, vel, vel, st.floats(0.1, 0.6))


def _disc(i: int, x: float, y: float, vx: float, vy: float, r: float) -> ObstacleReading:
    c = np.array([x, y])
    return ObstacleReading(i, 0.0, c, c, np.array([vx, vy]), 0.0, np.zeros((0, 2)), r, r)


def _obs(
    pose: tuple[float, float, float], goal: tuple[float, float], humans: list[tuple[float, ...]],
    speed: float = 0.5,
) -> Observation:  # fmt: skip
    readings = tuple(_disc(i, *h) for i, h in enumerate(humans))
    return Observation(0.0, np.array(pose), speed, np.array(goal), readings)


def _rotated(angle: float, shift: tuple[float, float], p: tuple[float, float]) -> tuple[float, ...]:
    c, s = math.cos(angle), math.sin(angle)
    return (c * p[0] - s * p[1] + shift[0], s * p[0] + c * p[1] + shift[1])


@settings(max_examples=60, deadline=None)
@given(
    pose=st.tuples(coord, coord, st.floats(-math.pi, math.pi)),
    goal=st.tuples(coord, coord),
    humans=st.lists(human, max_size=8),
    angle=st.floats(-math.pi, math.pi),
    shift=st.tuples(coord, coord),
)
def test_the_features_do_not_change_when_the_whole_scene_turns_and_moves(
    pose: tuple[float, float, float],
    goal: tuple[float, float],
    humans: list[tuple[float, ...]],
    angle: float,
    shift: tuple[float, float],
) -> None:
    """The goal frame: turning and moving the robot, its goal and its humans together gives the
    same numbers (while the goal is not on the robot)."""
    if math.hypot(goal[0] - pose[0], goal[1] - pose[1]) < 1e-3:
        return
    moved = [
        (*_rotated(angle, shift, (h[0], h[1])), *_rotated(angle, (0.0, 0.0), (h[2], h[3])), h[4])
        for h in humans
    ]
    a = crowd_features(_obs(pose, goal, humans), 5, 1.0, 0.3)
    b = crowd_features(
        _obs((*_rotated(angle, shift, pose[:2]), pose[2] + angle),
             _rotated(angle, shift, goal), moved), 5, 1.0, 0.3,  # type: ignore[arg-type]
    )  # fmt: skip
    for x, y in zip(a, b, strict=True):
        np.testing.assert_allclose(x, y, atol=1e-7)


@settings(max_examples=60, deadline=None)
@given(humans=st.lists(human, max_size=9), k=st.integers(1, 7))
def test_the_slots_hold_the_k_nearest_seen_humans_nearest_first_then_empty_ones(
    humans: list[tuple[float, ...]], k: int
) -> None:
    robot, slots, mask = crowd_features(_obs((0.0, 0.0, 0.0), (5.0, 0.0), humans), k, 1.0, 0.3)
    gaps = sorted(math.hypot(h[0], h[1]) - h[4] - 0.3 for h in humans)
    n = min(k, len(humans))
    assert mask.tolist() == [1.0] * n + [0.0] * (k - n)
    np.testing.assert_allclose(slots[:n, 5] * POS_SCALE, np.clip(gaps[:n], -POS_SCALE, 8.0))
    assert not slots[n:].any()
    assert robot[0] == pytest.approx(5.0 / POS_SCALE)


def test_a_human_between_the_robot_and_its_goal_is_straight_ahead() -> None:
    """Goal due north: a human on the way is at x > 0, y = 0 of the frame, walking toward the
    robot (vx < 0); the robot moving north has velocity (speed, 0)."""
    obs = _obs((1.0, 1.0, math.pi / 2), (1.0, 9.0), [(1.0, 3.0, 0.0, -1.0, 0.3)], speed=0.5)
    robot, slots, mask = crowd_features(obs, 2, 1.0, 0.3)
    np.testing.assert_allclose(robot, [2.0, 0.5, 0.0], atol=1e-12)
    np.testing.assert_allclose(slots[0, :5], [2.0 / POS_SCALE, 0.0, -1.0, 0.0, 0.3], atol=1e-12)
    assert mask.tolist() == [1.0, 0.0]


def test_polygons_are_not_humans_and_the_vector_splits_back() -> None:
    square = np.array([[2.0, 2.0], [3.0, 2.0], [3.0, 3.0], [2.0, 3.0]])
    z = np.zeros(2)
    wall = ObstacleReading.known(7, 2.0, square[0], square.mean(0), z, 0.0, square, 0.0, 1.0)
    obs = Observation(0.0, np.zeros(3), 0.0, np.array([4.0, 0.0]), (wall,))
    x = crowd_vector(obs, 3, 1.0, 0.3)
    assert x.shape == (vector_size(3),) and x.dtype == np.float32
    robot, slots, mask = split_vector(x, 3)
    assert slots.shape == (3, HUMAN_DIM) and not mask.any() and robot[0] == 1.0


def test_an_action_is_a_velocity_in_the_goal_frame_within_v_max() -> None:
    obs = _obs((0.0, 0.0, 0.0), (0.0, 3.0), [])
    assert action_velocity(np.array([1.0, 0.0]), obs, 2.0) == pytest.approx((0.0, 2.0))
    vx, vy = action_velocity(np.array([1.0, 1.0]), obs, 2.0)
    assert math.hypot(vx, vy) == pytest.approx(2.0) and vx < 0 < vy  # ahead and to the left
    assert action_velocity(np.array([np.nan, 0.0]), obs, 2.0) == (0.0, 0.0)


@pytest.mark.parametrize("name", ["crowd-ppo-v1", "crowd-ppo-v2"])
def test_the_law_is_deterministic_and_drives_a_crowdnav_episode(name: str) -> None:
    from uvnav.scenarios.build import build_episode
    from uvnav.scenarios.crowdnav import crowdnav_scenario
    from uvnav.sim.run import run_episode
    from uvnav.sim.seeding import run_rng

    def episode() -> tuple[str, float, int]:
        setup = build_episode(crowdnav_scenario(3), 3)
        res = run_episode(setup, make_law(name), run_rng(3), vehicle="holonomic")
        return res.status, float(res.metrics.path_length), int(res.metrics.limit_violations)

    first = episode()
    assert first == episode()
    assert first[0] in ("success", "collision", "timeout") and first[1] > 1.0 and first[2] == 0


def test_the_same_observation_gives_the_same_command_to_any_copy_of_the_law() -> None:
    from uvnav.dynamics.omni import OmniSpec

    obs = _obs((0.0, -4.0, 1.0), (0.0, 4.0), [(0.5, -2.0, 0.0, -1.0, 0.3), (3.0, 0.0, -1, 0, 0.3)])
    cmds = []
    for _ in range(2):
        law = make_law("crowd-ppo-v1")
        law.reset(OmniSpec(1.0, 0.3), np.array([0.0, 4.0]), np.random.default_rng(0))
        cmds.append(law.act(obs))
    assert cmds[0] == cmds[1] and cmds[0].speed <= 1.0 + 1e-12


def test_v2_has_its_own_weights_and_supersedes_v1_in_the_campaigns() -> None:
    """v2 loads its shipped file (another policy than v1's, same shape); v1 stays registered,
    marked as superseded by v2."""
    from uvnav.controllers.base import controller_info

    v1, v2 = make_law("crowd-ppo-v1"), make_law("crowd-ppo-v2")
    assert v2.name == "crowd-ppo-v2" and v2.policy.config == v1.policy.config
    assert v1.policy.weights.keys() == v2.policy.weights.keys()
    assert any(not np.array_equal(v1.policy.weights[n], w) for n, w in v2.policy.weights.items())
    assert controller_info("crowd-ppo-v1").superseded_by == "crowd-ppo-v2"
    assert controller_info("crowd-ppo-v2").superseded_by == ""


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"k": 0}, "k must be a whole number from 1 to 64"),
        ({"weights": "no-such-file.safetensors"}, "weights: no-such-file.safetensors: file not"),
    ],
)
def test_bad_parameters_are_one_line(params: dict[str, object], message: str) -> None:
    with pytest.raises(ControllerParamsError) as info:
        make_law("crowd-ppo-v1", **params)
    assert message in str(info.value) and "\n" not in str(info.value)
