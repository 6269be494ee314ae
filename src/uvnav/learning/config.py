"""Configuration of the Chapter 6 CNN and its training schedule (plain dataclasses, no torch).

Kept free of torch so that the command line and the checkpoint reader can parse a configuration
without the ``learning`` extra, and so that a checkpoint's JSON header round-trips exactly.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any

#: largest input image side [px] a configuration (or a checkpoint's header) may ask for; a
#: module constant (raise it before loading for larger images)
MAX_IMAGE_SIDE = 1024
#: largest speed scale / target-speed cap [m/s]
MAX_SPEED = 1000.0

#: what the network's second output can be trained on
SECOND_OUTPUTS = ("throttle", "target_speed")


def _check_types(cfg: Any) -> None:
    """Refuse a field of the wrong type (a header's ``height: "66"``) or a non-finite number."""
    for f in dataclasses.fields(cfg):
        value = getattr(cfg, f.name)
        kind = type(f.default)
        name = f"{type(cfg).__name__}.{f.name}"
        if kind is int:
            if isinstance(value, bool) or not isinstance(value, int):
                raise ValueError(f"{name}: expected an integer (got {value!r:.40})")
        elif kind is float:
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ValueError(f"{name}: expected a number (got {value!r:.40})")
            if not math.isfinite(value):
                raise ValueError(f"{name}: expected a finite number (got {value})")
        elif kind is str and not isinstance(value, str):
            raise ValueError(f"{name}: expected a string (got {value!r:.40})")


@dataclass(frozen=True)
class PilotNetConfig:
    """Shape of the Chapter 6 network (thesis §6.2, Fig. 6.3; NVIDIA PilotNet, Bojarski 2016).

    Attributes:
        height: input image height [px] (thesis/PilotNet: 66).
        width: input image width [px] (thesis/PilotNet: 200).
        channels: input channels (3, RGB).
        n_outputs: 2 = steering and throttle (thesis), 1 = steering only.
        dropout: dropout rate of the three dropout layers (thesis: 0.5).
        conv3x3_layers: number of 64-channel 3×3 convolutions.  The thesis names FOUR convolution
            layers (24, 36, 48, 64) and a flatten of 3840 = 64 × 3 × 20, which is what ONE 3×3
            layer gives on 66×200; NVIDIA's PilotNet has two (flatten 1152).  Default 1 (thesis).
        extra_inputs: scalars concatenated to the flattened features (1 = the car's speed, which
            the learned throttle needs: from one image alone the right throttle is ambiguous).
        speed_scale: divisor of the speed input [m/s] (keeps it about unit size); also the
            scale of a target-speed output.
        second_output: what the second output (``n_outputs=2``) is trained on: ``"throttle"``
            (the thesis's throttle head: the expert's pedal) or ``"target_speed"`` (the speed
            the expert tracks, ``min(v_target, target_speed_max) / speed_scale``; at drive time
            a proportional law turns it into the pedal: the "learned-speed" throttle).
        target_speed_max: cap of the target-speed label [m/s], the learned driver's top speed
            (default 50).  Measured (docs/thesis-notes.md): the 30-epoch network's steering with
            the expert's own (oracle) speed profile, up to 75–95 m/s on straights, still leaves
            the road about once a lap at 66–75 m/s; capped at 50 m/s it does not.  Below the cap
            the label is the expert's corner-speed profile (32–50 m/s near corners), so the
            network still decides where and how hard to brake.
    """

    height: int = 66
    width: int = 200
    channels: int = 3
    n_outputs: int = 2
    dropout: float = 0.5
    conv3x3_layers: int = 1
    extra_inputs: int = 1
    speed_scale: float = 50.0
    second_output: str = "throttle"
    target_speed_max: float = 50.0

    def __post_init__(self) -> None:
        _check_types(self)
        for name in ("height", "width"):
            side = getattr(self, name)
            if side < 32:
                raise ValueError(
                    f"PilotNetConfig.{name}: input {self.height}x{self.width} is below 32x32"
                )
            if side > MAX_IMAGE_SIDE:
                raise ValueError(
                    f"PilotNetConfig.{name}: input {self.height}x{self.width} is above the limit "
                    f"of {MAX_IMAGE_SIDE} px a side (uvnav.learning.config.MAX_IMAGE_SIDE)"
                )
        if not 1 <= self.channels <= 4:
            raise ValueError(f"PilotNetConfig.channels: {self.channels} (must be 1..4)")
        if self.conv3x3_layers > 8 or self.extra_inputs > 64:
            raise ValueError(
                "PilotNetConfig: conv3x3_layers must be <= 8 and extra_inputs <= 64 "
                f"(got {self.conv3x3_layers}, {self.extra_inputs})"
            )
        if self.n_outputs not in (1, 2):
            raise ValueError(f"PilotNetConfig.n_outputs: {self.n_outputs} (must be 1 or 2)")
        if not 0.0 <= self.dropout < 1.0:
            raise ValueError(f"PilotNetConfig.dropout: {self.dropout} (must be in [0, 1))")
        if self.conv3x3_layers < 0 or self.extra_inputs < 0:
            raise ValueError("PilotNetConfig: conv3x3_layers and extra_inputs must be >= 0")
        if self.second_output not in SECOND_OUTPUTS:
            raise ValueError(
                f"PilotNetConfig.second_output: {self.second_output!r} "
                f"(must be one of {', '.join(SECOND_OUTPUTS)})"
            )
        for name in ("speed_scale", "target_speed_max"):
            value = getattr(self, name)
            if not 0 < value <= MAX_SPEED:
                raise ValueError(
                    f"PilotNetConfig.{name}: {value} (must be in (0, {MAX_SPEED:g}] m/s)"
                )

    @property
    def predicts_target_speed(self) -> bool:
        """True when the second output is the target speed (the "learned-speed" throttle)."""
        return self.n_outputs == 2 and self.second_output == "target_speed"

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON-able dict."""
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> PilotNetConfig:
        """Inverse of :meth:`to_dict`; unknown keys are an error (one line naming the key)."""
        names = {f.name for f in dataclasses.fields(cls)}
        extra = sorted(set(data) - names)
        if extra:
            raise ValueError(f"PilotNetConfig: unknown field(s) {', '.join(extra)}")
        return cls(**data)


@dataclass(frozen=True)
class TrainConfig:
    """Training schedule (thesis §6.3: Adam, learning rate 0.001, batch 100, 30 epochs).

    Attributes:
        epochs: passes over the training set (thesis: 30).
        batch_size: samples per step (thesis: 100).
        lr: Adam learning rate (thesis: 1e-3).
        augment: apply flip / brightness / zoom to training batches (thesis Fig. 6.7).
        flip_prob: probability of a horizontal flip (steering negated).
        brightness: range of the brightness factor (multiplicative).
        zoom: range of the zoom factor (1 = none; > 1 zooms in about the centre).
        throttle_weight: weight of the throttle term in the MSE (6.1) (steering weight is 1).
        seed: seed of the shuffling, dropout and augmentation.
        threads: torch CPU threads (default 1: on a shared, oversubscribed machine OpenMP barriers
            stall a second thread; measured 32 vs 24 img/s training, 31 vs 380 ms inference).
        device: torch device string ("cpu", "cuda").
    """

    epochs: int = 30
    batch_size: int = 100
    lr: float = 1e-3
    augment: bool = True
    flip_prob: float = 0.5
    brightness: tuple[float, float] = (0.6, 1.3)
    zoom: tuple[float, float] = (1.0, 1.3)
    throttle_weight: float = 1.0
    seed: int = 0
    threads: int = 1
    device: str = "cpu"
    extra: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.epochs < 1 or self.batch_size < 1 or self.lr <= 0:
            raise ValueError("TrainConfig: epochs, batch_size and lr must be positive")
