"""Udacity-layout dataset: reader/writer, camera expansion, balancing, split."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uvnav.driving.dataset import (
    DatasetError,
    LogWriter,
    balance_indices,
    expand_cameras,
    load_images,
    read_log,
    split_indices,
    steering_histogram,
)


def _img(v: int) -> np.ndarray:
    return np.full((66, 200, 3), v, dtype=np.uint8)


def test_write_then_read_round_trip(tmp_path) -> None:
    w = LogWriter(tmp_path)
    for k in range(3):
        w.write(
            f"k{k}",
            (_img(10), _img(20), _img(30)),
            steering=0.1 * k,
            throttle=0.5,
            brake=0.0,
            speed=12.0,
        )
    w.close()
    log = read_log(tmp_path)
    assert len(log) == 3
    assert np.allclose(log.steering, [0.0, 0.1, 0.2])
    assert all(p.is_file() for p in log.center + log.left + log.right)
    imgs = load_images(log.left[:2])
    assert imgs.shape == (2, 66, 200, 3)
    assert abs(float(imgs.mean()) - 20) < 2  # JPEG keeps a flat image flat


def test_reads_udacity_rows_with_absolute_windows_paths(tmp_path) -> None:
    from PIL import Image

    (tmp_path / "IMG").mkdir()
    for name in ("center_1.jpg", "left_1.jpg", "right_1.jpg"):
        Image.fromarray(np.zeros((160, 320, 3), dtype=np.uint8)).save(tmp_path / "IMG" / name)
    (tmp_path / "driving_log.csv").write_text(
        "C:\\Users\\me\\sim\\IMG\\center_1.jpg, C:\\Users\\me\\sim\\IMG\\left_1.jpg,"
        " C:\\Users\\me\\sim\\IMG\\right_1.jpg, -0.25, 0.9, 0, 30.1\n"
    )
    log = read_log(tmp_path)
    assert log.center[0].name == "center_1.jpg" and log.steering[0] == -0.25
    # 160x320 Udacity frames are cropped and resized to the network's 66x200
    assert load_images(log.center).shape == (1, 66, 200, 3)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("a.jpg,b.jpg,c.jpg,0.1,0.2\n", "row 1: 5 columns"),
        ("IMG/x.jpg,IMG/x.jpg,IMG/x.jpg,abc,0,0,0\n", "image 'x.jpg' not found"),
    ],
)
def test_bad_logs_give_one_line_naming_file_row_and_field(tmp_path, text: str, match: str) -> None:
    (tmp_path / "driving_log.csv").write_text(text)
    with pytest.raises(DatasetError, match=match) as info:
        read_log(tmp_path)
    assert "driving_log.csv" in str(info.value) and "\n" not in str(info.value)


def test_bad_number_names_the_column(tmp_path) -> None:
    w = LogWriter(tmp_path)
    w.write("a", (_img(1), _img(1), _img(1)), steering=0.0, throttle=0.0, brake=0.0, speed=0.0)
    w.close()
    row = (tmp_path / "driving_log.csv").read_text().split(",")
    row[4] = "fast"
    (tmp_path / "driving_log.csv").write_text(",".join(row))
    with pytest.raises(DatasetError, match="column 'throttle'"):
        read_log(tmp_path)


def test_side_cameras_get_the_steering_correction(tmp_path) -> None:
    w = LogWriter(tmp_path)
    w.write("a", (_img(1), _img(2), _img(3)), steering=0.1, throttle=0.3, brake=0.0, speed=5.0)
    w.write("b", (_img(1), _img(2), _img(3)), steering=0.95, throttle=0.3, brake=0.0, speed=5.0)
    w.close()
    s = expand_cameras(read_log(tmp_path), correction=0.2)
    assert len(s) == 6
    assert np.allclose(s.steering, [0.1, 0.95, 0.3, 1.0, -0.1, 0.75])  # left +, right −, clipped
    assert [p.name.split("_")[0] for p in s.paths] == ["center"] * 2 + ["left"] * 2 + ["right"] * 2
    assert len(expand_cameras(read_log(tmp_path), sides=False)) == 2


@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.floats(-1.5, 1.5, allow_nan=False), min_size=1, max_size=3000),
    st.integers(1, 300),
    st.integers(1, 40),
)
def test_balancing_caps_every_bin(values: list[float], cap: int, n_bins: int) -> None:
    s = np.asarray(values)
    keep = balance_indices(s, np.random.default_rng(0), n_bins=n_bins, max_per_bin=cap)
    before, _ = steering_histogram(s, n_bins=n_bins)
    after, _ = steering_histogram(s[keep], n_bins=n_bins)
    assert after.max() <= cap
    assert np.array_equal(after, np.minimum(before, cap))  # only full bins lose samples
    assert len(np.unique(keep)) == len(keep)


def test_balancing_at_200_on_a_peaked_distribution() -> None:
    rng = np.random.default_rng(1)
    s = np.concatenate([np.zeros(5000), rng.uniform(-1, 1, 1000)])
    keep = balance_indices(s, rng)
    counts, _ = steering_histogram(s[keep])
    assert counts.max() == 200 and len(keep) < 1400


def test_split_is_8_to_2_disjoint_and_complete() -> None:
    tr, va = split_indices(1499, np.random.default_rng(0))
    assert (len(tr), len(va)) == (1199, 300)  # the thesis's counts
    assert set(tr).isdisjoint(va) and set(tr) | set(va) == set(range(1499))
    tr2, _ = split_indices(1499, np.random.default_rng(0))
    assert np.array_equal(tr, tr2)


def test_target_speed_column_is_optional_and_udacity_rows_still_load(tmp_path) -> None:
    w = LogWriter(tmp_path)
    w.write("a", (_img(1), _img(2), _img(3)), steering=0.1, throttle=0.3, brake=0.0, speed=5.0)
    w.close()
    plain = read_log(tmp_path)
    assert plain.target_speed is None  # seven columns, as Udacity's recorder writes
    assert expand_cameras(plain).target_speed is None
    w = LogWriter(tmp_path)  # resumed with the 8th column (e.g. DAgger rows)
    w.write(
        "b",
        (_img(1), _img(2), _img(3)),
        steering=0.2,
        throttle=0.3,
        brake=0.0,
        speed=5.0,
        target_speed=42.5,
    )
    w.close()
    lines = (tmp_path / "driving_log.csv").read_text().splitlines()
    assert [len(x.split(",")) for x in lines] == [7, 8]
    log = read_log(tmp_path)
    assert log.target_speed is not None
    assert np.isnan(log.target_speed[0]) and log.target_speed[1] == 42.5
    s = expand_cameras(log, correction=0.2)
    assert s.target_speed is not None and len(s.target_speed) == 6
    assert np.allclose(s.target_speed[[1, 3, 5]], 42.5)  # side cameras keep the target speed
    assert np.allclose(s.take(np.array([3])).target_speed, [42.5])


def test_bad_target_speed_names_the_column(tmp_path) -> None:
    (tmp_path / "IMG").mkdir()
    from PIL import Image

    Image.fromarray(_img(1)).save(tmp_path / "IMG" / "c.jpg")
    (tmp_path / "driving_log.csv").write_text("IMG/c.jpg,IMG/c.jpg,IMG/c.jpg,0,0,0,0,fast\n")
    with pytest.raises(DatasetError, match="column 'target_speed'"):
        read_log(tmp_path)
    (tmp_path / "driving_log.csv").write_text("IMG/c.jpg,IMG/c.jpg,IMG/c.jpg,0,0,0,0,1,2\n")
    with pytest.raises(DatasetError, match="row 1: 9 columns"):
        read_log(tmp_path)


def test_exact_side_labels_replace_the_correction_where_a_row_has_them(tmp_path) -> None:
    w = LogWriter(tmp_path)
    w.write("a", (_img(1), _img(2), _img(3)), steering=0.1, throttle=0.3, brake=0.0, speed=5.0)
    w.write(
        "b",
        (_img(1), _img(2), _img(3)),
        steering=0.1,
        throttle=0.3,
        brake=0.0,
        speed=5.0,
        side_steering=(0.45, -0.05),
    )
    w.write(
        "c",
        (_img(1), _img(2), _img(3)),
        steering=-0.2,
        throttle=0.3,
        brake=0.0,
        speed=5.0,
        target_speed=30.0,
        side_steering=(0.05, -0.6),
    )
    w.close()
    lines = (tmp_path / "driving_log.csv").read_text().splitlines()
    assert [len(x.split(",")) for x in lines] == [7, 10, 10]
    log = read_log(tmp_path)
    assert log.target_speed is not None and np.isnan(log.target_speed[:2]).all()
    assert log.steering_left is not None and log.steering_right is not None
    assert np.isnan(log.steering_left[0]) and log.steering_left[1:].tolist() == [0.45, 0.05]
    s = expand_cameras(log, correction=0.2)
    # centre a, b, c; left a (0.1 + 0.2: no exact label), b, c; right a, b, c
    assert np.allclose(s.steering, [0.1, 0.1, -0.2, 0.3, 0.45, 0.05, -0.1, -0.05, -0.6])
    assert s.camera is not None and s.camera.tolist() == [0] * 3 + [1] * 3 + [2] * 3
    assert s.take(np.array([4, 8])).camera.tolist() == [1, 2]
    fixed = expand_cameras(log, correction=0.2, exact_sides=False)  # the thesis's recipe
    assert np.allclose(fixed.steering[3:], [0.3, 0.3, 0.0, -0.1, -0.1, -0.4])
    (tmp_path / "driving_log.csv").write_text(lines[2].rsplit(",", 1)[0] + ",left\n")
    with pytest.raises(DatasetError, match="column 'steering_right'"):
        read_log(tmp_path)


@pytest.mark.parametrize(
    ("column", "value", "shown"),
    [
        (3, "1e308", "1e+308 is outside its range [-1, 1]"),
        (5, "-0.5", "-0.5 is outside its range [0, 1]"),
    ],
)
def test_a_label_outside_its_physical_range_is_refused(
    tmp_path, column: int, value: str, shown: str
) -> None:
    w = LogWriter(tmp_path)
    w.write("a", (_img(1), _img(1), _img(1)), steering=1.0, throttle=-1.0, brake=1.0, speed=0.0)
    w.close()
    assert len(read_log(tmp_path)) == 1  # the ends of the ranges are labels
    row = (tmp_path / "driving_log.csv").read_text().split(",")
    row[column] = value
    (tmp_path / "driving_log.csv").write_text(",".join(row))
    with pytest.raises(DatasetError, match=rf"row 1, column '\w+': {re.escape(shown)}$"):
        read_log(tmp_path)
