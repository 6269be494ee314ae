"""The one checkpoint format (uvnav.learning.checkpoint): BPNN and CNN, legacy files."""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import asdict
from pathlib import Path

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from uvnav.learning import PilotNetConfig, bpnn  # noqa: E402
from uvnav.learning.checkpoint import (  # noqa: E402
    FORMAT,
    LEGACY_BPNN_FORMAT,
    CheckpointError,
    load_checkpoint,
    read_checkpoint,
    read_header,
    save_checkpoint,
)
from uvnav.learning.pilotnet import build_pilotnet  # noqa: E402

SMALL = PilotNetConfig(dropout=0.0)


def _bpnn_model() -> bpnn.TrainedBPNN:
    rng = np.random.default_rng(1)
    x = rng.uniform(0.5, 8.0, (30, 9))
    y = np.stack([x.min(axis=1), x.argmin(axis=1) + 1.0], axis=1)
    return bpnn.train_bpnn(x, y, np.random.default_rng(0), bpnn.BPNNConfig(max_epochs=3))


def _write_legacy_bpnn(model: bpnn.TrainedBPNN, base: Path) -> None:
    """The BPNN's writer before the one format (``uvnav-bpnn-v1``), kept verbatim in substance:
    a safetensors file without metadata, the header in the JSON file beside it."""
    from safetensors.numpy import save_file

    tensors = {"x_lo": model.x_lo, "x_hi": model.x_hi, "y_lo": model.y_lo, "y_hi": model.y_hi}
    for k, (w, b) in enumerate(model.weights):
        tensors[f"layer{k}.weight"] = w
        tensors[f"layer{k}.bias"] = b
    save_file(
        {k: np.asarray(v, dtype=np.float64) for k, v in tensors.items()},
        str(base.with_suffix(".safetensors")),
    )
    meta = {
        "format": "uvnav-bpnn-v1",
        "config": asdict(model.config),
        "n_layers": len(model.weights),
        "history": model.history,
        "best_epoch": model.best_epoch,
        "stop_reason": model.stop_reason,
        "split": {k: [int(i) for i in v] for k, v in model.split.items()},
    }
    base.with_suffix(".json").write_text(json.dumps(meta, indent=1))


def test_both_kinds_round_trip_through_the_one_format(tmp_path: Path) -> None:
    m = _bpnn_model()
    st, js = bpnn.save_checkpoint(m, tmp_path / "bpnn")
    torch.manual_seed(0)
    net = build_pilotnet(SMALL).eval()
    cnn = save_checkpoint(net, tmp_path / "cnn.safetensors", record={"val_loss": [0.5]})
    for path, kind in ((st, "bpnn"), (cnn, "pilotnet")):
        header = read_header(path)
        assert header["format"] == FORMAT and header["kind"] == kind
        assert json.loads(path.with_suffix(".json").read_text()) == header  # the copy
    assert read_header(tmp_path / "bpnn") == read_header(js)  # the stem, the copy: same header
    assert read_header(st)["record"]["best_epoch"] == m.best_epoch
    back = bpnn.load_checkpoint(st)
    x = np.random.default_rng(2).uniform(0.5, 8.0, (5, 9))
    np.testing.assert_array_equal(back.predict(x), m.predict(x))
    assert back.history == m.history and back.stop_reason == m.stop_reason
    np.testing.assert_array_equal(back.split["val"], m.split["val"])
    net2, header = load_checkpoint(cnn)
    assert header["record"] == {"val_loss": [0.5]}
    for k, v in net.state_dict().items():
        assert torch.equal(v, net2.state_dict()[k])
    # each loader refuses the other kind, in one line
    with pytest.raises(CheckpointError, match=r"cnn\.safetensors: a pilotnet checkpoint") as e:
        bpnn.load_checkpoint(cnn)
    assert "\n" not in str(e.value)
    with pytest.raises(CheckpointError, match=r"bpnn\.safetensors: a bpnn checkpoint"):
        load_checkpoint(st)
    assert not list(tmp_path.glob(".*"))  # no temporary files left


