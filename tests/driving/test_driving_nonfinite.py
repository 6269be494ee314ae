"""Driving logs and dataset.json: NaN/±inf where a finite number is meant is refused (issue 17)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from uvnav.driving.collect import META_NAME, dataset_meta
from uvnav.driving.dataset import LOG_NAME, DatasetError, LogWriter, read_log


def _img() -> np.ndarray:
    return np.zeros((8, 8, 3), dtype=np.uint8)


def _log(tmp_path: Path, rows: int = 3) -> list[list[str]]:
    """A small log written by :class:`LogWriter`; its rows as CSV fields."""
    w = LogWriter(tmp_path)
    for k in range(rows):
        w.write(
            f"k{k}",
            (_img(), _img(), _img()),
            steering=0.1,
            throttle=0.5,
            brake=0.0,
            speed=10.0,
            target_speed=30.0,
            side_steering=(0.2, 0.0),
        )
    w.close()
    return [ln.split(",") for ln in (tmp_path / LOG_NAME).read_text().splitlines()]


def _rewrite(tmp_path: Path, rows: list[list[str]]) -> None:
    (tmp_path / LOG_NAME).write_text("".join(",".join(r) + "\n" for r in rows))


@pytest.mark.parametrize(
    ("column", "index", "value"),
    [
        ("steering", 3, "nan"),
        ("throttle", 4, "NaN"),
        ("brake", 5, "inf"),
        ("speed", 6, "-inf"),
        ("target_speed", 7, "inf"),
        ("steering_left", 8, "-Infinity"),
    ],
)
def test_a_non_finite_value_is_refused_naming_file_row_and_column(
    tmp_path: Path, column: str, index: int, value: str
) -> None:
    rows = _log(tmp_path)
    rows[1][index] = value
    _rewrite(tmp_path, rows)
    with pytest.raises(DatasetError) as info:
        read_log(tmp_path)
    msg = str(info.value)
    assert LOG_NAME in msg and "row 2" in msg and f"column '{column}'" in msg
    assert "not a finite number" in msg and "\n" not in msg


def test_nan_in_an_optional_column_still_means_no_value(tmp_path: Path) -> None:
    rows = _log(tmp_path)
    rows[0][7] = "nan"  # what LogWriter writes when the target speed is unknown
    _rewrite(tmp_path, rows)
    log = read_log(tmp_path)
    assert log.target_speed is not None
    assert math.isnan(log.target_speed[0]) and log.target_speed[1] == 30.0


def test_writer_refuses_a_non_finite_label_and_writes_nothing(tmp_path: Path) -> None:
    w = LogWriter(tmp_path)
    with pytest.raises(DatasetError, match=r"column 'steering'.*not a finite number"):
        w.write(
            "a", (_img(), _img(), _img()), steering=math.nan, throttle=0.0, brake=0.0, speed=1.0
        )
    w.close()
    assert (tmp_path / LOG_NAME).read_text() == ""
    assert not list((tmp_path / "IMG").iterdir())


def test_dataset_json_with_a_non_finite_number_is_refused(tmp_path: Path) -> None:
    (tmp_path / META_NAME).write_text('{"camera": "front", "fov_deg": NaN, "height": 66}')
    with pytest.raises(DatasetError, match=r"dataset\.json: field 'fov_deg'.*not a finite"):
        dataset_meta(tmp_path)
    (tmp_path / META_NAME).write_text(json.dumps({"camera": "front", "height": 66}))
    assert dataset_meta(tmp_path)["fov_deg"] == 90.0
