"""A sonar dataset with NaN/±inf, a distance beyond 1000 km, an impossible sensor number or no
samples is refused."""

from __future__ import annotations

import numpy as np
import pytest

from uvnav.sensors.sonar_dataset import SonarDataset


def _arrays(n: int = 4) -> dict[str, np.ndarray]:
    ranges = np.linspace(1.0, 8.0, 9 * n).reshape(n, 9)
    return {
        "ranges": ranges,
        "inputs": ranges.copy(),
        "target_distance": ranges.min(axis=1) - 0.1,
        "target_index": np.ones(n, dtype=np.int64),
        "baseline_distance": ranges.min(axis=1),
        "baseline_index": np.ones(n, dtype=np.int64),
    }


@pytest.mark.parametrize(
    ("name", "where", "value", "expect"),
    [
        ("inputs", (2, 5), np.nan, "'inputs', row 2, column 5: nan is not a finite number"),
        ("ranges", (0, 0), np.inf, "'ranges', row 0, column 0: inf is not a finite number"),
        ("target_distance", (3,), -np.inf, "'target_distance', row 3: -inf is not a finite"),
        ("target_index", (1,), np.nan, "'target_index', row 1: nan is not a finite number"),
        ("baseline_index", (1,), 12, "'baseline_index', row 1: 12 is not a sensor number 1..9"),
        ("inputs", (1, 3), 1e300, r"'inputs', row 1, column 3: 1e\+300 is outside .* 1e\+06 m"),
    ],
)
def test_bad_values_are_refused_naming_array_and_row(
    name: str, where: tuple[int, ...], value: float, expect: str
) -> None:
    arrays = _arrays()
    a = arrays[name].astype(float) if np.isnan(value) else arrays[name].copy()
    a[where] = value
    arrays[name] = a
    with pytest.raises(ValueError, match=expect) as info:
        SonarDataset.from_arrays(arrays)
    assert "\n" not in str(info.value)


def test_finite_arrays_load() -> None:
    assert len(SonarDataset.from_arrays(_arrays())) == 4


def test_an_empty_dataset_is_refused() -> None:
    arrays = {k: v[:0] for k, v in _arrays().items()}
    with pytest.raises(ValueError, match=r"^dataset array 'ranges' has no samples \(0 rows\)$"):
        SonarDataset.from_arrays(arrays)
