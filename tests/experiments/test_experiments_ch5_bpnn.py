"""Chapter 5's BPNN experiment (:mod:`uvnav.experiments.ch5_bpnn`): cached data sets that continue
the same random stream, learning rows as stages, beam ties, the model keys."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from uvnav.bench.stages import StageCache, StaleStageError
from uvnav.experiments import ch5_bpnn as b5
from uvnav.experiments.ch5_bpnn import cached_dataset
from uvnav.sensors.sonar_dataset import sample_sonar_dataset


def _cache(results: Path, fingerprint: str = "a" * 16, **kw: Any) -> StageCache:
    return StageCache(results, fingerprint, **kw)


def _stage_names(results: Path) -> list[str]:
    return [s["name"] for s in _cache(results).stored()]


def test_cached_dataset_resumes_the_same_data_and_random_stream(tmp_path: Path) -> None:
    ds, rng = cached_dataset(4, 123, _cache(tmp_path))
    assert _stage_names(tmp_path) == ["ch5-data-n4-r123"]
    cache = _cache(tmp_path)
    again, rng2 = cached_dataset(4, 123, cache)  # read back, nothing sampled
    assert (cache.reused, cache.built) == (["ch5-data-n4-r123"], [])
    np.testing.assert_array_equal(again.ranges, ds.ranges)
    np.testing.assert_array_equal(again.target_index, ds.target_index)
    # one uninterrupted run: sample, then continue with the same generator
    ref_rng = np.random.default_rng(123)
    ref = sample_sonar_dataset(4, ref_rng, subdivisions=b5.DATA_SUBDIVISIONS)
    np.testing.assert_array_equal(ref.ranges, ds.ranges)
    expect = ref_rng.random(3)
    np.testing.assert_array_equal(rng.random(3), expect)
    np.testing.assert_array_equal(rng2.random(3), expect)


def test_learning_rows_are_stages_built_on_their_data_and_test_set(tmp_path: Path) -> None:
    pytest.importorskip("torch")
    from uvnav.learning.bpnn import BPNNConfig

    cfg = BPNNConfig(max_epochs=3)
    test, _ = cached_dataset(6, 7, _cache(tmp_path))
    row, model, _ = b5.learning_row(12, 0, test, cfg, cache=_cache(tmp_path))
    assert len(list(tmp_path.rglob("model.safetensors"))) == 1  # in the row's stage folder
    cache = _cache(tmp_path)
    again, back, _ = b5.learning_row(12, 0, test, cfg, cache=cache)
    assert cache.reused == ["ch5-data-n12-r10000", "ch5-row-n12-s0-plain"]  # nothing trained
    assert cache.built == []
    assert again == json.loads(json.dumps(row, default=b5.json_default))
    np.testing.assert_array_equal(back.predict(test.inputs), model.predict(test.inputs))
    # another independent test set: the row is measured again on the same data
    other, _ = cached_dataset(6, 8, _cache(tmp_path))
    cache = _cache(tmp_path)
    b5.learning_row(12, 0, other, cfg, cache=cache)
    assert (cache.reused, cache.built) == (["ch5-data-n12-r10000"], ["ch5-row-n12-s0-plain"])
    # the data set sampled again (its stage lost): the row built on it is trained again too
    for f in (tmp_path / "stages").glob("*/stage.json"):
        if json.loads(f.read_text())["name"] == "ch5-data-n12-r10000":
            shutil.rmtree(f.parent)
    cache = _cache(tmp_path)
    b5.learning_row(12, 0, other, cfg, cache=cache)
    assert cache.reused == [] and cache.built == ["ch5-data-n12-r10000", "ch5-row-n12-s0-plain"]


def test_a_stage_of_other_code_is_refused_and_fresh_rebuilds_it(tmp_path: Path) -> None:
    pytest.importorskip("torch")
    from uvnav.learning.bpnn import BPNNConfig

    cfg = BPNNConfig(max_epochs=3)
    test, _ = cached_dataset(6, 7, None)
    first, _, _ = b5.learning_row(12, 0, test, cfg, cache=_cache(tmp_path, "a" * 16))
    # another code fingerprint: refused in one line naming the stage, nothing trained
    with pytest.raises(StaleStageError) as err:
        b5.learning_row(12, 0, test, cfg, cache=_cache(tmp_path, "b" * 16))
    msg = str(err.value)
    assert "\n" not in msg and "'ch5-data-n12-r10000'" in msg and "--fresh" in msg
    fresh = _cache(tmp_path, "b" * 16, fresh=True)
    again, _, _ = b5.learning_row(12, 0, test, cfg, cache=fresh)
    assert fresh.reused == [] and fresh.built == ["ch5-data-n12-r10000", "ch5-row-n12-s0-plain"]
    stored = sorted((s["name"], s["fingerprint"]) for s in _cache(tmp_path).stored())
    # the data set remade in place; the row on it has new inputs (the data's new id), so the
    # old row stays under its old key, never reused
    assert stored == [("ch5-data-n12-r10000", "b" * 16), ("ch5-row-n12-s0-plain", "a" * 16),
                      ("ch5-row-n12-s0-plain", "b" * 16)]  # fmt: skip
    drop = ("train_seconds",)  # the same seeds: the same row
    assert {k: v for k, v in again.items() if k not in drop} == {
        k: v for k, v in first.items() if k not in drop
    }


def test_the_literal_experiments_rows_are_stages_of_their_own(tmp_path: Path) -> None:
    pytest.importorskip("torch")
    from uvnav.learning.bpnn import BPNNConfig

    cfg = BPNNConfig(max_epochs=3)
    test, _ = cached_dataset(6, 7, None)
    geo, _, _ = b5.learning_row(20, 0, test, cfg, cache=_cache(tmp_path))
    cache = _cache(tmp_path)
    row, model, ds = b5.learning_row(20, 0, test, cfg, cache=cache, target_kind="readings")
    assert cache.reused == ["ch5-data-n20-r10000"]  # the same data, a new row (its own stage)
    assert cache.built == ["ch5-row-n20-s0-plain-readings"]
    assert (row["targets"], model.target_kind, geo["targets"]) == ("readings",) * 2 + ("geometry",)
    assert row["division"] == [14, 3, 3]  # dividerand: round(0.15 * 20) = 3
    # its errors are against min/argmin of the inputs
    grp = model.split["test"]
    err = ds.inputs[grp].min(axis=1) - model.predict(ds.inputs[grp])[:, 0]
    assert row["test_group"]["network"]["distance"]["lo"] == pytest.approx(err.min())
    cache = _cache(tmp_path)
    b5.learning_row(20, 0, test, cfg, cache=cache, target_kind="readings")
    b5.learning_row(20, 0, test, cfg, cache=cache)
    assert cache.reused == ["ch5-data-n20-r10000", "ch5-row-n20-s0-plain-readings",
                            "ch5-data-n20-r10000", "ch5-row-n20-s0-plain"]  # fmt: skip


def test_beam_ties_names_the_samples_whose_true_sensor_is_not_argmin() -> None:
    ranges = np.full((3, 9), 8.0)
    ranges[0, 0] = 2.0  # S1 nearest, and it is the true sensor
    ranges[1, [1, 8]] = [1.076, 1.077]  # argmin S2, but the true point is in S9's beam
    ranges[2, 4] = 3.0
    ds = b5.SonarDataset(
        ranges=ranges,
        inputs=ranges,
        target_distance=np.array([1.9, 1.05, 2.9]),
        target_index=np.array([1, 9, 5]),
        baseline_distance=ranges.min(axis=1),
        baseline_index=np.argmin(ranges, axis=1) + 1,
    )
    predicted = np.array([[1.9, 1.2], [1.05, 2.0], [2.9, 4.9]])
    ties = b5.beam_ties(ds, np.arange(3), predicted)
    assert ties["n"] == 1
    assert ties["max_reading_gap"] == pytest.approx(0.001)
    assert ties["index_error_others"] == pytest.approx([-0.2, 0.1])
    only_tie = b5.beam_ties(ds, np.array([1]), predicted[[1]])["index_error_others"]
    assert all(np.isnan(only_tie))


def test_model_keys_name_every_variant_and_nothing_else() -> None:
    assert b5.split_model_key("n150") == (150, "plain")
    assert b5.split_model_key("n150r") == (150, "residual")
    assert b5.split_model_key("n5000h") == (5000, "residual-huber")
    assert b5.split_model_key("n50p") == (50, "plain-huber")
    for other in ("closed_loop", "episodes", "n", "nx", "n150rh", "x150"):
        assert b5.split_model_key(other) is None
    for variant, suffix in b5.VARIANT_KEYS.items():  # every config variant has a key and label
        assert b5.split_model_key(f"n7{suffix}") == (7, variant)
        assert variant in b5.VARIANT_LABELS
    from uvnav.experiments.sections import _ch5_caption

    caption = _ch5_caption(Path("ch5_errors_n150h_independent.png"))
    assert "150-sample residual (Huber loss) network on the independent test set" in caption
