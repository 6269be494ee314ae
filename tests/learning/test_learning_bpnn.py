"""BPNN (thesis Ch. 5 Figs. 5.1/5.4): training with early stopping, safe checkpoints."""

from __future__ import annotations

import json
import pickle
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("torch")
pytest.importorskip("safetensors")

from hypothesis import given
from hypothesis import strategies as st

from uvnav.learning import bpnn
from uvnav.learning.bpnn import (
    HUBER_DELTA,
    VARIANTS,
    BPNNConfig,
    CheckpointError,
    error_table,
    load_checkpoint,
    save_checkpoint,
    split_indices,
    split_sizes,
    train_bpnn,
    variant_config,
)
from uvnav.sensors.sonar_dataset import SonarDataset, sample_sonar_dataset


@pytest.fixture(scope="module")
def data() -> tuple[SonarDataset, SonarDataset]:
    return (
        sample_sonar_dataset(120, np.random.default_rng(1), subdivisions=1),
        sample_sonar_dataset(100, np.random.default_rng(2), subdivisions=1),
    )


def test_split_is_random_disjoint_and_complete() -> None:
    tr, va, te = split_indices(50, np.random.default_rng(0), (0.7, 0.15, 0.15))
    assert (len(tr), len(va), len(te)) == (34, 8, 8)
    assert sorted(np.concatenate([tr, va, te]).tolist()) == list(range(50))


def test_split_proportions_are_the_toolboxs_dividerand() -> None:
    # MATLAB's dividerand: round(0.15 n) for validation and test, halves away from zero
    # (150 -> 22.5 -> 23; Python's round would give 22), training the rest
    assert split_sizes(50, (0.7, 0.15, 0.15)) == (34, 8, 8)
    assert split_sizes(150, (0.7, 0.15, 0.15)) == (104, 23, 23)
    assert split_sizes(500, (0.7, 0.15, 0.15)) == (350, 75, 75)
    assert BPNNConfig().fractions == (0.7, 0.15, 0.15)  # the toolbox's default the thesis used
    tr, va, te = split_indices(150, np.random.default_rng(1), (0.7, 0.15, 0.15))
    assert (len(tr), len(va), len(te)) == (104, 23, 23)
    with pytest.raises(ValueError, match="too few samples"):
        split_sizes(2, (0.7, 0.15, 0.15))


@given(st.integers(3, 10_000))
def test_split_sizes_round_each_group_to_its_share(n: int) -> None:
    n_train, n_val, n_test = split_sizes(n, (0.7, 0.15, 0.15))
    assert n_train + n_val + n_test == n
    for k in (n_val, n_test):
        assert k >= 1 and (abs(k - 0.15 * n) < 0.5 or k - 0.15 * n == 0.5 or k == 1)


def test_variants_by_name() -> None:
    assert [variant_config(v).variant for v in VARIANTS] == list(VARIANTS)
    assert variant_config("residual-huber").huber_delta == HUBER_DELTA > 0
    assert not variant_config("plain").residual
    assert variant_config("residual", max_epochs=3).max_epochs == 3
    with pytest.raises(ValueError, match="variant: 'deep'"):
        variant_config("deep")


def test_network_learns_a_smooth_map_far_below_its_initial_error() -> None:
    rng = np.random.default_rng(0)
    x = rng.uniform(0, 5, (120, 9))
    y = np.stack([x.min(axis=1) * 0 + np.sin(x[:, 0]) + x[:, 1], x[:, 2] * 0.5], axis=1)
    m = train_bpnn(x, y, np.random.default_rng(1), BPNNConfig(hidden=(10,), max_epochs=20))
    err = np.abs(m.predict(x) - y).mean()
    assert err < 0.05 * np.abs(y - y.mean(axis=0)).mean()
    assert m.stop_reason in ("validation_stop", "max_epochs", "min_error")
    assert 1 <= m.best_epoch <= len(m.history["val"])
    # the kept weights are those of the best validation epoch
    assert min(m.history["val"]) == pytest.approx(m.history["val"][m.best_epoch - 1])


def test_same_seed_same_network(data: tuple[SonarDataset, SonarDataset]) -> None:
    ds, _ = data
    a = train_bpnn(ds.inputs, ds.targets(), np.random.default_rng(5), BPNNConfig(max_epochs=5))
    b = train_bpnn(ds.inputs, ds.targets(), np.random.default_rng(5), BPNNConfig(max_epochs=5))
    np.testing.assert_array_equal(a.predict(ds.inputs), b.predict(ds.inputs))


def test_residual_network_beats_the_min_argmin_baseline_on_distance(
    data: tuple[SonarDataset, SonarDataset],
) -> None:
    ds, test = data
    cfg = BPNNConfig(residual=True)
    m = train_bpnn(ds.inputs, ds.targets(), np.random.default_rng(0), cfg, offset=ds.baseline())
    table = error_table(m.predict(test.inputs, test.baseline()), test.targets(), test.baseline())
    assert table["network"]["distance"]["mae"] < table["baseline"]["distance"]["mae"]
    with pytest.raises(ValueError, match="offset"):
        m.predict(test.inputs)


