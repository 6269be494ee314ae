"""The observation types (uvnav.sensors.observation)."""

from __future__ import annotations

import copy
import dataclasses
import pickle

import numpy as np
import pytest

from uvnav.sensors.observation import ObstacleReading, Readings, any_estimated, read_arrays


def test_a_disc_reading_built_fast_is_the_constructors() -> None:
    args = (2, 0.7, np.array([0.1, 0.2]), np.array([0.5, 0.5]), np.array([1.0, 0.0]), 0.0,
            np.zeros((0, 2)), 0.3, 0.3)  # fmt: skip
    fast, slow = ObstacleReading.known(*args), ObstacleReading(*args)
    for f in dataclasses.fields(slow):
        a, b = getattr(fast, f.name), getattr(slow, f.name)
        assert a is b or a == b
    assert fast.is_disc and fast.speed == 1.0


def test_a_polygon_reading_built_fast_is_the_constructors() -> None:
    args = (3, 0.5, np.array([1.0, 2.0]), np.array([1.5, 2.5]), np.array([0.3, -0.4]), 0.2,
            np.array([[1.0, 2.0], [2.0, 2.0], [1.5, 3.0]]), 0.9)  # fmt: skip
    fast = ObstacleReading.known(*args[:7], 0.0, args[7])
    slow = ObstacleReading(*args[:7], 0.0, args[7])
    for f in dataclasses.fields(slow):
        a, b = getattr(fast, f.name), getattr(slow, f.name)
        assert a is b or a == b
    assert not fast.is_disc and fast.velocity_source == "known"
    assert fast.speed == slow.speed == 0.5
    with pytest.raises(dataclasses.FrozenInstanceError):
        fast.distance = 1.0  # type: ignore[misc]


def _disc(k: int, d: float) -> ObstacleReading:
    z = np.zeros(2)
    return ObstacleReading(k, d, z, np.array([d + 0.5, 0.0]), np.array([0.1 * k, 1.0]), 0.0,
                           np.zeros((0, 2)), 0.5, 0.5)  # fmt: skip


def test_readings_made_once_from_the_sensors_arrays_and_plain_when_copied() -> None:
    rds = (_disc(0, 1.0), _disc(1, 2.0))
    calls = []

    def make() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        calls.append(1)
        return read_arrays(rds)

    r = Readings.lazy(rds, make)
    assert r == rds and not calls  # nothing made until read
    first = r.arrays
    assert r.arrays is first and len(calls) == 1
    assert first[0].tolist() == [[1.0, 0.0, 0.5, 0.5], [2.0, 0.0, 0.5, 0.5]]
    with pytest.raises(ValueError, match="read-only"):
        first[1][0, 0] = 9.0
    back = pickle.loads(pickle.dumps(r))
    assert type(back) is tuple and back[1].obstacle_id == 1
    assert type(copy.copy(r)) in (tuple, Readings) and type(r[1:]) is tuple


def test_readings_without_a_maker_read_themselves() -> None:
    rds = (_disc(0, 1.0),)
    got = Readings(rds).arrays
    assert all(np.array_equal(a, b) for a, b in zip(got, read_arrays(rds), strict=True))
    assert read_arrays(())[0].shape == (0, 4)


def test_whether_any_velocity_is_estimated_is_the_sensors_word_or_the_readings() -> None:
    est = dataclasses.replace(_disc(1, 2.0), velocity_source="estimated")
    assert any_estimated((_disc(0, 1.0), est)) and not any_estimated((_disc(0, 1.0),))
    said = Readings.lazy((_disc(0, 1.0),), lambda: read_arrays(()), all_known=True)
    assert not any_estimated(said) and not any_estimated(Readings((_disc(0, 1.0),)))
    assert any_estimated(Readings((est,)))
