"""ONNX export of the Chapter 6 CNN, checked against torch with onnxruntime.

The exported graph takes ``images`` ``(N, H, W, 3)`` float32 in [0, 255] (and ``speed``
``(N, 1)`` [m/s] when the network uses it) and returns ``(N, n_outputs)``.  ``export_onnx``
runs onnxruntime on random inputs and reports the largest absolute difference to torch; the
check requires ≤ ``atol`` (1e-5 by default).  ``onnx_session`` does the same in memory and
returns the session, for driving with onnxruntime (``Predictor(backend="onnxruntime")``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np


def export_onnx(
    model: Any, path: Path | str, *, atol: float = 1e-5, batch: int = 4, seed: int = 0
) -> float:
    """Export to ONNX and compare onnxruntime with torch on random inputs.

    Args:
        model: the network (eval mode is set).
        path: output ``.onnx`` file.
        atol: largest allowed absolute difference.
        batch: batch size of the check.
        seed: seed of the random check inputs.

    Returns:
        The largest absolute difference between onnxruntime and torch.

    Raises:
        ValueError: the difference exceeds ``atol``.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    data = _onnx_bytes(model)
    path.write_bytes(data)
    return _check(model, _session(data, threads=1), str(path), atol=atol, batch=batch, seed=seed)


def onnx_session(model: Any, *, threads: int = 1, atol: float = 1e-5) -> Any:
    """An onnxruntime session of the network, exported in memory and checked against torch.

    Args:
        model: the network (eval mode is set).
        threads: onnxruntime intra-op threads.
        atol: largest allowed absolute difference to torch on random inputs.

    Returns:
        The ``onnxruntime.InferenceSession`` (inputs ``images`` and, when used, ``speed``).

    Raises:
        ValueError: the difference exceeds ``atol``.
    """
    sess = _session(_onnx_bytes(model), threads=threads)
    _check(model, sess, "onnx export", atol=atol)
    return sess


def _onnx_bytes(model: Any) -> bytes:
    """The network as an ONNX model (bytes); inputs ``images`` (and ``speed``), output
    ``controls``, the batch dimension dynamic."""
    import tempfile

    import torch

    model = model.cpu().eval()
    cfg = model.config
    args: tuple[Any, ...] = (torch.zeros(1, cfg.height, cfg.width, cfg.channels),)
    names = ["images"]
    if cfg.extra_inputs:
        args = (*args, torch.zeros(1, 1))
        names.append("speed")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "pilotnet.onnx"
        torch.onnx.export(
            model,
            args,
            str(path),
            input_names=names,
            output_names=["controls"],
            dynamic_axes={n: {0: "batch"} for n in [*names, "controls"]},
            dynamo=False,
        )
        return path.read_bytes()


def _session(data: bytes, *, threads: int) -> Any:
    import onnxruntime as ort

    opts = ort.SessionOptions()
    opts.intra_op_num_threads = max(1, threads)
    opts.inter_op_num_threads = 1
    return ort.InferenceSession(data, sess_options=opts, providers=["CPUExecutionProvider"])


def _check(
    model: Any, sess: Any, what: str, *, atol: float, batch: int = 4, seed: int = 0
) -> float:
    """Largest |onnxruntime − torch| on random inputs; ``ValueError`` above ``atol``."""
    import torch

    cfg = model.config
    rng = np.random.default_rng(seed)
    imgs = rng.uniform(0, 255, size=(batch, cfg.height, cfg.width, cfg.channels)).astype(np.float32)
    speed = rng.uniform(0, 80, size=(batch, 1)).astype(np.float32)
    args: tuple[Any, ...] = (torch.from_numpy(imgs),)
    feeds = {"images": imgs}
    if cfg.extra_inputs:
        args = (*args, torch.from_numpy(speed))
        feeds["speed"] = speed
    with torch.no_grad():
        ref = model.cpu().eval()(*args).numpy()
    out = sess.run(None, feeds)[0]
    diff = float(np.max(np.abs(out - ref)))
    if diff > atol:
        raise ValueError(f"{what}: onnxruntime differs from torch by {diff:.3g} (> {atol:g})")
    return diff
