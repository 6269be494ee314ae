"""ONNX export of the Chapter 6 CNN, checked against torch with onnxruntime.

The exported graph takes ``images`` ``(N, H, W, 3)`` float32 in [0, 255] (and ``speed``
``(N, 1)`` [m/s] when the network uses it) and returns ``(N, n_outputs)``.  ``export_onnx``
runs onnxruntime on random inputs and reports the largest absolute difference to torch; the
check requires ≤ ``atol`` (1e-5 by default).
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
    import onnxruntime as ort
    import torch

    model = model.cpu().eval()
    cfg = model.config
    rng = np.random.default_rng(seed)
    imgs = rng.uniform(0, 255, size=(batch, cfg.height, cfg.width, cfg.channels)).astype(np.float32)
    speed = rng.uniform(0, 80, size=(batch, 1)).astype(np.float32)
    args: tuple[Any, ...] = (torch.from_numpy(imgs),)
    names = ["images"]
    if cfg.extra_inputs:
        args = (*args, torch.from_numpy(speed))
        names.append("speed")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    torch.onnx.export(
        model,
        args,
        str(path),
        input_names=names,
        output_names=["controls"],
        dynamic_axes={n: {0: "batch"} for n in [*names, "controls"]},
        dynamo=False,
    )
    with torch.no_grad():
        ref = model(*args).numpy()
    sess = ort.InferenceSession(str(path), providers=["CPUExecutionProvider"])
    feeds = {"images": imgs}
    if cfg.extra_inputs:
        feeds["speed"] = speed
    out = sess.run(None, feeds)[0]
    diff = float(np.max(np.abs(out - ref)))
    if diff > atol:
        raise ValueError(f"{path}: onnxruntime differs from torch by {diff:.3g} (> {atol:g})")
    return diff
