"""The Chapter 5 loop on the thesis scenes (Fig. 5.3): reach B, no collision, never in Scene 2's
narrow inner space."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from uvnav.controllers.zhang_uuv3d import GeometricLocator, OracleLocator, ZhangUUV3D
from uvnav.core import SENSINGS, VEHICLES
from uvnav.scenarios.ch5 import build_uuv3d, load_ch5_scenario
from uvnav.sim.episode_uuv3d import UUV3DWorld
from uvnav.sim.metrics import METRIC_NAMES
from uvnav.sim.run import run_episode


@pytest.mark.parametrize("scene", ["thesis-ch5-scene1", "thesis-ch5-scene2"])
def test_thesis_scene_reached_without_collision(scene: str) -> None:
    setup = build_uuv3d(load_ch5_scenario(scene))
    res = run_episode(
        setup, ZhangUUV3D(None, GeometricLocator()), np.random.default_rng(0), record=True
    )
    m = res.metrics
    assert res.status == "success", res.status
    assert m.success and not m.collision
    assert m.min_clearance is not None and m.min_clearance > 0.2
    assert not res.flags["entered_inner_space"]
    assert m.limit_violations == 0
    assert m.mode_switches >= 2  # it did avoid (M1 -> M2 -> M1)
    assert 1.0 <= m.detour_ratio < 1.3
    assert set(m.to_dict()) == set(METRIC_NAMES)
    assert "M2" in res.trajectory.modes


@pytest.mark.slow
def test_scene3_with_the_oracle_and_noise_is_deterministic() -> None:
    setup = build_uuv3d(load_ch5_scenario("thesis-ch5-scene3"), noise_std=0.05)
    a = run_episode(
        setup, ZhangUUV3D(None, OracleLocator()), np.random.default_rng(4), record=False
    )
    assert a.metrics.success
    setup = build_uuv3d(load_ch5_scenario("thesis-ch5-scene3"), noise_std=0.05)
    b = run_episode(
        setup, ZhangUUV3D(None, GeometricLocator()), np.random.default_rng(4), record=False
    )
    c = run_episode(
        setup, ZhangUUV3D(None, GeometricLocator()), np.random.default_rng(4), record=False
    )
    assert b.metrics.success
    assert b.metrics.path_length == c.metrics.path_length


def test_world_contract_shared_generator_and_oracle_truth() -> None:
    setup = build_uuv3d(load_ch5_scenario("thesis-ch5-scene1"))
    rng = np.random.default_rng(0)
    world = UUV3DWorld(setup, rng)
    assert world.vehicle in VEHICLES and world.sensing in SENSINGS and world.n_agents == 1
    spec, goal, law_rng = world.law_setup(0)
    assert law_rng is rng  # the Ch. 5 quirk: the law and the sonar share one generator
    assert spec is setup.spec and np.array_equal(goal, setup.goal)
    world.start([False])
    assert world.t == 0.0 and not world.done and world.acting() == (0,)
    assert world.observe().truth_point is None
    world.start([True])
    assert world.observe().truth_point is not None


def test_step_count_and_trace_ends_at_t_max() -> None:
    setup = dataclasses.replace(build_uuv3d(load_ch5_scenario("thesis-ch5-scene1")), t_max=0.5)
    res = run_episode(
        setup, ZhangUUV3D(None, GeometricLocator()), np.random.default_rng(0), record=True
    )
    assert res.status == "timeout"
    assert res.trajectory.times == pytest.approx(
        [0.0, 0.2, 0.4, 0.5]
    )  # decisions, then the final state
    assert (
        len(res.trajectory.located)
        == len(res.trajectory.true_nearest)
        == len(res.trajectory.modes)
        == 4
    )
    assert np.isnan(res.trajectory.located[-1]).all()
