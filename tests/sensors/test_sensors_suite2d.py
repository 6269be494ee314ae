"""The 2D sensor suite (uvnav.sensors.suite2d)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from uvnav.sensors.config import SensingConfig
from uvnav.sensors.observation import Observation
from uvnav.sensors.suite2d import Sensors2D, observation


def test_an_observation_built_fast_is_the_constructors() -> None:
    pose, goal = np.array([1.0, 2.0, 0.3]), np.array([5.0, 6.0])
    fast = observation(1.5, pose, 0.4, goal, (), None, {"x": 1})
    slow = Observation(time=1.5, pose=pose, speed=0.4, goal=goal, extras={"x": 1})
    # every field is set on the instance (a field added to Observation must be added here)
    assert set(vars(fast)) == {f.name for f in dataclasses.fields(Observation)}
    for f in dataclasses.fields(Observation):
        assert getattr(fast, f.name) is getattr(slow, f.name) or (
            getattr(fast, f.name) == getattr(slow, f.name)
        )
    assert fast.heading == 0.3
    with pytest.raises(dataclasses.FrozenInstanceError):
        fast.time = 2.0  # type: ignore[misc]


def test_the_exact_observation_is_the_one_observe_makes() -> None:
    sensors = Sensors2D(SensingConfig(sensing_range=5.0), np.random.default_rng(0))
    sensors.reset(oracle=False)
    assert sensors.exact_only
    pose, goal = np.array([0.0, 0.0, 0.0]), np.array([3.0, 0.0])
    full = sensors.observe(0.2, pose, 0.5, goal, lambda: (), lambda: None)  # type: ignore[arg-type,return-value]
    short = sensors.exact_observation(0.2, pose, 0.5, goal, ())
    assert vars(full).keys() == vars(short).keys()
    assert full.time == short.time and full.speed == short.speed and full.obstacles == ()
    assert full.lidar is None and short.lidar is None and full.extras == short.extras == {}
    assert short.extras is not sensors.exact_observation(0.2, pose, 0.5, goal, ()).extras
