"""The PettingZoo ParallelEnv: PettingZoo's API test, agents removed when done."""

from __future__ import annotations

import numpy as np
from pettingzoo.test import parallel_api_test

from uvnav.envs import as_policy
from uvnav.envs.multi_robot import MultiNav2DParallelEnv


def test_parallel_api_test_passes() -> None:
    parallel_api_test(MultiNav2DParallelEnv("antipodal:4", render_mode="rgb_array"), num_cycles=60)


TUNED = {"switch_distance": 2.5, "forecast_horizon": 2.0, "safety_margin": 0.3}


def test_zhang2019_agents_all_arrive_on_the_4_swap_and_leave_the_agent_list() -> None:
    env = MultiNav2DParallelEnv("antipodal:4")
    pols = {a: as_policy("zhang2019-v1", **TUNED) for a in env.possible_agents}
    obs, infos = env.reset(seed=0)
    # each robot's controller sees the 3 others as moving discs once they are within 5 m
    status: dict[str, str] = {}
    while env.agents:
        obs, _rew, term, trunc, infos = env.step({a: pols[a](obs[a], infos[a]) for a in env.agents})
        for a in term:
            if term[a] or trunc[a]:
                status[a] = infos[a]["status"]
                assert a not in env.agents
    assert status == {a: "success" for a in env.possible_agents}


def test_other_robots_are_in_each_lidar() -> None:
    env = MultiNav2DParallelEnv("crossing:4", n_rays=64)
    obs, infos = env.reset(seed=0)
    seen = infos["robot_0"]["uvnav"].observation.obstacles
    assert seen and all(rd.radius > 0 for rd in seen)  # robots are discs; no world obstacles
    assert min(obs["robot_0"][4:]) < 1.0
    assert np.isfinite(obs["robot_1"]).all()