def test_an_old_format_bpnn_checkpoint_still_loads(tmp_path: Path) -> None:
    m = _bpnn_model()
    _write_legacy_bpnn(m, tmp_path / "old")
    header = read_header(tmp_path / "old.safetensors")
    assert header["format"] == LEGACY_BPNN_FORMAT and header["kind"] == "bpnn"
    back = bpnn.load_checkpoint(tmp_path / "old")
    x = np.random.default_rng(2).uniform(0.5, 8.0, (5, 9))
    np.testing.assert_array_equal(back.predict(x), m.predict(x))
    assert back.config == m.config and back.best_epoch == m.best_epoch
    np.testing.assert_array_equal(back.split["test"], m.split["test"])
    # the Ch. 5 digest covers the weights only: the same network in either format, same digest
    from uvnav.experiments.ch5 import checkpoint_digest

    bpnn.save_checkpoint(back, tmp_path / "new")
    assert checkpoint_digest(tmp_path / "new") == checkpoint_digest(tmp_path / "old")
    # a legacy file with a NaN is refused like a new one
    from safetensors.numpy import load_file, save_file

    arrays = load_file(str(tmp_path / "old.safetensors"))
    arrays["x_hi"][3] = np.nan
    save_file(arrays, str(tmp_path / "old.safetensors"))
    with pytest.raises(CheckpointError, match=r"x_hi\[3\] = nan is not a finite number"):
        bpnn.load_checkpoint(tmp_path / "old")


def test_an_old_format_cnn_checkpoint_still_loads(tmp_path: Path) -> None:
    from safetensors.torch import save_file

    torch.manual_seed(0)
    net = build_pilotnet(SMALL).eval()
    header = {"format": "uvnav-pilotnet-v1", "config": SMALL.to_dict(), "record": {"a": 1}}
    path = tmp_path / "old.safetensors"
    save_file(dict(net.state_dict()), str(path), metadata={"uvnav": json.dumps(header)})
    back, got = load_checkpoint(path)
    assert got["kind"] == "pilotnet" and got["record"] == {"a": 1}
    x = torch.randint(0, 255, (1, 66, 200, 3), dtype=torch.uint8)
    e = torch.tensor([[20.0]])
    with torch.no_grad():
        assert torch.equal(net(x, e), back(x, e))


def test_a_header_with_another_format_is_refused_in_one_line(tmp_path: Path) -> None:
    from safetensors.numpy import save_file

    path = tmp_path / "m.safetensors"
    header = {"format": "uvnav-checkpoint-v9", "kind": "bpnn", "config": {}, "record": {}}
    save_file({"w": np.zeros(2)}, str(path), metadata={"uvnav": json.dumps(header)})
    msg = f"{path}: header format 'uvnav-checkpoint-v9' (expected '{FORMAT}')"
    for load in (read_header, bpnn.load_checkpoint, load_checkpoint):
        with pytest.raises(CheckpointError) as e:
            load(path)  # type: ignore[operator]
        assert str(e.value) == msg
    header = {**header, "format": FORMAT, "kind": "svm"}
    save_file({"w": np.zeros(2)}, str(path), metadata={"uvnav": json.dumps(header)})
    with pytest.raises(CheckpointError, match="header kind 'svm'"):
        read_checkpoint(path, "bpnn")
    save_file({"w": np.zeros(2)}, str(path))  # no header, no JSON beside it
    with pytest.raises(CheckpointError, match="no 'uvnav' header"):
        read_header(path)


def test_a_bpnn_checkpoint_loads_without_torch(tmp_path: Path) -> None:
    bpnn.save_checkpoint(_bpnn_model(), tmp_path / "m")
    code = (
        "import sys\n"
        "from uvnav.learning.bpnn import load_checkpoint\n"
        f"m = load_checkpoint({str(tmp_path / 'm')!r})\n"
        "print(m.n_inputs, 'torch' in sys.modules)\n"
    )
    src = Path(bpnn.__file__).resolve().parents[2]
    out = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        env={"PYTHONPATH": str(src), "PATH": "/usr/bin:/bin"},
    )
    assert out.stdout.split() == ["9", "False"]
