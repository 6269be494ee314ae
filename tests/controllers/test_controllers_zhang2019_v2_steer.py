"""The unicycle's decision of ``zhang2019-v2`` made on floats
(:mod:`uvnav.controllers.zhang2019_v2_steer`) hands the compiled loop the numbers the numpy
building blocks make, to the bit, and keeps its constants only while they hold."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers.zhang2019_limits import RampModel, preferred_under_limits
from uvnav.controllers.zhang2019_v2 import Zhang2019V2Params
from uvnav.controllers.zhang2019_v2_bodies import body_table
from uvnav.controllers.zhang2019_v2_loop import outline_rings
from uvnav.controllers.zhang2019_v2_paths import plan_paths
from uvnav.controllers.zhang2019_v2_steer import (
    PathConstants,
    path_constants,
    plan_on_floats,
    preferred_floats,
)
from uvnav.dynamics.unicycle import UnicycleSpec
from uvnav.sensors.observation import Observation, ObstacleReading

MODELS = (RampModel(1.0, math.pi, math.inf, math.inf, 0.25),
          RampModel(1.0, math.pi, 1.0, 2.0, 0.25), RampModel(0.7, 2.0, 0.5, 1.0, 0.13))  # fmt: skip
coord = st.floats(-20.0, 20.0, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(px=coord, py=coord, gx=coord, gy=coord, k=st.integers(0, len(MODELS) - 1),
       scale=st.sampled_from((1e-13, 1e-3, 1.0)))  # fmt: skip
def test_preferred_floats_equal_the_numpy_preferred_velocity(
    px: float, py: float, gx: float, gy: float, k: int, scale: float
) -> None:
    goal = np.array([px + scale * gx, py + scale * gy])
    want = preferred_under_limits(np.array([px, py]), goal, MODELS[k])
    got = preferred_floats(px, py, float(goal[0]), float(goal[1]), MODELS[k])
    assert got == (want[0], want[1])


def _numpy_state(obs: Observation, goal: np.ndarray, model: RampModel,
                 now: tuple[float, float], v_prev: np.ndarray) -> np.ndarray:  # fmt: skip
    """The loop's state vector as the numpy building blocks make it."""
    pose = np.asarray(obs.pose, dtype=float)
    v_pref = preferred_under_limits(np.asarray(obs.position, dtype=float), goal, model)
    moving = 1.0 if math.hypot(v_prev[0], v_prev[1]) > 1e-9 else 0.0
    return np.array((pose[0], pose[1], pose[2], now[0], now[1], v_pref[0], v_pref[1],
                     math.hypot(v_pref[0], v_pref[1]), v_prev[0], v_prev[1], moving))  # fmt: skip


@pytest.mark.parametrize("seed", range(12))
def test_plan_on_floats_chooses_what_the_numpy_state_chooses(seed: int) -> None:
    rng = np.random.default_rng(seed)
    readings = []
    for k in range(int(rng.integers(0, 20))):
        c, v = rng.uniform(-6.0, 6.0, 2), rng.uniform(-1.2, 1.2, 2)
        dist = float(np.hypot(*c))
        readings.append(ObstacleReading(k, dist - 0.3, c * (1 - 0.3 / dist), c, v, 0.0,
                                        np.zeros((0, 2)), 0.3, 0.3))  # fmt: skip
    readings.sort(key=lambda r: r.distance)
    pose = np.array([*rng.uniform(-0.5, 0.5, 2), rng.uniform(-math.pi, math.pi)])
    goal = rng.uniform(-8.0, 8.0, 2) * (0.05 if seed % 4 == 0 else 1.0)
    obs = Observation(time=0.0, pose=pose, speed=0.5, goal=goal, obstacles=tuple(readings))
    model, p = MODELS[seed % len(MODELS)], Zhang2019V2Params()
    now, v_prev = (float(rng.uniform(0.0, 1.0)), float(rng.uniform(-1.0, 1.0))), rng.normal(size=2)
    prm = path_constants(model, p, 0.3)
    speeds = model.v_max * np.asarray(p.speed_levels)
    table = body_table(obs.obstacles, p.noise_sigmas)
    want = plan_paths(_numpy_state(obs, goal, model, now, v_prev), table,
                      outline_rings(obs.obstacles, table[0]), speeds, prm)  # fmt: skip
    got = plan_on_floats(obs, goal, model, now, v_prev, p.noise_sigmas, (prm, speeds))
    assert np.array_equal(got, want)


def test_path_constants_are_kept_while_the_law_the_vehicle_and_the_period_are() -> None:
    keep, p = PathConstants(), Zhang2019V2Params()
    spec = UnicycleSpec(1.0, math.pi, radius=0.3, accel_max=1.0, turn_accel_max=2.0)
    model, prm, speeds = keep.get(p, spec, 0.25)
    assert model == RampModel(1.0, math.pi, 1.0, 2.0, 0.25)
    assert np.array_equal(prm, path_constants(model, p, 0.3))
    assert speeds.tolist() == [1.0, 0.6, 0.3]
    assert keep.get(p, spec, 0.25)[1] is prm  # nothing changed: the same arrays
    other = keep.get(p, spec, 0.2)
    assert other[0].period == 0.2 and other[1][4] == 0.2
    wider = dataclasses.replace(spec, radius=0.5)
    assert keep.get(p, wider, 0.2)[1][18] == 0.5  # another vehicle: made again
    slower = Zhang2019V2Params(speed_levels=(0.5,))
    assert keep.get(slower, wider, 0.2)[2].tolist() == [0.5]  # other parameters: made again
