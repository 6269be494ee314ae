"""The batched Nav2D env (uvnav.envs.nav2d_vec): equal to a SyncVectorEnv of Nav2DEnv."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import uvnav.envs
from uvnav.envs.nav2d import Nav2DEnv
from uvnav.envs.nav2d_vec import Nav2DVectorEnv
from uvnav.geometry.kernels3d import compiled, numba_available

gym.register_envs(uvnav.envs)


def assert_same_run(scene: str, k: int, steps: int, **kwargs: Any) -> int:
    """Step both with the same seeded random actions (outside the box too); every output must
    be equal.  Returns how many episodes ended."""
    ref = gym.vector.SyncVectorEnv(
        [lambda: Nav2DEnv(scene, swept=False, **kwargs) for _ in range(k)]
    )
    vec = gym.make_vec("uvnav/Nav2D-v0", num_envs=k, vectorization_mode="vector_entry_point",
                       scenario=scene, **kwargs)  # fmt: skip
    assert isinstance(vec, Nav2DVectorEnv)
    assert vec.observation_space == ref.observation_space
    assert vec.action_space == ref.action_space
    o1, _ = ref.reset(seed=11)
    o2, _ = vec.reset(seed=11)
    assert np.array_equal(o1, o2)
    rng = np.random.default_rng(0)
    ended = 0
    for _ in range(steps):
        a = rng.uniform(-1.3, 1.3, (k, 2))
        if kwargs.get("raw_commands"):
            a = a * np.array([1.0, 1.5])
        a = a.astype(vec.action_space.dtype)
        out1, out2 = ref.step(a), vec.step(a)
        for x, y in zip(out1[:4], out2[:4], strict=True):
            np.testing.assert_array_equal(x, y)
        for key in ("status", "distance", "clearance", "time"):
            np.testing.assert_array_equal(out1[4][key], out2[4][key])
        ended += int(out1[2].sum() + out1[3].sum())
    ref.close()
    vec.close()
    return ended


def test_equal_to_sync_vector_env_through_resets() -> None:
    assert assert_same_run("random-ch2:1", 4, 400) >= 2


def test_equal_with_raw_commands_and_a_short_lidar() -> None:
    assert_same_run("thesis-ch2-one-obstacle", 3, 150, raw_commands=True, n_rays=8,
                    max_range=2.0, reward={"clearance": 2.0})  # fmt: skip


@pytest.mark.skipif(not numba_available(), reason="needs numba (the fast extra)")
def test_python_kernels_give_the_same_numbers() -> None:
    with compiled(False):
        assert_same_run("random-ch2:2", 2, 40)


def test_seeds_per_env_and_episode_seed_option() -> None:
    env = Nav2DVectorEnv(3, "random-ch2:4")
    env.reset(seed=[5, None, 7])
    first = env.episode_seeds.copy()
    env.reset(seed=[5, 6, 7])
    assert env.episode_seeds[0] == first[0] and env.episode_seeds[2] == first[2]
    env.reset(options={"episode_seed": 42})
    assert env.episode_seeds.tolist() == [42, 42, 42]
    with pytest.raises(ValueError, match="2 seeds for 3 environments"):
        env.reset(seed=[1, 2])


def test_scenes_that_cannot_be_batched_are_refused() -> None:
    with pytest.raises(ValueError, match="cannot be batched: obstacle 0 is a DiscBody"):
        Nav2DVectorEnv(2, "crowd-eth:0")


def test_the_batched_env_says_it_judges_collisions_at_step_ends() -> None:
    with pytest.raises(ValueError, match="swept: the batched worlds judge collisions at the end"):
        Nav2DVectorEnv(2, "random-ch2:1", swept=True)


def test_a_non_finite_action_is_refused_and_changes_nothing() -> None:
    vec = Nav2DVectorEnv(2, "random-ch2:1")
    vec.reset(seed=3)
    time, pose = vec.worlds.time.copy(), vec._obs.copy()
    for bad in (np.nan, np.inf, -np.inf):
        a = np.zeros((2, 2))
        a[1, 0] = bad
        with pytest.raises(
            ValueError, match=rf"^actions\[1, 0\] is {bad}: an action must be finite$"
        ):
            vec.step(a)
    with pytest.raises(ValueError, match=r"^actions must have shape \(2, 2\) \(got \(2,\)\)$"):
        vec.step(np.zeros(2))
    assert np.array_equal(vec.worlds.time, time) and np.array_equal(vec._obs, pose)
    _, rewards, *_ = vec.step(np.zeros((2, 2)))
    assert np.isfinite(rewards).all()


@pytest.mark.parametrize(
    ("num_envs", "error", "message"),
    [
        (10**7, ValueError, "num_envs must be a whole number >= 1 and <= 10000 (got 10000000)"),
        (2.5, ValueError, "num_envs must be a whole number >= 1 and <= 10000 (got 2.5)"),
        (0, ValueError, "num_envs must be a whole number >= 1 and <= 10000 (got 0)"),
        ("4", TypeError, "num_envs must be a whole number (got str '4')"),
    ],
)
def test_bad_num_envs_is_one_line(num_envs: object, error: type, message: str) -> None:
    with pytest.raises(error) as info:
        Nav2DVectorEnv(num_envs, "random-ch2:1")  # type: ignore[arg-type]
    assert str(info.value) == message
