"""Safe checkpoints for the Chapter 6 CNN: safetensors weights + a JSON header.

One ``.safetensors`` file holds the weights and, in its string metadata, the network
configuration (``PilotNetConfig`` as JSON) and any training record (loss curves, data counts).
Loading never executes code (no pickle): safetensors reads raw tensors, the configuration is JSON.
A JSON copy of the header is written beside the weights for people and tools.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from uvnav.learning.config import PilotNetConfig

FORMAT = "uvnav-pilotnet-v1"


class NonFiniteWeightsError(ValueError):
    """A network whose weights hold NaN or ±inf (a diverged training): never saved or loaded."""


def non_finite_tensor(state: dict[str, Any]) -> str | None:
    """``"name: k of n values are not finite"`` for the first tensor of ``state`` (a
    ``state_dict``) with a NaN/±inf among its floating-point values, else ``None``."""
    import torch

    for name, t in state.items():
        if not torch.is_tensor(t) or not torch.is_floating_point(t):
            continue
        bad = int((~torch.isfinite(t)).sum())
        if bad:
            return f"{name}: {bad} of {t.numel()} values are not finite"
    return None


def save_checkpoint(model: Any, path: Path | str, *, record: dict[str, Any] | None = None) -> Path:
    """Write ``path`` (``.safetensors``) and ``path.with_suffix('.json')``.

    Args:
        model: a network from :func:`uvnav.learning.pilotnet.build_pilotnet`.
        path: output file.
        record: JSON-able training record stored in the header.

    Returns:
        The weights path.

    Raises:
        NonFiniteWeightsError: a weight is NaN/±inf (nothing is written).
    """
    from safetensors.torch import save_file

    path = Path(path)
    state = {k: v.detach().cpu().contiguous() for k, v in model.state_dict().items()}
    bad = non_finite_tensor(state)
    if bad is not None:
        raise NonFiniteWeightsError(f"{path}: refusing to save a network with {bad}")
    path.parent.mkdir(parents=True, exist_ok=True)
    header = {"format": FORMAT, "config": model.config.to_dict(), "record": json_safe(record or {})}
    save_file(state, str(path), metadata={"uvnav": json.dumps(header, allow_nan=False)})
    path.with_suffix(".json").write_text(json.dumps(header, indent=2, allow_nan=False))
    return path


def json_safe(value: Any) -> Any:
    """``value`` with every NaN/±inf float replaced by ``None`` (strict JSON ``null``: "no value").

    Dicts, lists and tuples are walked; numpy scalars are converted to Python numbers.
    """
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_safe(v) for v in value]
    if hasattr(value, "item") and callable(value.item) and getattr(value, "ndim", None) == 0:
        value = value.item()  # numpy / torch scalar
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def read_header(path: Path | str) -> dict[str, Any]:
    """The JSON header of a checkpoint (no tensors loaded).

    Raises:
        ValueError: not a uvnav PilotNet checkpoint (one line naming the file).
    """
    from safetensors import safe_open

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(2, "No such file or directory", str(path))
    try:
        with safe_open(str(path), framework="pt") as fh:
            meta = fh.metadata() or {}
    except Exception as exc:
        raise ValueError(f"{path}: not a safetensors file ({exc})") from None
    if "uvnav" not in meta:
        raise ValueError(f"{path}: no 'uvnav' header (not a uvnav PilotNet checkpoint)")
    try:
        header: dict[str, Any] = json.loads(meta["uvnav"])
    except json.JSONDecodeError as exc:
        raise ValueError(f"{path}: the 'uvnav' header is not JSON ({exc})") from None
    if not isinstance(header, dict):
        raise ValueError(f"{path}: the 'uvnav' header is not a JSON object")
    if header.get("format") != FORMAT:
        raise ValueError(f"{path}: header format {header.get('format')!r} (expected {FORMAT!r})")
    return header


def load_checkpoint(path: Path | str) -> tuple[Any, dict[str, Any]]:
    """Rebuild the network from a checkpoint: ``(model in eval mode, header)``.

    Raises:
        ValueError: not a uvnav PilotNet checkpoint.
        NonFiniteWeightsError: a weight is NaN/±inf (one line naming the file and the tensor).
    """
    from safetensors.torch import load_file

    from uvnav.learning.pilotnet import build_pilotnet

    header = read_header(path)
    config = header.get("config")
    if not isinstance(config, dict):
        raise ValueError(f"{path}: header field 'config' must be a mapping (got {config!r:.40})")
    try:
        cfg = PilotNetConfig.from_dict(config)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"{path}: header config: {exc}") from None
    try:
        state = load_file(str(path))
    except Exception as exc:  # safetensors raises its own error types
        raise ValueError(f"{path}: unreadable weights ({_first_line(exc)})") from None
    bad = non_finite_tensor(state)
    if bad is not None:
        raise NonFiniteWeightsError(f"{path}: {bad} (a diverged network; retrain it)")
    model = build_pilotnet(cfg)
    try:
        model.load_state_dict(state)
    except RuntimeError as exc:
        raise ValueError(
            f"{path}: the weights do not fit the header config ({_first_line(exc, 1)})"
        ) from None
    model.eval()
    return model, header


def _first_line(exc: BaseException, index: int = 0) -> str:
    lines = [ln.strip() for ln in str(exc).splitlines() if ln.strip()]
    return lines[min(index, len(lines) - 1)] if lines else type(exc).__name__


#: format of the per-epoch training state (:func:`save_training_state`)
TRAINING_STATE_FORMAT = "uvnav-pilotnet-training-state-v1"


def save_training_state(
    path: Path | str,
    *,
    model: Any,
    optimizer: Any,
    generator: Any,
    rng: Any,
    epochs_done: int,
    history: dict[str, Any],
    key: str,
) -> Path:
    """Write everything needed to continue a training run after ``epochs_done`` epochs.

    One safetensors file (no pickle, like :func:`save_checkpoint`): the weights, the optimizer's
    tensors, torch's global and augmentation random states as tensors; the optimizer's
    hyper-parameters, the numpy generator's state, the loss curves and ``key`` (what the run
    is: data and settings) in the JSON metadata.  Written to a temporary name and renamed, so an
    interruption while writing leaves the previous epoch's state.

    Args:
        path: output file.
        model: the network being trained.
        optimizer: its torch optimizer.
        generator: the torch generator of the augmentation.
        rng: the numpy generator of the shuffling.
        epochs_done: finished epochs.
        history: JSON-able loss curves so far.
        key: fingerprint of the run; :func:`load_training_state` refuses another one.

    Returns:
        The path.
    """
    import torch
    from safetensors.torch import save_file

    path = Path(path)
    tensors = {f"model.{k}": v.detach().cpu().contiguous() for k, v in model.state_dict().items()}
    opt = optimizer.state_dict()
    for i, st in opt["state"].items():
        for name, v in st.items():
            tensors[f"opt.{i}.{name}"] = torch.as_tensor(v).detach().cpu().contiguous()
    tensors["rng.torch"] = torch.get_rng_state()
    tensors["rng.generator"] = generator.get_state()
    header = {
        "format": TRAINING_STATE_FORMAT,
        "key": key,
        "epochs_done": epochs_done,
        "history": history,
        "param_groups": opt["param_groups"],
        "numpy_rng": rng.bit_generator.state,
    }
    tmp = path.with_name(path.name + ".tmp")
    save_file(tensors, str(tmp), metadata={"uvnav": json.dumps(header)})
    tmp.replace(path)
    return path


def load_training_state(
    path: Path | str, *, model: Any, optimizer: Any, generator: Any, rng: Any, key: str
) -> tuple[int, dict[str, Any]] | None:
    """Restore a state written by :func:`save_training_state` into the given objects.

    Returns:
        ``(epochs_done, history)``, or ``None`` (nothing restored) when there is no file, it is
        not a training state, it belongs to another run (a different ``key``), or its weights
        are not finite.
    """
    import torch
    from safetensors import safe_open
    from safetensors.torch import load_file

    path = Path(path)
    if not path.is_file():
        return None
    try:
        with safe_open(str(path), framework="pt") as fh:
            header = json.loads((fh.metadata() or {}).get("uvnav", "{}"))
    except Exception:
        return None
    if header.get("format") != TRAINING_STATE_FORMAT or header.get("key") != key:
        return None
    tensors = load_file(str(path))
    if non_finite_tensor({k: v for k, v in tensors.items() if k.startswith("model.")}):
        return None  # a diverged state is not continued: train again from the start
    model.load_state_dict(
        {k.removeprefix("model."): v for k, v in tensors.items() if k.startswith("model.")}
    )
    state: dict[int, dict[str, Any]] = {}
    for k, v in tensors.items():
        if k.startswith("opt."):
            _, i, name = k.split(".", 2)
            state.setdefault(int(i), {})[name] = v
    optimizer.load_state_dict({"state": state, "param_groups": header["param_groups"]})
    torch.set_rng_state(tensors["rng.torch"])
    generator.set_state(tensors["rng.generator"])
    rng.bit_generator.state = header["numpy_rng"]
    return int(header["epochs_done"]), dict(header["history"])
