"""NaN/±inf never becomes a model: training stops, saving and loading refuse it (issue 17)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

torch = pytest.importorskip("torch")
pytest.importorskip("safetensors")

from uvnav.learning import PilotNetConfig, TrainConfig, bpnn  # noqa: E402
from uvnav.learning.checkpoint import (  # noqa: E402
    NonFiniteWeightsError,
    load_checkpoint,
    save_checkpoint,
)
from uvnav.learning.pilotnet import build_pilotnet  # noqa: E402
from uvnav.learning.train import NonFiniteTrainingError, Predictor, train_pilotnet  # noqa: E402

H, W = 48, 96
SMALL = PilotNetConfig(height=H, width=W, dropout=0.0)


def _data(n: int = 20) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(0)
    imgs = rng.integers(0, 255, (n, H, W, 3), dtype=np.uint8)
    return imgs, rng.uniform(-0.5, 0.5, n), rng.uniform(0, 1, n), rng.uniform(5, 50, n)


def _poisoned(model: object) -> object:
    with torch.no_grad():
        model.head[-1].bias[0] = float("nan")  # type: ignore[attr-defined]
    return model


@pytest.mark.parametrize(("part", "index"), [("steering", 1), ("speed", 3)])
def test_a_nan_label_or_speed_stops_training_before_it_starts(part: str, index: int) -> None:
    arrays = list(_data())
    arrays[index] = arrays[index].copy()
    arrays[index][7] = np.nan
    with pytest.raises(NonFiniteTrainingError, match=f"training {part}: 1 of 20.*sample 7"):
        train_pilotnet(
            tuple(arrays),  # type: ignore[arg-type]
            None,
            net=SMALL,
            config=TrainConfig(epochs=1, batch_size=10, augment=False),
        )


def test_a_diverging_loss_stops_training_with_a_clear_error(tmp_path: Path) -> None:
    state = tmp_path / "state.safetensors"
    model = _poisoned(build_pilotnet(SMALL))
    with pytest.raises(NonFiniteTrainingError, match="diverged in epoch 1: the loss is nan"):
        train_pilotnet(
            _data(),
            None,
            model=model,
            config=TrainConfig(epochs=2, batch_size=10, augment=False),
            resume=state,
        )
    assert not state.exists()  # no state of a diverged epoch to continue from


def test_a_network_with_nan_weights_is_never_saved(tmp_path: Path) -> None:
    out = tmp_path / "m.safetensors"
    with pytest.raises(NonFiniteWeightsError, match=r"head\.\d+\.bias: 1 of \d+ values"):
        save_checkpoint(_poisoned(build_pilotnet(SMALL)), out)
    assert not out.exists() and not out.with_suffix(".json").exists()


def test_a_checkpoint_with_nan_weights_is_refused_at_load(tmp_path: Path) -> None:
    out = save_checkpoint(build_pilotnet(SMALL), tmp_path / "m.safetensors")
    from safetensors import safe_open
    from safetensors.torch import save_file

    with safe_open(str(out), framework="pt") as fh:
        meta = fh.metadata()
        state = {k: fh.get_tensor(k) for k in fh.keys()}  # noqa: SIM118
    name = next(k for k in state if k.endswith("bias"))
    state[name][0] = float("inf")
    save_file(state, str(out), metadata=meta)
    with pytest.raises(NonFiniteWeightsError, match=rf"m\.safetensors: {name}: 1 of"):
        load_checkpoint(out)


def test_record_values_that_are_missing_are_written_as_json_null(tmp_path: Path) -> None:
    out = save_checkpoint(
        build_pilotnet(SMALL), tmp_path / "m.safetensors", record={"val_throttle_mse": [np.nan]}
    )
    text = out.with_suffix(".json").read_text()
    assert "NaN" not in text and '"val_throttle_mse": [\n      null' in text


def test_predictor_refuses_a_non_finite_output() -> None:
    pred = Predictor(build_pilotnet(SMALL))
    frame = np.zeros((H, W, 3), dtype=np.uint8)
    with pytest.raises(ValueError, match=r"output .* is not finite"):
        pred.outputs(frame, float("nan"))


# ------------------------------------------------------------------------------------- BPNN


def _bpnn_data(n: int = 40) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(1)
    x = rng.uniform(0.5, 8.0, (n, 9))
    return x, np.stack([x.min(axis=1), x.argmin(axis=1) + 1.0], axis=1)


def test_bpnn_refuses_nan_in_its_data() -> None:
    x, y = _bpnn_data()
    x[3, 4] = np.nan
    with pytest.raises(bpnn.NonFiniteError, match=r"inputs\[3, 4\] = nan is not a finite"):
        bpnn.train_bpnn(x, y, np.random.default_rng(0), bpnn.BPNNConfig(max_epochs=2))


def test_bpnn_divergence_is_an_error_not_a_model() -> None:
    x, y = _bpnn_data()
    cfg = bpnn.BPNNConfig(optimizer="adam", learning_rate=1e200, max_epochs=20)
    with pytest.raises(bpnn.NonFiniteError, match="training diverged at epoch"):
        bpnn.train_bpnn(x, y, np.random.default_rng(0), cfg)


def test_bpnn_checkpoint_with_nan_is_neither_saved_nor_loaded(tmp_path: Path) -> None:
    x, y = _bpnn_data()
    model = bpnn.train_bpnn(x, y, np.random.default_rng(0), bpnn.BPNNConfig(max_epochs=2))
    st, _ = bpnn.save_checkpoint(model, tmp_path / "good")
    model.x_lo = model.x_lo.copy()
    model.x_lo[2] = np.nan
    with pytest.raises(bpnn.NonFiniteError, match=r"x_lo\[2\] = nan"):
        bpnn.save_checkpoint(model, tmp_path / "bad")
    assert not list(tmp_path.glob("bad*"))
    from safetensors import safe_open
    from safetensors.numpy import load_file, save_file

    with safe_open(str(st), framework="numpy") as fh:
        meta = fh.metadata()  # the header: kept, only a weight is changed
    arrays = load_file(str(st))
    arrays["layer0.weight"][1, 1] = np.inf
    save_file(arrays, str(st), metadata=meta)
    with pytest.raises(bpnn.CheckpointError, match=r"layer0\.weight\[1, 1\] = inf"):
        bpnn.load_checkpoint(st)
