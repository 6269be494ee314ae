"""uvnav/Nav3D-v0: Gymnasium's env checker, determinism, sensing only, a thesis law as a policy."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import uvnav.envs
from uvnav.dynamics.vehicle3d import Vehicle3DCommand
from uvnav.envs import as_policy
from uvnav.envs.nav3d import Nav3DEnv, action_of, body_frame, command_of

SCENE = "thesis-ch3-fig3-6-whole-manoeuvre"


def _drive(env: gym.Env, policy, seed: int = 0) -> tuple[dict, int]:  # type: ignore[no-untyped-def]
    obs, info = env.reset(seed=seed)
    steps = 0
    while True:
        obs, _, term, trunc, info = env.step(policy(obs, info))
        steps += 1
        assert env.observation_space.contains(obs)
        if term or trunc:
            return info, steps


def test_check_env_passes() -> None:
    env = Nav3DEnv(SCENE, render_mode="rgb_array")
    check_env(env, skip_render_check=False)
    frame = env.render()
    assert frame is not None and frame.shape == (256, 512, 3) and frame.dtype == np.uint8
    assert (120, 120, 120) in {tuple(c) for c in frame.reshape(-1, 3)}  # the obstacle is drawn
    env.close()


def test_registered_and_make_vec() -> None:
    assert "uvnav/Nav3D-v0" in uvnav.envs.ENV_IDS and "uvnav/Nav3D-v0" in gym.registry
    vec = gym.make_vec("uvnav/Nav3D-v0", num_envs=2, vectorization_mode="sync")
    obs, _ = vec.reset(seed=1)
    assert obs.shape == (2, 5 + 8 * 4)
    obs, rew, term, _, _ = vec.step(vec.action_space.sample())
    assert rew.shape == (2,) and term.dtype == bool
    vec.close()


def test_same_seed_same_episode_and_random_scenes_differ() -> None:
    env = Nav3DEnv("random-ch3")
    runs = []
    for seed in (4, 4, 5):
        first, _ = env.reset(seed=seed)
        acts = np.random.default_rng(0).uniform(-1, 1, size=(30, 3))
        runs.append(np.array([first] + [env.step(a)[0] for a in acts]))
    np.testing.assert_array_equal(runs[0], runs[1])
    assert not np.array_equal(runs[0][0], runs[2][0])  # another seed: another random scene


def _until_sensed(env: Nav3DEnv) -> list[tuple[np.ndarray, dict]]:
    """Fly toward the goal until the sensor reports an obstacle for two decisions."""
    obs, info = env.reset(seed=0)
    seen = []
    pol = as_policy(_Straight())
    while len(seen) < 2:
        obs, _, term, trunc, info = env.step(pol(obs, info))
        assert not (term or trunc)
        if info["uvnav"].observation.obstacles:
            seen.append((obs, info))
    return seen


def test_observation_is_the_sensor_reading_and_rates_are_estimated_unless_oracle() -> None:
    env = Nav3DEnv(SCENE)
    _, info = env.reset(seed=0)
    assert info["uvnav"].observation.obstacles == ()  # out of sensing range at the start
    (_, info1), (obs2, info2) = _until_sensed(env)
    rd1 = info1["uvnav"].observation.obstacles[0]
    rd2 = info2["uvnav"].observation.obstacles[0]
    assert rd1.velocity_source == rd2.velocity_source == "estimated"
    # first sighting: nothing to difference yet; then a finite difference of the sensed centre
    assert np.all(rd1.velocity == 0) and np.linalg.norm(rd2.velocity) > 0
    np.testing.assert_allclose(rd2.velocity, (rd2.centre - rd1.centre) / 0.1, rtol=1e-9)
    assert obs2[5] == 1.0 and obs2[6] == pytest.approx(rd2.distance / 8.0, rel=1e-6)
    assert np.all(obs2[5 + 8 :] == 0.0)  # one obstacle: the other slots are empty
    oracle = Nav3DEnv(SCENE, oracle=True)
    (_, info1), _ = _until_sensed(oracle)
    rd = info1["uvnav"].observation.obstacles[0]
    assert rd.velocity_source == "known" and np.linalg.norm(rd.velocity) > 0


def test_actions_map_to_commands_within_the_limits_and_back() -> None:
    rng = np.random.default_rng(1)
    for _ in range(50):
        a_r = rng.normal(size=3)
        a_r /= np.linalg.norm(a_r)
        act = rng.uniform(-1, 1, 3)
        cmd = command_of(act, a_r, 1.5, 0.8)
        assert not cmd.violates(_spec(), a_r)
        back = action_of(cmd, a_r, 1.5, 0.8)
        w = act[1:] / max(1.0, float(np.hypot(*act[1:])))
        np.testing.assert_allclose(back, [act[0], *w], atol=1e-6)
    frame = body_frame(np.array([0.0, 0.0, 1.0]))  # vertical heading: still orthonormal
    np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-12)


def _spec():  # type: ignore[no-untyped-def]
    from uvnav.dynamics.vehicle3d import Vehicle3DSpec

    return Vehicle3DSpec(1.5, 0.8, 0.1)


def test_zhang2020_as_policy_reaches_the_goal_on_the_thesis_scene() -> None:
    env = Nav3DEnv(SCENE)
    info, _ = _drive(env, as_policy("zhang2020-3d-v1"))
    assert info["status"] == "success" and info["distance"] <= 0.3
    assert info["clearance"] > 0


def test_flying_straight_into_the_obstacle_is_a_penalised_collision() -> None:
    env = Nav3DEnv(SCENE, reward={"collision": 7.0})
    pol = as_policy(_Straight())
    obs, info = env.reset(seed=0)
    term = trunc = False
    while not (term or trunc):
        obs, r, term, trunc, info = env.step(pol(obs, info))
    # the Fig. 3.6 body crosses the straight line S-E: ignoring it ends in a collision
    assert term and info["status"] == "collision" and info["clearance"] < 0
    assert r < -6.0  # the configured collision penalty dominates the last reward


class _Straight:
    """Flies straight at V_max (ignores obstacles)."""

    name = "straight-test"
    oracle = False
    mode = "M1"

    def reset(self, spec, goal, rng) -> None:  # type: ignore[no-untyped-def]
        self.v = spec.v_max

    def act(self, obs) -> Vehicle3DCommand:  # type: ignore[no-untyped-def]
        return Vehicle3DCommand(self.v, np.zeros(3))
