"""uvnav/UUV2D-v0: Gymnasium's env checker, determinism, sonar only, a thesis law as a policy."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import uvnav.envs
from uvnav.controllers.base import make_law
from uvnav.dynamics.holonomic import HolonomicSpec
from uvnav.envs import as_policy
from uvnav.envs.uuv2d import Uuv2DEnv, action_of, command_of
from uvnav.scenarios.uuv2d import load_uuv2d_scenario
from uvnav.sim.run import run_episode

SCENE = "thesis-ch4-fig4-9-whole-run"


def _drive(env: gym.Env, policy, seed: int = 0) -> dict:  # type: ignore[no-untyped-def]
    obs, info = env.reset(seed=seed)
    while True:
        obs, _, term, trunc, info = env.step(policy(obs, info))
        assert env.observation_space.contains(obs)
        if term or trunc:
            return info


def test_check_env_passes() -> None:
    env = Uuv2DEnv(SCENE, render_mode="rgb_array")
    check_env(env, skip_render_check=False)
    frame = env.render()
    assert frame is not None and frame.shape == (256, 256, 3) and frame.dtype == np.uint8
    colours = {tuple(c) for c in frame.reshape(-1, 3)}
    assert (120, 120, 120) in colours and (31, 119, 180) in colours
    env.close()


def test_registered_and_make_vec() -> None:
    assert "uvnav/UUV2D-v0" in uvnav.envs.ENV_IDS and "uvnav/UUV2D-v0" in gym.registry
    vec = gym.make_vec("uvnav/UUV2D-v0", num_envs=2, vectorization_mode="sync")
    obs, _ = vec.reset(seed=1)
    assert obs.shape == (2, 4 + 91)
    obs, rew, term, _, _ = vec.step(vec.action_space.sample())
    assert rew.shape == (2,) and term.dtype == bool
    vec.close()


def test_same_seed_same_episode_with_a_noisy_sonar_and_random_scenes_differ() -> None:
    env = Uuv2DEnv("random-ch4:3")
    # a noisy, dropping sonar: the noise is drawn from the episode's generator
    from uvnav.scenarios.uuv2d import random_ch4_scenario

    noisy = Uuv2DEnv(random_ch4_scenario(3, noise_std=0.05, dropout=0.1))
    runs = []
    for seed in (4, 4, 5):
        first, _ = noisy.reset(seed=seed)
        acts = np.random.default_rng(0).uniform(-1, 1, size=(20, 2))
        runs.append(np.array([first] + [noisy.step(a)[0] for a in acts]))
    np.testing.assert_array_equal(runs[0], runs[1])
    assert not np.array_equal(runs[0], runs[2])  # other noise
    a, _ = env.reset(seed=0)
    per_episode = Uuv2DEnv("random-ch4")
    b, _ = per_episode.reset(seed=0)
    c, _ = per_episode.reset(seed=1)
    assert a.shape == b.shape and not np.array_equal(b, c)


def test_observation_is_the_sonar_sweep() -> None:
    env = Uuv2DEnv(SCENE)
    obs, info = env.reset(seed=0)
    sonar = info["uvnav"].observation.sonar
    np.testing.assert_allclose(obs[4:], np.clip(sonar.ranges / sonar.max_range, 0, 1), rtol=1e-6)
    assert (obs[4:] < 1.0).any() or len(sonar.ids) == 0


def test_actions_map_to_commands_within_the_limits_and_back() -> None:
    spec = HolonomicSpec(1.0, 2.0, 0.2)
    rng = np.random.default_rng(2)
    for _ in range(100):
        heading = float(rng.uniform(-math.pi, math.pi))
        act = rng.uniform(-1, 1, 2)
        cmd = command_of(act, heading, spec.v_max, spec.u_max, 0.2)
        assert not cmd.violates(spec, heading, 0.2)
        back = action_of(cmd, heading, spec.v_max, spec.u_max, 0.2)
        if act[0] > -1 + 1e-6:
            np.testing.assert_allclose(back, act, atol=1e-6)


@pytest.mark.parametrize("scene", [SCENE, "thesis-ch4-fig4-2b-trap"])
def test_zhang2022_as_policy_reaches_the_goal_like_in_the_simulator(scene: str) -> None:
    info = _drive(Uuv2DEnv(scene), as_policy("zhang2022-uuv2d-v1"))
    assert info["status"] == "success" and info["distance"] <= 0.2
    assert info["clearance"] > 0 and not info["entered_forbidden"]
    sim = run_episode(
        load_uuv2d_scenario(scene).to_setup(),
        make_law("zhang2022-uuv2d-v1", vehicle="uuv2d"),
        np.random.default_rng(0),
        record=False,
    )
    # a noiseless, fixed scene: the law takes the same time through either interface
    assert sim.status == "success"
    assert info["time"] == pytest.approx(sim.metrics.time_to_goal, abs=0.2)
