"""as_policy: a uvnav controller drives the Gymnasium env as it drives the simulator."""

from __future__ import annotations

import numpy as np
import pytest

from uvnav.controllers import make_controller
from uvnav.envs import as_policy
from uvnav.envs.nav2d import Nav2DEnv
from uvnav.scenarios import load_scenario
from uvnav.scenarios.build import build_episode
from uvnav.sim import run_episode


def _drive(env: Nav2DEnv, policy, seed: int = 0) -> dict:
    obs, info = env.reset(seed=seed)
    while True:
        obs, _, term, trunc, info = env.step(policy(obs, info))
        if term or trunc:
            return info


def test_zhang2019_as_policy_reaches_the_goal_like_in_the_simulator() -> None:
    env = Nav2DEnv("thesis-ch2-fig2-10-comparison")
    info = _drive(env, as_policy("zhang2019-v1"))
    assert info["status"] == "success"
    sim = run_episode(
        build_episode(load_scenario("thesis-ch2-fig2-10-comparison"), 0),
        make_controller("zhang2019-v1"),
        np.random.default_rng(0),
        record=False,
    )
    assert sim.status == "success"
    # deterministic scene: the same law takes the same time through either interface
    assert info["time"] == pytest.approx(sim.metrics.time_to_goal, abs=0.25)


def test_policy_resets_between_episodes_and_actions_are_in_the_box() -> None:
    env = Nav2DEnv("open-field")
    pol = as_policy(make_controller("straight-v1"))
    obs, info = env.reset(seed=0)
    a = pol(obs, info)
    assert env.action_space.contains(a)
    first = _drive(env, pol)
    second = _drive(env, pol)
    assert first["status"] == second["status"] == "success"
    assert first["time"] == pytest.approx(second["time"])
