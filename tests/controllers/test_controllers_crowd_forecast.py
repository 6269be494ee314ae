"""The crowd forecast (uvnav.controllers.crowd_forecast) and the grid route reading it."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.controllers.crowd_forecast import (
    FORECAST_STEP,
    STILL,
    crowd_forecast,
    kernel,
    orca_rollout_py,
)
from uvnav.controllers.crowd_grid import _kernel, exposure_map_py, exposure_track_py, grid_way_point
from uvnav.controllers.crowd_route import RouteParams
from uvnav.geometry.kernels3d import compiled


def head_on() -> np.ndarray:
    """Two people 4 m apart walking at each other at 1 m/s, 0.1 m off a head-on line."""
    return np.array([[-2.0, 0.05, 1.0, 0.0, 0.3], [2.0, -0.05, -1.0, 0.0, 0.3]])


def test_a_lone_walker_walks_on_and_a_still_one_stands() -> None:
    bodies = np.array([[0.0, 0.0, 0.6, -0.8, 0.3], [5.0, 5.0, 0.5 * STILL, 0.0, 0.3]])
    track = crowd_forecast(bodies, 2.0)
    assert track.shape == (round(2.0 / FORECAST_STEP) + 1, 2, 2)
    times = FORECAST_STEP * np.arange(track.shape[0])
    np.testing.assert_allclose(track[:, 0], np.outer(times, [0.6, -0.8]), atol=1e-12)
    np.testing.assert_array_equal(track[:, 1], np.tile([5.0, 5.0], (track.shape[0], 1)))


def test_people_walking_at_each_other_are_forecast_to_pass_not_to_meet() -> None:
    bodies = head_on()
    track = crowd_forecast(bodies, 4.0)
    gaps = np.hypot(*(track[:, 0] - track[:, 1]).T)
    assert gaps.min() >= 0.6 - 1e-6  # never closer than touching
    assert track[-1, 0, 0] > 1.0 and track[-1, 1, 0] < -1.0  # past each other by 4 s
    times = FORECAST_STEP * np.arange(track.shape[0])
    straight = bodies[:, None, :2] + times[None, :, None] * bodies[:, None, 2:4]
    assert np.hypot(*(straight[0] - straight[1]).T).min() < 0.2  # constant velocity: they meet


@settings(max_examples=20, deadline=None)
@given(st.integers(0, 2**32 - 1))
def test_the_compiled_rollout_agrees_with_plain_python(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 12))
    bodies = np.column_stack([rng.uniform(-4, 4, (n, 2)), rng.uniform(-1, 1, (n, 2)),
                              rng.uniform(0.2, 0.5, n)])  # fmt: skip
    ref, got = np.empty((9, n, 2)), np.empty((9, n, 2))
    pref = rng.uniform(-1, 1, (n, 2))
    orca_rollout_py(bodies, pref, 0.25, 5.0, 10.0, 10, 0.01, ref)
    with compiled(True):
        kernel("orca_rollout_py")(bodies, pref, 0.25, 5.0, 10.0, 10, 0.01, got)
    np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-9)


def test_a_straight_track_costs_the_cells_as_the_constant_velocity_map() -> None:
    bodies = np.array([[2.0, 2.0, 0.0, -1.0, 0.3], [-1.0, 0.5, 0.7, 0.2, 0.4]])
    times = FORECAST_STEP * np.arange(9)  # to 2 s
    track = np.ascontiguousarray(
        np.transpose(bodies[:, None, :2] + times[None, :, None] * bodies[:, None, 2:4], (1, 0, 2))
    )
    ref, got = np.empty((16, 12)), np.empty((16, 12))
    exposure_map_py(-2.0, -1.5, 0.1, 0.2, bodies, 1.0, 2.0, 0.6, ref)
    exposure_track_py(-2.0, -1.5, 0.1, 0.2, track, bodies[:, 4].copy(), FORECAST_STEP, 1.0, 2.0,
                      0.6, got)  # fmt: skip
    np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-12)
    with compiled(True):
        _kernel("exposure_track_py")(-2.0, -1.5, 0.1, 0.2, track, bodies[:, 4].copy(),
                                     FORECAST_STEP, 1.0, 2.0, 0.6, got)  # fmt: skip
    np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-12)


def test_a_walker_heading_into_a_standing_crowd_is_forecast_to_stop_short() -> None:
    standing = [[3.0, y, 0.0, 0.0, 0.3] for y in np.arange(-3.0, 3.01, 0.6)]
    bodies = np.array([[0.0, 0.0, 1.0, 0.0, 0.3], *standing])
    track = crowd_forecast(bodies, 4.0)
    assert track[-1, 0, 0] < 3.0 - 0.6  # constant velocity: at x = 4 m, through the crowd
    for k in range(track.shape[0]):
        gaps = np.hypot(*(track[k, 1:] - track[k, 0]).T)
        assert gaps.min() >= 0.62 - 0.05  # never into anyone (ORCA radii, a step's slack)


def test_the_grid_route_reads_the_forecast_only_when_asked() -> None:
    rng = np.random.default_rng(3)
    still = np.column_stack([rng.uniform(1, 5, (8, 2)) - [0, 3], np.zeros((8, 2)),
                             np.full(8, 0.3)])  # fmt: skip
    goal, start = np.array([6.0, 0.0]), np.zeros(2)
    plain = grid_way_point(start, goal, still, 1.0, 3.0, 0.6, 3.0, 2.0)
    assert grid_way_point(start, goal, still, 1.0, 3.0, 0.6, 3.0, 2.0, 0.0).tolist() == (
        plain.tolist()
    )
    rolled = grid_way_point(start, goal, still, 1.0, 99.0, 0.6, 3.0, 2.0, 3.0)
    assert rolled.tolist() == pytest.approx(plain.tolist())  # standing people stay put
    assert RouteParams().route_forecast == 0.0
    with pytest.raises(ValueError, match="route_forecast"):
        RouteParams(route_forecast=-1.0)