def test_huber_loss_keeps_a_few_wild_labels_from_pulling_the_others() -> None:
    # a residual task whose correction is 0 except 3 % of labels shifted by 5 to 8 (like the
    # beam ties of the sensor index): the robust loss fits the clean samples far better
    rng = np.random.default_rng(3)
    x = rng.uniform(0, 5, (200, 9))
    offset = np.stack([x.min(axis=1), np.argmin(x, axis=1) + 1.0], axis=1)
    y = offset.copy()
    wild = rng.choice(200, 6, replace=False)
    y[wild, 1] += rng.uniform(5, 8, 6)
    clean = np.setdiff1d(np.arange(200), wild)
    worst = {}
    for delta in (0.0, 0.02):
        cfg = BPNNConfig(residual=True, huber_delta=delta)
        assert cfg.variant == ("residual-huber" if delta else "residual")
        m = train_bpnn(x, y, np.random.default_rng(4), cfg, offset=offset)
        worst[delta] = float(np.abs(m.predict(x, offset)[clean, 1] - y[clean, 1]).max())
    assert worst[0.02] < 0.1 < worst[0.0]
    with pytest.raises(ValueError, match="huber_delta"):
        BPNNConfig(huber_delta=-1.0)


def test_adam_option_trains(data: tuple[SonarDataset, SonarDataset]) -> None:
    ds, _ = data
    m = train_bpnn(
        ds.inputs,
        ds.targets(),
        np.random.default_rng(0),
        BPNNConfig(optimizer="adam", max_epochs=50, learning_rate=0.05),
    )
    assert m.history["train"][-1] < m.history["train"][0]
    with pytest.raises(ValueError, match="optimizer"):
        BPNNConfig(optimizer="sgd")


def test_checkpoint_round_trip(tmp_path: Path, data: tuple[SonarDataset, SonarDataset]) -> None:
    ds, _ = data
    m = train_bpnn(ds.inputs, ds.targets(), np.random.default_rng(0), BPNNConfig(max_epochs=5))
    path, js = save_checkpoint(m, tmp_path / "net")
    assert path.suffix == ".safetensors" and js.suffix == ".json"
    back = load_checkpoint(path)
    np.testing.assert_array_equal(back.predict(ds.inputs), m.predict(ds.inputs))
    assert back.config == m.config
    assert back.target_kind == "geometry"
    np.testing.assert_array_equal(back.split["test"], m.split["test"])


def test_a_checkpoint_keeps_what_its_network_learnt(
    tmp_path: Path, data: tuple[SonarDataset, SonarDataset]
) -> None:
    ds, _ = data
    cfg = variant_config("residual-huber", max_epochs=3)
    y = ds.targets("readings")
    m = train_bpnn(
        ds.inputs, y, np.random.default_rng(0), cfg, offset=ds.baseline(), target_kind="readings"
    )
    back = load_checkpoint(save_checkpoint(m, tmp_path / "net")[0])
    assert (back.variant, back.target_kind) == ("residual-huber", "readings")
    np.testing.assert_array_equal(
        back.predict(ds.inputs, ds.baseline()), m.predict(ds.inputs, ds.baseline())
    )
    header = json.loads((tmp_path / "net.json").read_text())
    header["record"]["target_kind"] = "vibes"
    from uvnav.learning.checkpoint import write_checkpoint

    arrays = {k: np.asarray(v) for k, v in bpnn._model_arrays(m).items()}
    write_checkpoint(
        tmp_path / "bad.safetensors", arrays, kind="bpnn", config=header["config"],
        record=header["record"],
    )  # fmt: skip
    with pytest.raises(CheckpointError, match="target_kind 'vibes'"):
        load_checkpoint(tmp_path / "bad.safetensors")
    with pytest.raises(ValueError, match="target_kind"):
        train_bpnn(ds.inputs, y, np.random.default_rng(0), cfg, target_kind="vibes")


class _Evil:
    def __reduce__(self):  # type: ignore[no-untyped-def]
        return (Path.touch, (Path(self.marker),))  # type: ignore[attr-defined]


def test_a_malicious_pickle_is_refused_and_never_runs(tmp_path: Path) -> None:
    marker = tmp_path / "pwned"
    evil = _Evil()
    evil.marker = str(marker)  # type: ignore[attr-defined]
    payload = pickle.dumps(evil)
    # sanity: unpickling it WOULD run code
    pickle.loads(payload)
    assert marker.exists()
    marker.unlink()
    (tmp_path / "model.safetensors").write_bytes(payload)
    (tmp_path / "model.json").write_text('{"format": "uvnav-bpnn-v1"}')
    with pytest.raises(CheckpointError, match="not a safetensors checkpoint"):
        load_checkpoint(tmp_path / "model.safetensors")
    assert not marker.exists()
    with pytest.raises(CheckpointError, match="not found"):
        load_checkpoint(tmp_path / "missing")
