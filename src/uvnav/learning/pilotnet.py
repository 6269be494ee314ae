"""The Chapter 6 CNN: PilotNet-style steering + throttle regression (thesis §6.2, eq. (6.1)).

Paper: M. Bojarski et al., "End to End Learning for Self-Driving Cars", NVIDIA, arXiv:1604.07316
(2016); thesis Chapter 6 (J. Zhang, H. Huang, Y. Zhang, ANZCC 2020), Fig. 6.3 and eq. (6.1).

Layers, in the thesis's words and order: a normalisation layer (x / 127.5 − 1), four convolution
layers with 24, 36, 48 (5×5, stride 2) and 64 (3×3, stride 1) filters, ELU after each, a dropout
layer (0.5), a flatten of 3840 neurons, dense 50, 10 and 2 (steering, throttle) with ELU and a
dropout after each of the first two, trained on the mean squared error (6.1).

Thesis ambiguities and what was chosen (also in docs/thesis-notes.md):

* The thesis text attaches "kernel 3*3, stride 0" to the flatten layer and "kernel 5*5, stride 2"
  to the dense layers; kernel and stride belong to the convolutions.  We read it as PilotNet:
  the first three convolutions 5×5 stride 2, the 64-filter one 3×3 stride 1.
* 3840 = 64 × 3 × 20 is exactly the output of ONE 3×3 convolution on a 66×200 input (PilotNet has
  two, giving 64 × 1 × 18 = 1152); the thesis also counts four convolution layers.  Default: one
  (``conv3x3_layers=1``, flatten 3840); ``conv3x3_layers=2`` gives the original PilotNet.
* The learned throttle: from a single image the right throttle is ambiguous (the same view at
  10 m/s and at 60 m/s asks for different pedals), and a network trained on images only learns
  the average — which made a prototype brake to a stop.  ``extra_inputs=1`` concatenates the
  car's speed (scaled) to the flattened features; ``extra_inputs=0`` is the thesis's image-only
  network.
* The learned throttle, continued (measured earlier: with the speed input and 30 epochs the
  throttle head's validation MSE stays at 0.16 and the car enters sharp corners at 46–52 m/s
  where the expert brakes to ~32): the expert's pedal is ``clip(k (v_target − v))``, a steep,
  often saturated function of the speed, while ``v_target`` (its corner-speed profile over the
  preview distance) depends on the road ahead only, i.e. on what one forward image shows.
  ``second_output="target_speed"`` trains the second output on ``v_target`` (capped at
  ``target_speed_max``, divided by ``speed_scale``: :func:`target_speed_label`); at drive time
  the same proportional law as the expert's tracks the prediction (the "learned-speed" throttle,
  :mod:`uvnav.driving.pipeline`).  The network still decides how fast to go; the law only
  closes the loop on the measured speed.  ``second_output="throttle"`` is the thesis's head.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from uvnav.learning.config import PilotNetConfig
from uvnav.learning.runtime import require_torch

if TYPE_CHECKING:
    import torch


def target_speed_label(v_target: ArrayLike, config: PilotNetConfig) -> NDArray[np.float64]:
    """Training label of a target-speed output: ``min(v_target, target_speed_max) / speed_scale``.

    Args:
        v_target: the expert's target speed [m/s].
        config: network configuration (cap and scale).

    Returns:
        The label (dimensionless; 0.64–1.0 for the expert's 32–50 m/s with the default cap).
    """
    v = np.asarray(v_target, dtype=float)
    if not np.all(np.isfinite(v)):
        raise ValueError(
            "target_speed: the dataset has rows without the target_speed column "
            "(record it with `uvnav drive collect`, or train the throttle head instead)"
        )
    return np.minimum(v, config.target_speed_max) / config.speed_scale


def target_speed_from_output(y: ArrayLike, config: PilotNetConfig) -> NDArray[np.float64]:
    """Inverse of :func:`target_speed_label`: the network's output as a speed [m/s] (≥ 0)."""
    return np.maximum(np.asarray(y, dtype=float) * config.speed_scale, 0.0)


def conv_output_shape(config: PilotNetConfig) -> tuple[int, int, int]:
    """(channels, height, width) after the convolutions, i.e. the flatten size's factors.

    Args:
        config: network configuration.

    Returns:
        ``(64, 3, 20)`` for the thesis's 66×200 input with one 3×3 layer.
    """
    h, w = config.height, config.width
    for _ in range(3):
        h, w = (h - 5) // 2 + 1, (w - 5) // 2 + 1
    for _ in range(config.conv3x3_layers):
        h, w = h - 2, w - 2
    if h < 1 or w < 1:
        raise ValueError(f"PilotNetConfig: input {config.height}x{config.width} is too small")
    c = 64 if config.conv3x3_layers else 48
    return c, h, w


def flatten_size(config: PilotNetConfig) -> int:
    """Neurons of the flatten layer (thesis: 3840)."""
    c, h, w = conv_output_shape(config)
    return c * h * w


def build_pilotnet(config: PilotNetConfig | None = None) -> torch.nn.Module:
    """Build the network (uninitialised weights use torch's defaults, seeded by the caller).

    Args:
        config: network configuration (default: the thesis's).

    Returns:
        A ``torch.nn.Module`` whose ``forward(images, extra=None)`` takes ``images`` as uint8 or
        float tensors ``(N, H, W, 3)`` in [0, 255] (HWC, as images are stored) and ``extra``
        ``(N, extra_inputs)`` (the speed [m/s], scaled inside), and returns ``(N, n_outputs)``.
    """
    torch = require_torch()
    nn = torch.nn
    cfg = config or PilotNetConfig()

    class PilotNet(nn.Module):  # type: ignore[name-defined]
        def __init__(self) -> None:
            super().__init__()
            self.config = cfg
            layers: list[Any] = []
            c_in = cfg.channels
            for c_out in (24, 36, 48):
                layers += [nn.Conv2d(c_in, c_out, 5, stride=2), nn.ELU()]
                c_in = c_out
            for _ in range(cfg.conv3x3_layers):
                layers += [nn.Conv2d(c_in, 64, 3, stride=1), nn.ELU()]
                c_in = 64
            layers += [nn.Dropout(cfg.dropout), nn.Flatten()]
            self.features = nn.Sequential(*layers)
            n_flat = flatten_size(cfg)
            self.head = nn.Sequential(
                nn.Linear(n_flat + cfg.extra_inputs, 50),
                nn.ELU(),
                nn.Dropout(cfg.dropout),
                nn.Linear(50, 10),
                nn.ELU(),
                nn.Dropout(cfg.dropout),
                nn.Linear(10, cfg.n_outputs),
            )

        def hidden(self, images: Any, extra: Any = None) -> Any:
            """The last hidden layer (the 10 units the output layer reads)."""
            # normalisation layer (thesis §6.2): [0, 255] -> [-1, 1], HWC -> CHW
            x = (images.float().permute(0, 3, 1, 2) / 127.5 - 1.0).contiguous()
            f = self.features(x)
            if cfg.extra_inputs:
                if extra is None:
                    raise ValueError("PilotNet: this network needs the speed input (extra)")
                f = torch.cat([f, extra.float().reshape(f.shape[0], -1) / cfg.speed_scale], dim=1)
            return self.head[:-1](f)

        def forward(self, images: Any, extra: Any = None) -> Any:
            return self.head[-1](self.hidden(images, extra))

    return PilotNet()
