"""Sonar dataset (thesis Ch. 5 §5.4): true-geometry targets, min/argmin baseline, determinism."""

from __future__ import annotations

import hypothesis.extra.numpy as hnp
import hypothesis.strategies as st
import numpy as np
import pytest
from hypothesis import given, settings

from uvnav.sensors.sonar_array import SonarArray, adapted_ranges
from uvnav.sensors.sonar_dataset import SonarDataset, reading_targets, sample_sonar_dataset


@pytest.fixture(scope="module")
def ds() -> SonarDataset:
    return sample_sonar_dataset(40, np.random.default_rng(3), subdivisions=2)


def test_shapes_and_determinism(ds: SonarDataset) -> None:
    assert len(ds) == 40
    assert ds.ranges.shape == (40, 9) and ds.targets().shape == (40, 2)
    again = sample_sonar_dataset(40, np.random.default_rng(3), subdivisions=2)
    np.testing.assert_array_equal(again.ranges, ds.ranges)
    np.testing.assert_array_equal(again.target_index, ds.target_index)


def test_targets_are_true_geometry_not_min_argmin(ds: SonarDataset) -> None:
    arr = SonarArray()
    # every reading is at least the true hull gap (a sensor sits on the hull) ...
    assert np.all(ds.ranges >= ds.target_distance[:, None] - 1e-9)
    np.testing.assert_allclose(ds.baseline_distance, ds.ranges.min(axis=1))
    np.testing.assert_array_equal(ds.baseline_index, ds.ranges.argmin(axis=1) + 1)
    # ... and the baseline is biased high somewhere (the targets are not min of the inputs)
    assert np.any(ds.baseline_distance - ds.target_distance > 1e-4)
    assert np.all((ds.target_index >= 1) & (ds.target_index <= 9))
    np.testing.assert_allclose(ds.inputs, adapted_ranges(arr, ds.ranges))
    assert np.all(ds.ranges.min(axis=1) < arr.max_range)  # an echo in every sample


def test_round_trip_and_bad_arrays(ds: SonarDataset) -> None:
    back = SonarDataset.from_arrays(ds.arrays())
    np.testing.assert_array_equal(back.inputs, ds.inputs)
    bad = ds.arrays()
    del bad["inputs"]
    with pytest.raises(ValueError, match="inputs"):
        SonarDataset.from_arrays(bad)
    bad = ds.arrays()
    bad["target_index"] = bad["target_index"][:-1]
    with pytest.raises(ValueError, match="target_index"):
        SonarDataset.from_arrays(bad)
    with pytest.raises(ValueError, match=">= 1"):
        sample_sonar_dataset(0, np.random.default_rng(0))


def test_thesis_targets_are_min_and_argmin_of_the_networks_own_inputs(ds: SonarDataset) -> None:
    y = ds.targets("readings")
    assert y.shape == (40, 2)
    # the label is a function of the inputs alone: the least input and the number holding it
    np.testing.assert_array_equal(y[:, 0], ds.inputs.min(axis=1))
    np.testing.assert_array_equal(y[:, 1], ds.inputs.argmin(axis=1) + 1)
    np.testing.assert_array_equal(ds.inputs[np.arange(40), y[:, 1].astype(int) - 1], y[:, 0])
    # the inputs are the adapted readings, so these are not the raw min/argmin everywhere
    assert np.any(y[:, 0] != ds.baseline_distance)
    assert not np.array_equal(y, ds.targets("geometry"))
    with pytest.raises(ValueError, match="targets: 'truth'"):
        ds.targets("truth")


@settings(max_examples=60, deadline=None)
@given(
    hnp.arrays(
        np.float64,
        hnp.array_shapes(min_dims=2, max_dims=2, min_side=1, max_side=12).map(lambda s: (s[0], 9)),
        elements=st.floats(0.0, 8.0),
    )
)
def test_reading_targets_pick_the_first_least_input(x: np.ndarray) -> None:
    y = reading_targets(x)
    for row, (d, i) in zip(x, y, strict=True):
        k = int(i) - 1
        assert 0 <= k < 9 and row[k] == d == row.min()
        assert np.all(row[:k] > d)  # the first input holding the least value (ties: the lowest)
