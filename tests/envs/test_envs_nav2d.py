"""uvnav/Nav2D-v0: Gymnasium's env checker, vector envs, rewards, frames, determinism."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import uvnav.envs
from uvnav.controllers import make_controller
from uvnav.core import AgentLog
from uvnav.envs.core import RewardConfig
from uvnav.envs.nav2d import Nav2DEnv
from uvnav.geometry.kernels3d import compiled, numba_enabled
from uvnav.scenarios import load_scenario
from uvnav.scenarios.build import build_episode
from uvnav.scenarios.generators import generate
from uvnav.scenarios.schema import Scenario
from uvnav.sim import run_episode, run_rng
from uvnav.sim.bodies2d import PackedBodies


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


# ------------------------------------------------- the env steps the simulator's world, bit for bit
def _scene(name: str, **changes: object) -> Scenario:
    sc = load_scenario(name)
    return Scenario.model_validate({**sc.model_dump(), **changes}) if changes else sc


NOISY = {
    "control_period": 0.3,  # three integration steps per env step
    "sensing": {
        "range": 5.0,
        "velocities": "estimated",  # the world's estimator, fed by its sensor generator
        "position_noise": 0.02,
        "lidar": {"n_rays": 36, "noise_std": 0.01, "dropout": 0.05},  # noisy: the same stream
    },
}


@pytest.mark.parametrize(
    ("scene", "changes", "law", "k"),
    [
        ("thesis-ch2-fig2-10-comparison", {}, "zhang2019-v1", 0),
        ("random-ch2:2", {}, "dwa-v1", 2),
        ("random-ch2:3", NOISY, "zhang2019-v1", 3),
    ],
)
def test_env_episode_is_the_simulators_bit_for_bit(
    scene: str, changes: dict, law: str, k: int
) -> None:
    """The law's own commands as raw actions (``raw_commands=True``: the normalised float32 map
    cannot carry them exactly), its generator the world's (``law_setup``), episode ``k``: every
    pose at every decision and the episode's metrics equal ``run_episode``'s (no tolerance)."""
    sc = _scene(scene, **changes)
    env = Nav2DEnv(sc, raw_commands=True)
    _, info = env.reset(options={"episode_seed": k})
    ctrl = make_controller(law)
    ctrl.reset(*env.world.law_setup())
    poses = [env.world.pose]
    term = trunc = False
    while not (term or trunc):
        cmd = ctrl.act(info["uvnav"].observation)
        _, _, term, trunc, info = env.step(np.array([cmd.v, cmd.u]))
        poses.append(env.world.pose)
    sim = run_episode(build_episode(sc, k), make_controller(law), run_rng(k), record=True)
    tr = sim.trajectory
    assert tr is not None
    ratio = env.world.ratio
    expected = [*tr.robot[: len(tr.robot) - 1 : ratio], tr.robot[-1]]
    np.testing.assert_array_equal(np.array(poses), np.array(expected))
    assert info["status"] == sim.status and info["time"] == tr.times[-1]
    timing = ("mode_switches", "decision_us_median", "decision_us_p99")
    got = {m: v for m, v in env.world.metrics(AgentLog()).to_dict().items() if m not in timing}
    assert got == {m: v for m, v in sim.metrics.to_dict().items() if m not in timing}
    env.close()


def test_raw_commands_are_applied_as_the_simulator_applies_them() -> None:
    env = Nav2DEnv("open-field", raw_commands=True)
    spec = env.scenario.robot
    box = env.action_space
    assert isinstance(box, gym.spaces.Box) and box.dtype == np.float64
    np.testing.assert_array_equal(box.high, [spec.v_max, spec.u_max])
    env.reset(seed=0)
    env.step(np.array([2.0 * spec.v_max, 0.0]))  # outside the limits: saturated and counted
    assert env.world.book.violations == 1 and env.world.applied.v == spec.v_max


@pytest.mark.parametrize(
    "code",
    [
        # Gymnasium 1.x loads no plugin entry points: import the module, name it for linters
        "import gymnasium as gym, uvnav.envs; gym.register_envs(uvnav.envs); "
        "env = gym.make('uvnav/Nav2D-v0', scenario='office-floor')",
        # or let gymnasium import it
        "import gymnasium as gym; env = gym.make('uvnav.envs:uvnav/Nav2D-v0', scenario='corridor')",
        # or import uvnav, before or after gymnasium
        "import gymnasium as gym, uvnav; env = gym.make('uvnav/Nav2D-v0', scenario='corridor')",
        "import uvnav, gymnasium as gym; env = gym.make('uvnav/Nav2D-v0', scenario='corridor')",
    ],
)
def test_gymnasium_make_in_a_fresh_interpreter(code: str) -> None:
    import os
    import subprocess
    import sys
    from pathlib import Path

    src = str(Path(uvnav.envs.__file__).resolve().parents[2])
    path = os.pathsep.join(p for p in (src, os.environ.get("PYTHONPATH", "")) if p)
    check = "; obs, _ = env.reset(seed=0); assert env.observation_space.contains(obs); print('ok')"
    out = subprocess.run(
        [sys.executable, "-c", code + check],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": path},
        timeout=120,
        check=False,
    )
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"n_rays": -3}, "n_rays must be a whole number >= 0"),
        ({"n_rays": 2.5}, "n_rays must be a whole number >= 0"),
        ({"max_range": float("nan")}, "max_range must be a finite number > 0"),
        ({"max_range": 0.0}, "max_range must be a finite number > 0"),
        ({"goal_scale": -1.0}, "goal_scale must be a finite number > 0"),
        ({"reward": {"bogus": 1.0}}, "reward: unknown field(s) bogus; known: "),
        ({"n_rays": 10**9}, "n_rays must be a whole number >= 0 and <= 4096 (got 1000000000)"),
        ({"reward": {"success": float("nan")}}, "reward.success must be a finite number"),
        ({"reward": {"time": 1e300}}, "reward.time must be a finite number within +-1e+06"),
        ({"goal_scale": 1e15}, "goal_scale must be a finite number > 0 and <= 1e+06"),
    ],
)
def test_bad_settings_are_refused_by_name(kwargs: dict[str, object], message: str) -> None:
    from uvnav.envs.multi_robot import MultiNav2DParallelEnv
    from uvnav.envs.nav2d_vec import Nav2DVectorEnv

    for make in (Nav2DEnv, MultiNav2DParallelEnv, Nav2DVectorEnv):
        with pytest.raises(ValueError) as info:
            make(**kwargs)  # type: ignore[arg-type]
        assert message in str(info.value), (make, str(info.value))


@pytest.mark.parametrize("env_id", ["uvnav/Nav2D-v0", "uvnav/Nav3D-v0", "uvnav/UUV2D-v0"])
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_non_finite_action_is_refused_before_it_reaches_the_state(
    env_id: str, bad: float
) -> None:
    import gymnasium as gym

    env = gym.make(env_id).unwrapped
    env.reset(seed=0)
    n = 3 if env_id == "uvnav/Nav3D-v0" else 2
    action = np.zeros(n)
    action[-1] = bad
    with pytest.raises(ValueError) as info:
        env.step(action)
    assert str(info.value) == f"action[{n - 1}] is {bad}: an action must be finite"
    again, reward, *_ = env.step(np.zeros(n))
    assert math.isfinite(float(reward)) and np.isfinite(again).all()
    fresh = gym.make(env_id).unwrapped
    fresh.reset(seed=0)
    assert np.array_equal(fresh.step(np.zeros(n))[0], again)


def test_the_multi_robot_env_refuses_a_non_finite_action_before_any_robot_moves() -> None:
    from uvnav.envs.multi_robot import MultiNav2DParallelEnv

    env = MultiNav2DParallelEnv("antipodal:3")
    env.reset(seed=0)
    poses = env.world.state.copy()
    actions = {a: np.zeros(2) for a in env.agents}
    actions["robot_2"] = np.array([0.5, np.nan])
    with pytest.raises(ValueError, match=r"^action of robot_2\[1\] is nan: an action must be"):
        env.step(actions)
    assert np.array_equal(env.world.state, poses) and env.world.t == 0.0


def _rollout(kwargs: dict, steps: int) -> tuple[list, list[bool]]:
    """A seeded random-action rollout through resets: every vector, reward, flag and info item
    (the law's observation compared by ControllerView's equality), and whether each episode's
    bodies were packed."""
    env = Nav2DEnv(**kwargs)
    rng = np.random.default_rng(1)
    low, high = env.action_space.low, env.action_space.high  # type: ignore[attr-defined]
    obs, info = env.reset(seed=11)
    out: list = [obs, info]
    packed = [isinstance(env.world.bodies, PackedBodies)]
    for _ in range(steps):
        obs, r, term, trunc, info = env.step(rng.uniform(low, high).astype(env.action_space.dtype))
        out += [obs, r, term, trunc, info]
        if term or trunc:
            obs, info = env.reset()
            out += [obs, info]
            packed.append(isinstance(env.world.bodies, PackedBodies))
    env.close()
    return out, packed


@pytest.mark.skipif(not numba_enabled(), reason="needs numba (the fast extra), enabled")
@pytest.mark.parametrize(
    "kwargs",
    [
        {},
        {"swept": False},
        {"raw_commands": True},
        {"n_rays": 7, "max_range": 2.0},
    ],
)
def test_compiled_bodies_and_lidar_give_the_reference_rollout(kwargs: dict) -> None:
    """With numba the env's bodies move, sense and cast the lidar in compiled calls; a seeded
    rollout of random actions through resets gives the numpy reference's observation vectors,
    rewards, terminations, truncations and infos (the law's observation included), exactly."""
    kwargs = {"scenario": generate("random-ch2", 3, n_obstacles=10), **kwargs}
    fast, packed = _rollout(kwargs, 700)
    with compiled(False):
        slow, unpacked = _rollout(kwargs, 700)
    assert all(packed) and not any(unpacked) and len(packed) >= 2  # a reset happened
    assert len(fast) == len(slow)
    for a, b in zip(fast, slow, strict=True):
        if isinstance(a, np.ndarray):
            assert a.dtype == b.dtype and np.array_equal(a, b)
        else:
            assert a == b


def _law_observations(read_at_once: bool, steps: int) -> list:
    """The law's observations of a seeded random rollout (through resets): the world's
    ``observe()`` at each step (``read_at_once``), or the infos' kept and read after the
    rollout."""
    env = Nav2DEnv(generate("random-ch2", 3, n_obstacles=10))
    rng = np.random.default_rng(2)
    _, info = env.reset(seed=5)
    # compiled bodies leave the sensing to the read (none in the steps)
    assert env.world.sense_in_step != isinstance(env.world.bodies, PackedBodies)
    infos, seen = [info], [env.world.observe()] if read_at_once else []
    for _ in range(steps):
        *_, term, trunc, info = env.step(rng.uniform(-1, 1, 2).astype(np.float32))
        infos.append(info)
        if read_at_once:
            seen.append(env.world.observe())
        if term or trunc:
            infos.append(env.reset()[1])
            if read_at_once:
                seen.append(env.world.observe())
    return seen if read_at_once else [i["uvnav"].observation for i in infos]


def test_the_law_observation_read_later_is_the_one_of_its_step() -> None:
    """``info["uvnav"]``'s observation is made when first read; read after the env has moved on
    it is, field for field, the one the world's sensors gave at its own step."""
    now, later = _law_observations(True, 400), _law_observations(False, 400)
    assert len(now) == len(later) > 400 and any(o.obstacles for o in now)
    for a, b in zip(now, later, strict=True):
        assert (a.time, a.speed, a.lidar, dict(a.extras)) == (b.time, b.speed, b.lidar, {})
        assert np.array_equal(a.pose, b.pose) and np.array_equal(a.goal, b.goal)
        assert len(a.obstacles) == len(b.obstacles)
        for ra, rb in zip(a.obstacles, b.obstacles, strict=True):
            for name in ("nearest_point", "centre", "velocity", "outline"):
                assert np.array_equal(getattr(ra, name), getattr(rb, name))
            for name in ("obstacle_id", "distance", "angular_velocity", "radius",
                         "bounding_radius", "velocity_source"):  # fmt: skip
                assert getattr(ra, name) == getattr(rb, name)


def test_the_law_view_pickles_and_crosses_an_async_vector_env() -> None:
    """A view whose observation is made on first read pickles with it made (an async vector
    env's workers send their infos through pipes), equal to the original."""
    import pickle

    env = Nav2DEnv(generate("random-ch2", 3, n_obstacles=10))
    env.reset(seed=3)
    *_, info = env.step(np.zeros(2, dtype=np.float32))
    again = pickle.loads(pickle.dumps(info))
    assert again["uvnav"] == info["uvnav"] and again["uvnav"].observation.obstacles
    vec = gym.make_vec("uvnav/Nav2D-v0", num_envs=2, vectorization_mode="async",
                       scenario=generate("random-ch2", 3, n_obstacles=10))  # fmt: skip
    try:
        vec.reset(seed=0)
        *_, infos = vec.step(np.zeros((2, 2), dtype=np.float32))
        views = infos["uvnav"]
        assert len(views) == 2 and all(v.observation.time > 0 for v in views)
    finally:
        vec.close()


@pytest.mark.parametrize(
    "action",
    [
        np.array([3.0, -2.0]),
        np.array([3.0, -2.0], dtype=np.float16),
        np.array([300, -2]),
        [3.0, -2.0],
        (np.float32(1.5), -1.0),
    ],
)
def test_any_form_of_an_action_steps_as_its_float_array(action: object) -> None:
    """An action outside [-1, 1] is clipped, and an action of any array-like form or dtype
    steps the env as the same numbers in a float64 array do."""
    envs = [Nav2DEnv(generate("random-ch2", 3, n_obstacles=10)) for _ in range(2)]
    for env in envs:
        env.reset(seed=4)
    for _ in range(5):
        got = envs[0].step(action)  # type: ignore[arg-type]
        want = envs[1].step(np.array([1.0, -1.0]))
        assert np.array_equal(got[0], want[0]) and got[1:4] == want[1:4]
        assert got[4]["uvnav"] == want[4]["uvnav"]
