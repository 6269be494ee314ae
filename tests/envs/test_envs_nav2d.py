"""uvnav/Nav2D-v0: Gymnasium's env checker, vector envs, rewards, frames, determinism."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import uvnav.envs
from uvnav.envs.core import RewardConfig
from uvnav.envs.nav2d import Nav2DEnv


def test_check_env_passes() -> None:
    env = Nav2DEnv("thesis-ch2-one-obstacle", render_mode="rgb_array")
    check_env(env, skip_render_check=False)
    env.close()


def test_registered_and_make_vec() -> None:
    assert "uvnav/Nav2D-v0" in uvnav.envs.ENV_IDS and "uvnav/Nav2D-v0" in gym.registry
    env = gym.make("uvnav.envs:uvnav/Nav2D-v0", scenario="office-floor")
    obs, _ = env.reset(seed=0)
    assert env.observation_space.contains(obs)
    vec = gym.make_vec("uvnav/Nav2D-v0", num_envs=3, vectorization_mode="sync")
    obs, _ = vec.reset(seed=5)
    assert obs.shape == (3, 36)
    obs, rew, term, _trunc, _ = vec.step(vec.action_space.sample())
    assert obs.shape == (3, 36) and rew.shape == (3,) and term.dtype == bool
    vec.close()


def test_same_seed_same_episode_and_random_obstacles_differ() -> None:
    env = Nav2DEnv("random-ch2:1")
    a, _ = env.reset(seed=3)
    steps_a = [env.step(np.array([0.5, 0.1]))[0] for _ in range(20)]
    b, _ = env.reset(seed=3)
    steps_b = [env.step(np.array([0.5, 0.1]))[0] for _ in range(20)]
    np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(np.array(steps_a), np.array(steps_b))


def test_full_speed_ahead_collides_with_the_obstacle_and_is_penalised() -> None:
    env = Nav2DEnv("thesis-ch2-fig2-10-comparison", reward={"collision": 7.0})
    obs, info = env.reset(seed=0)
    # drive straight at the goal without avoiding anything
    total, term, trunc = 0.0, False, False
    while not (term or trunc):
        bearing = np.arctan2(obs[2], obs[1])
        obs, r, term, trunc, info = env.step(np.array([1.0, np.clip(bearing, -1, 1)]))
        total += r
    # the Fig. 2.10 disc crosses the straight line: ignoring it ends in a collision
    assert info["status"] == "collision" and term
    assert r < -6.0  # the configured collision penalty dominates the last reward


def test_progress_reward_and_lidar_see_the_wall() -> None:
    env = Nav2DEnv("corridor", reward=RewardConfig(time=0.0, clearance=0.0))
    obs, info = env.reset(seed=0)
    d0 = info["distance"]
    obs, r, *_, info = env.step(np.array([1.0, 0.0]))  # full speed along the corridor
    assert r == pytest.approx(d0 - info["distance"], abs=1e-9) and r > 0.05
    # the corridor walls are 2 m to each side: the side beams read about 1.8-2 m / 5 m
    lidar = obs[4:]
    assert lidar.min() < 0.45 and lidar.max() == pytest.approx(1.0)
    assert info["uvnav"].observation.obstacles  # the walls are in sensing range


def test_render_draws_robot_and_obstacles() -> None:
    env = Nav2DEnv("office-floor", render_mode="rgb_array")
    env.reset(seed=0)
    frame = env.render()
    assert frame is not None and frame.shape == (256, 256, 3) and frame.dtype == np.uint8
    colours = {tuple(c) for c in frame.reshape(-1, 3)}
    assert (120, 120, 120) in colours and (31, 119, 180) in colours
    assert Nav2DEnv("office-floor").render() is None
    with pytest.raises(ValueError, match="render_mode"):
        Nav2DEnv(render_mode="human")


def test_gymnasium_entry_point_resolves_to_the_registration() -> None:
    from importlib.metadata import entry_points

    (ep,) = [e for e in entry_points(group="gymnasium.envs") if e.name == "uvnav"]
    assert ep.load() is uvnav.envs.register_envs
    uvnav.envs.register_envs()  # idempotent
    assert gym.spec("uvnav/Nav2D-v0").entry_point == "uvnav.envs.nav2d:Nav2DEnv"


def test_one_reward_formula_for_every_env() -> None:
    """``RewardConfig.reward`` (used by Nav2D, Nav3D, UUV2D and the multi-robot env)."""
    from uvnav.envs.core import RewardConfig

    rw = RewardConfig(progress=2.0, time=0.1, clearance=1.0, clearance_margin=0.5)
    assert rw.reward(0.3, 1.0, "running") == pytest.approx(2.0 * 0.3 - 0.1)
    assert rw.reward(0.0, 0.2, "running") == pytest.approx(-0.1 - 0.3)  # 0.3 m inside the margin
    assert rw.reward(0.0, 1.0, "success") == pytest.approx(-0.1 + rw.success)
    assert rw.reward(0.0, 1.0, "collision") == pytest.approx(-0.1 - rw.collision)
    assert rw.reward(0.0, 1.0, "timeout") == pytest.approx(-0.1)
