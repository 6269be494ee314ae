"""The Chapter 6 network: shape (thesis §6.2), configuration, checkpoints, ONNX export."""

from __future__ import annotations

import numpy as np
import pytest

torch = pytest.importorskip("torch")

from uvnav.learning import PilotNetConfig  # noqa: E402
from uvnav.learning.checkpoint import load_checkpoint, read_header, save_checkpoint  # noqa: E402
from uvnav.learning.pilotnet import build_pilotnet, conv_output_shape, flatten_size  # noqa: E402


def test_flatten_is_the_thesis_3840_with_four_convolutions() -> None:
    assert conv_output_shape(PilotNetConfig()) == (64, 3, 20)
    assert flatten_size(PilotNetConfig()) == 3840
    # NVIDIA's PilotNet (two 3x3 layers) flattens to 1152
    assert flatten_size(PilotNetConfig(conv3x3_layers=2)) == 1152


def test_forward_shapes_and_layers() -> None:
    torch.manual_seed(0)
    net = build_pilotnet(PilotNetConfig())
    convs = [m for m in net.modules() if isinstance(m, torch.nn.Conv2d)]
    assert [c.out_channels for c in convs] == [24, 36, 48, 64]
    assert [c.kernel_size for c in convs] == [(5, 5)] * 3 + [(3, 3)]
    assert [c.stride for c in convs] == [(2, 2)] * 3 + [(1, 1)]
    dense = [m for m in net.modules() if isinstance(m, torch.nn.Linear)]
    assert [d.out_features for d in dense] == [50, 10, 2]
    assert dense[0].in_features == 3840 + 1  # + speed
    assert sum(isinstance(m, torch.nn.Dropout) for m in net.modules()) == 3
    x = torch.randint(0, 255, (4, 66, 200, 3), dtype=torch.uint8)
    out = net.eval()(x, torch.full((4, 1), 30.0))
    assert out.shape == (4, 2)
    with pytest.raises(ValueError, match="speed"):
        net(x)
    img_only = build_pilotnet(PilotNetConfig(extra_inputs=0, n_outputs=1)).eval()
    assert img_only(x).shape == (4, 1)


def test_config_round_trip_and_errors() -> None:
    cfg = PilotNetConfig(dropout=0.3, conv3x3_layers=2)
    assert PilotNetConfig.from_dict(cfg.to_dict()) == cfg
    with pytest.raises(ValueError, match="unknown field"):
        PilotNetConfig.from_dict({**cfg.to_dict(), "bogus": 1})
    with pytest.raises(ValueError, match="n_outputs"):
        PilotNetConfig(n_outputs=3)


def test_checkpoint_round_trip_is_exact(tmp_path) -> None:
    torch.manual_seed(1)
    net = build_pilotnet(PilotNetConfig(dropout=0.2)).eval()
    path = save_checkpoint(net, tmp_path / "m.safetensors", record={"val_loss": [0.1]})
    assert read_header(path)["record"] == {"val_loss": [0.1]}
    assert (tmp_path / "m.json").is_file()
    back, header = load_checkpoint(path)
    assert header["config"]["dropout"] == 0.2
    x = torch.randint(0, 255, (2, 66, 200, 3), dtype=torch.uint8)
    e = torch.tensor([[10.0], [40.0]])
    with torch.no_grad():
        assert torch.equal(net(x, e), back(x, e))


def test_checkpoint_rejects_other_files(tmp_path) -> None:
    bad = tmp_path / "x.safetensors"
    bad.write_bytes(b"not a checkpoint")
    with pytest.raises(ValueError, match=r"x\.safetensors"):
        read_header(bad)
    with pytest.raises(FileNotFoundError):
        read_header(tmp_path / "missing.safetensors")


def test_onnx_matches_torch(tmp_path) -> None:
    pytest.importorskip("onnxruntime")
    from uvnav.learning.export import export_onnx

    torch.manual_seed(2)
    net = build_pilotnet(PilotNetConfig())
    diff = export_onnx(net, tmp_path / "m.onnx", atol=1e-5)
    assert diff <= 1e-5
    assert (tmp_path / "m.onnx").stat().st_size > 100_000
    assert np.isfinite(diff)


@pytest.mark.parametrize("second_output", ["throttle", "target_speed"])
def test_onnxruntime_predictor_drives_like_torch(second_output: str) -> None:
    """``Predictor(backend="onnxruntime")`` gives torch's steering and second output (throttle,
    or the target speed in m/s) to float32 rounding, frame by frame."""
    pytest.importorskip("onnxruntime")
    from uvnav.learning.train import Predictor

    torch.manual_seed(3)
    net = build_pilotnet(PilotNetConfig(second_output=second_output))
    ref, fast = Predictor(net), Predictor(net, backend="onnxruntime")
    rng = np.random.default_rng(0)
    for _ in range(3):
        frame = rng.integers(0, 256, size=(66, 200, 3), dtype=np.uint8)
        speed = float(rng.uniform(0, 80))
        a, b = ref.outputs(frame, speed), fast.outputs(frame, speed)
        scale = net.config.speed_scale if second_output == "target_speed" else 1.0
        assert a[0] == pytest.approx(b[0], abs=1e-5)
        assert a[1] == pytest.approx(b[1], abs=1e-5 * scale)
    with pytest.raises(ValueError, match="backend"):
        Predictor(net, backend="tensorrt")
    with pytest.raises(ValueError, match="device"):
        Predictor(net, backend="onnxruntime", device="cuda")
