"""Sonar dataset (thesis Ch. 5 §5.4): true-geometry targets, min/argmin baseline, determinism."""

from __future__ import annotations

import numpy as np
import pytest

from uvnav.sensors.sonar_array import SonarArray, adapted_ranges
from uvnav.sensors.sonar_dataset import SonarDataset, sample_sonar_dataset


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
