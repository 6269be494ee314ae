"""Training of the Chapter 6 CNN (thesis §6.3: Adam, lr 0.001, batch 100, 30 epochs, MSE (6.1)).

``train_pilotnet`` takes numpy arrays (images ``(N, H, W, 3)`` uint8, labels, speeds) for the
training and validation sets, augments training batches (:mod:`uvnav.learning.augment`), and
returns the model and the per-epoch loss curves (Fig. 6.8).  The loss is eq. (6.1), the mean
squared error, over steering plus ``throttle_weight`` × the second output when the network has
one.  The third array of a set is that second output's label: the throttle, or for a network with
``second_output="target_speed"`` the scaled target speed
(:func:`uvnav.learning.pilotnet.target_speed_label`; the caller converts), so the "throttle"
MSE of :class:`TrainHistory` is then the target-speed term in those units.  Determinism:
torch's seed and generator come from ``TrainConfig.seed``; the number of CPU threads is set
(1 by default: the machine is shared).  Interruptible: with ``resume=`` the state after each epoch
is written (:func:`uvnav.learning.checkpoint.save_training_state`) and a rerun on the same data
and settings continues from the last finished epoch, with the same result as an uninterrupted
run (the weights, the optimizer and every random state are restored).
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from uvnav.learning.config import PilotNetConfig, TrainConfig

#: inference backends of :class:`Predictor`
BACKENDS = ("torch", "onnxruntime")


class NonFiniteTrainingError(ValueError):
    """NaN or ±inf in the training data, the loss or the weights: training stops, nothing is
    saved (one-line message)."""


@dataclass
class TrainHistory:
    """Loss curves: mean training and validation MSE (6.1) per epoch, and throughput."""

    train_loss: list[float] = field(default_factory=list)
    val_loss: list[float] = field(default_factory=list)
    val_steering_mse: list[float] = field(default_factory=list)
    val_throttle_mse: list[float] = field(default_factory=list)
    images_per_s: float = 0.0


def _targets(
    steering: NDArray[np.float64], throttle: NDArray[np.float64] | None, n_out: int
) -> Any:
    import torch

    if n_out == 1 or throttle is None:
        return torch.as_tensor(np.asarray(steering, dtype=np.float32)[:, None])
    return torch.as_tensor(np.stack([steering, throttle], axis=1).astype(np.float32))


def _batched_eval(
    model: Any,
    forward: Any,
    images: NDArray[np.uint8],
    speed: NDArray[np.float64] | None,
    batch_size: int,
    device: str,
) -> Any:
    """``forward(images, speed)`` in eval mode without gradients, batch by batch, concatenated
    on the CPU (``forward`` is the model or one of its methods; the speed input is passed when the
    model's config takes it)."""
    import torch

    model.eval()
    cfg: PilotNetConfig = model.config
    out = []
    with torch.no_grad():
        for a in range(0, len(images), batch_size):
            xb = torch.as_tensor(images[a : a + batch_size]).to(device)
            eb = (
                torch.as_tensor(
                    np.asarray(speed[a : a + batch_size], dtype=np.float32)[:, None]
                ).to(device)
                if cfg.extra_inputs and speed is not None
                else None
            )
            out.append(forward(xb, eb).cpu())
    return torch.cat(out)


def evaluate_mse(
    model: Any,
    images: NDArray[np.uint8],
    steering: NDArray[np.float64],
    throttle: NDArray[np.float64] | None,
    speed: NDArray[np.float64] | None,
    *,
    batch_size: int = 200,
    device: str = "cpu",
) -> tuple[float, float, float]:
    """``(mse, steering mse, throttle mse)`` of the model in eval mode (NaN where absent)."""

    y = _targets(steering, throttle, model.config.n_outputs)
    p = _batched_eval(model, model, images, speed, batch_size, device)
    se = (p - y) ** 2
    s_mse = float(se[:, 0].mean())
    t_mse = float(se[:, 1].mean()) if se.shape[1] > 1 else float("nan")
    return float(se.mean()), s_mse, t_mse


def train_pilotnet(
    train: tuple[NDArray[np.uint8], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]],
    val: tuple[NDArray[np.uint8], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
    | None,
    *,
    net: PilotNetConfig | None = None,
    config: TrainConfig | None = None,
    model: Any = None,
    on_epoch: Callable[[int, float, float], None] | None = None,
    resume: Path | str | None = None,
) -> tuple[Any, TrainHistory]:
    """Train the network.

    Args:
        train: ``(images (N,H,W,3) uint8, steering, throttle, speed)`` training set.
        val: the same for validation, or ``None``.
        net: network shape (ignored when ``model`` is given).
        config: schedule (default: the thesis's).
        model: a model to continue training (e.g. a DAgger round), else a new one.
        on_epoch: called with ``(epoch, train_loss, val_loss)`` after each epoch.
        resume: training-state file: written after every epoch, and read at the start when it
            holds the same run (same data, settings and initial weights; a larger ``epochs`` is
            the same run continued); the caller deletes it once the model is saved.

    Returns:
        ``(model, history)``; ``images_per_s`` counts the epochs run in this call.

    Raises:
        NonFiniteTrainingError: a label or speed is NaN/±inf, or the loss or a weight stops
            being finite (training diverged); no model is returned (the per-epoch state of the
            last finite epoch is kept for ``resume``).
        ValueError: an empty training set.
    """
    import torch

    from uvnav.learning.augment import augment_batch
    from uvnav.learning.pilotnet import build_pilotnet

    cfg = config or TrainConfig()
    torch.set_num_threads(max(1, cfg.threads))
    torch.manual_seed(cfg.seed)
    imgs, steer, thr, spd = train
    if len(imgs) == 0:
        raise ValueError("train_pilotnet: empty training set")
    for part, arrays in (("training", train), ("validation", val or ())):
        for name, arr in zip(
            ("steering", "second output label", "speed"), arrays[1:], strict=False
        ):
            bad = _non_finite(arr)
            if bad:
                raise NonFiniteTrainingError(f"{part} {name}: {bad}")
    if model is None:
        model = build_pilotnet(net or PilotNetConfig())
        if model.config.predicts_target_speed:
            # a target-speed output starts at the labels' mean (about 1.3, i.e. 65 m/s) rather
            # than at 0 (standstill): the usual output-bias initialisation for a regression
            # whose labels are far from zero; the throttle and steering heads keep torch's
            with torch.no_grad():
                model.head[-1].bias[1] = float(np.mean(thr))
    model.to(cfg.device)
    ncfg: PilotNetConfig = model.config
    gen = torch.Generator(device=cfg.device)
    gen.manual_seed(cfg.seed)
    rng = np.random.default_rng(cfg.seed)
    opt = torch.optim.Adam(model.parameters(), lr=cfg.lr)
    w = torch.tensor([1.0, cfg.throttle_weight][: ncfg.n_outputs], device=cfg.device)
    hist = TrainHistory()
    start = 0
    key = _run_key(model, cfg, train, val) if resume is not None else ""
    if resume is not None:
        from uvnav.learning.checkpoint import load_training_state

        got = load_training_state(
            resume, model=model, optimizer=opt, generator=gen, rng=rng, key=key
        )
        if got is not None:
            start, saved = got
            hist = TrainHistory(**saved)
    n_seen = 0
    import time

    tic = time.perf_counter()
    for epoch in range(start, cfg.epochs):
        model.train()
        perm = rng.permutation(len(imgs))
        total, count = 0.0, 0
        for a in range(0, len(perm), cfg.batch_size):
            idx = np.sort(perm[a : a + cfg.batch_size])
            xb = torch.as_tensor(imgs[idx]).to(cfg.device).float()
            sb = torch.as_tensor(steer[idx].astype(np.float32)).to(cfg.device)
            if cfg.augment:
                xb, sb = augment_batch(
                    xb, sb, gen, flip_prob=cfg.flip_prob, brightness=cfg.brightness, zoom=cfg.zoom
                )
            if ncfg.n_outputs == 2:
                tb = torch.as_tensor(thr[idx].astype(np.float32)).to(cfg.device)
                yb = torch.stack([sb, tb], dim=1)
            else:
                yb = sb[:, None]
            eb = (
                torch.as_tensor(spd[idx].astype(np.float32)[:, None]).to(cfg.device)
                if ncfg.extra_inputs
                else None
            )
            pred = model(xb, eb)
            loss = (((pred - yb) ** 2) * w).mean()  # MSE, eq. (6.1)
            if not bool(torch.isfinite(loss)):
                raise NonFiniteTrainingError(
                    f"training diverged in epoch {epoch + 1}: the loss is {float(loss.detach())} "
                    f"(try a smaller learning rate than {cfg.lr:g}); no model was written"
                )
            opt.zero_grad()
            loss.backward()
            opt.step()
            total += float(loss.detach()) * len(idx)
            count += len(idx)
            n_seen += len(idx)
        hist.train_loss.append(total / count)
        bad = _non_finite_weights(model)
        if bad:
            raise NonFiniteTrainingError(
                f"training diverged in epoch {epoch + 1}: {bad} (try a smaller learning rate "
                f"than {cfg.lr:g}); no model was written"
            )
        if val is not None and len(val[0]):
            m, ms, mt = evaluate_mse(model, *val, device=cfg.device)
            if not math.isfinite(m):
                raise NonFiniteTrainingError(
                    f"training diverged in epoch {epoch + 1}: the validation loss is {m}; "
                    "no model was written"
                )
            hist.val_loss.append(m)
            hist.val_steering_mse.append(ms)
            hist.val_throttle_mse.append(mt)
        if resume is not None:
            from uvnav.learning.checkpoint import save_training_state

            save_training_state(
                resume,
                model=model,
                optimizer=opt,
                generator=gen,
                rng=rng,
                epochs_done=epoch + 1,
                history=dataclasses.asdict(hist),
                key=key,
            )
        if on_epoch is not None:
            on_epoch(
                epoch, hist.train_loss[-1], hist.val_loss[-1] if hist.val_loss else float("nan")
            )
    hist.images_per_s = n_seen / max(time.perf_counter() - tic, 1e-9)
    model.eval()
    return model, hist


def _non_finite(arr: Any) -> str:
    """``"k of n values are not finite (first at sample i: nan)"`` for a 1-D array of labels,
    or ``""`` when all are finite."""
    a = np.ravel(np.asarray(arr, dtype=float))
    bad = np.flatnonzero(~np.isfinite(a))
    if not len(bad):
        return ""
    i = int(bad[0])
    return f"{len(bad)} of {len(a)} values are not finite (first at sample {i}: {float(a[i])})"


def _non_finite_weights(model: Any) -> str:
    """``"<parameter>: k of n values are not finite"`` for the first such tensor, or ``""``."""
    from uvnav.learning.checkpoint import non_finite_tensor

    return non_finite_tensor(dict(model.state_dict())) or ""


def _run_key(model: Any, cfg: TrainConfig, train: Any, val: Any) -> str:
    """Fingerprint of a training run: settings (but the epoch count, threads and device), the
    network's shape and initial weights, and the data."""
    h = hashlib.blake2b(digest_size=16)
    settings = {
        k: v for k, v in dataclasses.asdict(cfg).items() if k not in ("epochs", "threads", "device")
    }
    h.update(json.dumps([settings, model.config.to_dict()], sort_keys=True, default=str).encode())
    for t in model.state_dict().values():
        h.update(t.detach().cpu().numpy().tobytes())
    for arr in (*train, *(val or ())):
        h.update(np.ascontiguousarray(arr).tobytes())
    return h.hexdigest()


def hidden_features(
    model: Any,
    images: NDArray[np.uint8],
    speed: NDArray[np.float64] | None,
    *,
    batch_size: int = 200,
    device: str = "cpu",
) -> NDArray[np.float64]:
    """The last hidden layer's activations (eval mode), ``(N, 10)``: what the output layer reads."""
    out = _batched_eval(model, model.hidden, images, speed, batch_size, device)
    return np.asarray(out.numpy(), dtype=np.float64)


class Predictor:
    """Run a trained network on single frames: ``predictor(frame, speed) -> (steer, throttle)``.

    For a network whose second output is the target speed (``second_output="target_speed"``)
    use :meth:`outputs`, which returns ``(steer, target speed [m/s])``; turning that into a pedal
    is the driver's business (:mod:`uvnav.driving.pipeline`, the "learned-speed" throttle).

    Args:
        model: the trained network (put in eval mode).
        threads: torch (or onnxruntime) CPU threads.
        device: torch device.
        backend: ``"torch"`` or ``"onnxruntime"`` (the network exported in memory and checked
            against torch to 1e-5, :func:`uvnav.learning.export.onnx_session`; CPU only;
            measured 1.7 vs 4.2 ms a frame at 2 threads, ``benchmarks/bench_ch6.py``).
    """

    def __init__(
        self, model: Any, *, threads: int = 1, device: str = "cpu", backend: str = "torch"
    ) -> None:
        import torch

        if backend not in BACKENDS:
            raise ValueError(f"backend: {backend!r} (must be one of {', '.join(BACKENDS)})")
        if backend == "onnxruntime" and device != "cpu":
            raise ValueError(f"device: {device!r} (the onnxruntime backend runs on the CPU)")
        torch.set_num_threads(max(1, threads))
        self.model = model.to(device).eval()
        self.device = device
        self.config: PilotNetConfig = model.config
        self.backend = backend
        self._session: Any = None
        if backend == "onnxruntime":
            from uvnav.learning.export import onnx_session

            self._session = onnx_session(self.model, threads=threads)

    def _forward(self, frame: NDArray[np.uint8], speed: float) -> NDArray[np.float32]:
        """The network's raw outputs for one frame."""
        if self._session is not None:
            feeds = {"images": np.ascontiguousarray(frame, dtype=np.float32)[None]}
            if self.config.extra_inputs:
                feeds["speed"] = np.array([[speed]], dtype=np.float32)
            return np.asarray(self._session.run(None, feeds)[0][0])
        import torch

        with torch.no_grad():
            x = torch.as_tensor(np.ascontiguousarray(frame)[None]).to(self.device)
            e = (
                torch.tensor([[speed]], dtype=torch.float32, device=self.device)
                if self.config.extra_inputs
                else None
            )
            return np.asarray(self.model(x, e)[0].cpu().numpy())

    def outputs(self, frame: NDArray[np.uint8], speed: float = 0.0) -> tuple[float, float]:
        """``(steer, second)`` for one frame: ``second`` is the throttle in [-1, 1] (0 for a
        steering-only network) or, for a target-speed network, the target speed [m/s].

        Raises:
            ValueError: the network's output is NaN/±inf (e.g. a NaN speed input).
        """
        from uvnav.learning.pilotnet import target_speed_from_output

        out = self._forward(frame, speed)
        if not np.isfinite(out).all():
            raise ValueError(
                f"the network's output {out.tolist()} is not finite (speed input {speed})"
            )
        steer = float(np.clip(out[0], -1.0, 1.0))
        if len(out) < 2:
            return steer, 0.0
        if self.config.predicts_target_speed:
            return steer, float(target_speed_from_output(out[1], self.config))
        return steer, float(np.clip(out[1], -1.0, 1.0))

    def __call__(self, frame: NDArray[np.uint8], speed: float = 0.0) -> tuple[float, float]:
        """Steering and throttle (throttle 0 for a steering-only network) for one frame.

        Raises:
            ValueError: the network predicts a target speed, not a throttle (use :meth:`outputs`).
        """
        if self.config.predicts_target_speed:
            raise ValueError(
                "this network predicts the target speed, not the throttle "
                "(drive it with the 'learned-speed' or 'pi' throttle)"
            )
        return self.outputs(frame, speed)
