"""The observation types (uvnav.sensors.observation)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from uvnav.sensors.observation import ObstacleReading


def test_a_polygon_reading_built_fast_is_the_constructors() -> None:
    args = (3, 0.5, np.array([1.0, 2.0]), np.array([1.5, 2.5]), np.array([0.3, -0.4]), 0.2,
            np.array([[1.0, 2.0], [2.0, 2.0], [1.5, 3.0]]), 0.9)  # fmt: skip
    fast = ObstacleReading.polygon(*args)
    slow = ObstacleReading(*args[:7], 0.0, args[7])
    for f in dataclasses.fields(slow):
        a, b = getattr(fast, f.name), getattr(slow, f.name)
        assert a is b or a == b
    assert not fast.is_disc and fast.velocity_source == "known"
    assert fast.speed == slow.speed == 0.5
    with pytest.raises(dataclasses.FrozenInstanceError):
        fast.distance = 1.0  # type: ignore[misc]
