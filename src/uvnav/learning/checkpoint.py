"""One checkpoint format for uvnav's networks (the Chapter 5 BPNN and the Chapter 6 CNN).

A checkpoint is one ``.safetensors`` file: the weights (and, for the BPNN, its min/max scalers) as
tensors, and in the file's string metadata (key ``uvnav``) a JSON header::

    {"format": "uvnav-checkpoint-v1", "kind": "pilotnet" | "bpnn",
     "config": {...the network's configuration...}, "record": {...training record...}}

A JSON copy of the header is written beside the weights (``<name>.json``) for people and tools;
loading reads the header from the weights file.  Both files are written atomically
(:func:`uvnav.stages.write_atomic`).  Loading never executes code (no pickle: safetensors reads
raw tensors, the header is JSON), refuses another ``format`` or ``kind`` in one line, and
refuses weights that are NaN/±inf (:class:`NonFiniteWeightsError`).

:func:`read_header` reads either kind without torch; :func:`read_checkpoint` returns a kind's
tensors (numpy arrays, or torch tensors with ``framework="pt"``) and header;
:func:`save_checkpoint`/:func:`load_checkpoint` are the CNN's (the BPNN's are
:func:`uvnav.learning.bpnn.save_checkpoint`/``load_checkpoint``, through the same functions).

Older checkpoints still load (legacy readers, kept for the files already on disk):

* ``uvnav-pilotnet-v1`` — the CNN's header before this format: the same layout without
  ``kind``;
* ``uvnav-bpnn-v1`` — the BPNN's: a safetensors file without metadata and the header
  (``config``, ``n_layers``, ``history``, ``best_epoch``, ``stop_reason``, ``split``) only in the
  ``.json`` beside it.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from uvnav.learning.config import PilotNetConfig
from uvnav.stages import write_atomic

#: the one checkpoint format
FORMAT = "uvnav-checkpoint-v1"
#: the networks it holds
KINDS: tuple[str, ...] = ("pilotnet", "bpnn")
#: legacy formats still read: the CNN's former header (no ``kind``) ...
LEGACY_PILOTNET_FORMAT = "uvnav-pilotnet-v1"
#: ... and the BPNN's former checkpoint (header only in the JSON file beside the weights)
LEGACY_BPNN_FORMAT = "uvnav-bpnn-v1"


class CheckpointError(ValueError):
    """A file that is not a valid uvnav checkpoint of the expected kind (one-line message)."""


class NonFiniteWeightsError(CheckpointError):
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


def first_non_finite(arrays: dict[str, Any]) -> str | None:
    """Where the first NaN/±inf of some named arrays is (``"name[i, j] = nan"``), or ``None``."""
    for name, value in arrays.items():
        a = np.asarray(value, dtype=float)
        bad = np.argwhere(~np.isfinite(a))
        if len(bad):
            where = tuple(int(i) for i in bad[0])
            index = ", ".join(str(i) for i in where)
            return f"{name}[{index}] = {float(a[where])}" if where else f"{name} = {float(a)}"
    return None


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


def _is_torch(tensors: dict[str, Any]) -> bool:
    return any(type(v).__module__.startswith("torch") for v in tensors.values())


def write_checkpoint(
    path: Path | str, tensors: dict[str, Any], *, kind: str, config: dict[str, Any],
    record: dict[str, Any] | None = None,
) -> Path:  # fmt: skip
    """Write a checkpoint ``path`` (``.safetensors``) and its header's JSON copy beside it.

    Args:
        path: the weights file; the copy is ``path.with_suffix('.json')``.
        tensors: named weights, all torch tensors or all numpy arrays.
        kind: one of :data:`KINDS`.
        config: the network's configuration (JSON-able).
        record: the training record (JSON-able; NaN/±inf become ``null``).

    Returns:
        ``path``.

    Raises:
        NonFiniteWeightsError: a weight is NaN/±inf (nothing is written).
    """
    if kind not in KINDS:
        raise ValueError(f"kind {kind!r} (must be one of {', '.join(KINDS)})")
    path = Path(path)
    header = {"format": FORMAT, "kind": kind, "config": config, "record": json_safe(record or {})}
    meta = {"uvnav": json.dumps(header, allow_nan=False)}
    if _is_torch(tensors):
        from safetensors.torch import save as save_torch

        bad = non_finite_tensor(tensors)
        if bad is not None:
            raise NonFiniteWeightsError(f"{path}: refusing to save a network with {bad}")
        data = save_torch({k: v.detach().cpu().contiguous() for k, v in tensors.items()}, meta)
    else:
        from safetensors.numpy import save as save_numpy

        bad = first_non_finite(tensors)
        if bad is not None:
            raise NonFiniteWeightsError(f"{path}: refusing to save a network with {bad}")
        data = save_numpy({k: np.ascontiguousarray(v) for k, v in tensors.items()}, meta)
    write_atomic(path, data)
    write_atomic(path.with_suffix(".json"), json.dumps(header, indent=2, allow_nan=False))
    return path


def weights_path(path: Path | str) -> Path:
    """The weights file of ``path``: itself, or the ``.safetensors`` beside a ``.json`` copy or
    a stem (the BPNN's ``--out`` names)."""
    p = Path(path)
    if p.suffix == ".json" or (not p.is_file() and p.suffix != ".safetensors"):
        return p.with_suffix(".safetensors")
    return p


def read_header(path: Path | str) -> dict[str, Any]:
    """The JSON header of a checkpoint of either kind (no tensors loaded, no torch needed).

    A legacy header is returned in the current shape (``kind`` added; a ``uvnav-bpnn-v1``
    BPNN's history, best epoch, stop reason and split under ``record``) with its ``format``.

    Raises:
        FileNotFoundError: no such file.
        CheckpointError: not a uvnav checkpoint, or another ``format`` (one line naming the file).
    """
    from safetensors import safe_open

    path = weights_path(path)
    if not path.is_file():
        raise FileNotFoundError(2, "No such file or directory", str(path))
    try:
        with safe_open(str(path), framework="numpy") as fh:
            meta = fh.metadata() or {}
    except Exception as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise CheckpointError(f"{path}: not a safetensors checkpoint ({first})") from None
    if "uvnav" not in meta:
        return _legacy_bpnn_header(path)
    try:
        header = json.loads(meta["uvnav"])
    except json.JSONDecodeError:
        raise CheckpointError(f"{path}: the 'uvnav' header is not valid JSON") from None
    if not isinstance(header, dict):
        raise CheckpointError(f"{path}: the 'uvnav' header is not a JSON object")
    fmt = header.get("format")
    if fmt == LEGACY_PILOTNET_FORMAT:
        header = {**header, "kind": "pilotnet"}
    elif fmt != FORMAT:
        raise CheckpointError(f"{path}: header format {fmt!r} (expected {FORMAT!r})")
    if header.get("kind") not in KINDS:
        raise CheckpointError(f"{path}: header kind {header.get('kind')!r} (one of {KINDS})")
    config = header.get("config")
    if not isinstance(config, dict):
        raise CheckpointError(
            f"{path}: header field 'config' must be a mapping (got {config!r:.40})"
        )
    header.setdefault("record", {})
    return header


def _legacy_bpnn_header(path: Path) -> dict[str, Any]:
    """Legacy reader: a ``uvnav-bpnn-v1`` checkpoint (weights without metadata, the header in
    the ``.json`` beside them), as the BPNN wrote it before the one format."""
    js = path.with_suffix(".json")
    if not js.is_file():
        raise CheckpointError(f"{path}: no 'uvnav' header (not a uvnav checkpoint)")
    try:
        meta = json.loads(js.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise CheckpointError(f"{js}: not valid JSON ({exc.__class__.__name__})") from None
    if not isinstance(meta, dict) or meta.get("format") != LEGACY_BPNN_FORMAT:
        raise CheckpointError(f"{path}: no 'uvnav' header (not a uvnav checkpoint)")
    if not isinstance(meta.get("config"), dict):
        raise CheckpointError(f"{js}: no 'config' object")
    record = {k: meta[k] for k in ("history", "best_epoch", "stop_reason", "split") if k in meta}
    return {
        "format": LEGACY_BPNN_FORMAT,
        "kind": "bpnn",
        "config": meta["config"],
        "record": record,
    }


def read_checkpoint(
    path: Path | str, kind: str, *, framework: str = "numpy"
) -> tuple[dict[str, Any], dict[str, Any]]:
    """The tensors and header of a checkpoint of ``kind``.

    Args:
        path: the weights file (or its JSON copy, or the stem).
        kind: the network expected.
        framework: ``"numpy"`` (arrays; no torch) or ``"pt"`` (torch tensors).

    Raises:
        FileNotFoundError: no such file.
        CheckpointError: not a uvnav checkpoint, another format or kind.
        NonFiniteWeightsError: a weight is NaN/±inf (one line naming the file and the tensor).
    """
    path = weights_path(path)
    header = read_header(path)
    if header["kind"] != kind:
        raise CheckpointError(f"{path}: a {header['kind']} checkpoint (expected {kind})")
    try:
        if framework == "pt":
            from safetensors.torch import load_file as load_torch

            tensors: dict[str, Any] = load_torch(str(path))
            bad = non_finite_tensor(tensors)
        else:
            from safetensors.numpy import load_file as load_numpy

            tensors = load_numpy(str(path))
            bad = first_non_finite(tensors)
            bad = None if bad is None else f"{bad} is not a finite number"
    except Exception as exc:  # safetensors' own error is no OSError/ValueError
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise CheckpointError(f"{path}: not a safetensors checkpoint ({first})") from None
    if bad is not None:
        raise NonFiniteWeightsError(f"{path}: {bad} (a diverged network; retrain it)")
    return tensors, header


def save_checkpoint(model: Any, path: Path | str, *, record: dict[str, Any] | None = None) -> Path:
    """Write the CNN ``model`` to ``path`` (``.safetensors``) and ``path.with_suffix('.json')``.

    Args:
        model: a network from :func:`uvnav.learning.pilotnet.build_pilotnet`.
        path: output file.
        record: JSON-able training record stored in the header.

    Returns:
        The weights path.

    Raises:
        NonFiniteWeightsError: a weight is NaN/±inf (nothing is written).
    """
    return write_checkpoint(
        path, model.state_dict(), kind="pilotnet", config=model.config.to_dict(), record=record
    )


def load_checkpoint(path: Path | str) -> tuple[Any, dict[str, Any]]:
    """Rebuild the CNN from a checkpoint: ``(model in eval mode, header)``.

    Raises:
        FileNotFoundError: no such file.
        CheckpointError: not a uvnav PilotNet checkpoint.
        NonFiniteWeightsError: a weight is NaN/±inf (one line naming the file and the tensor).
    """
    from uvnav.learning.pilotnet import build_pilotnet

    state, header = read_checkpoint(path, "pilotnet", framework="pt")
    try:
        config = PilotNetConfig.from_dict(header["config"])
    except (TypeError, ValueError) as exc:
        raise CheckpointError(f"{weights_path(path)}: config: {exc}") from None
    model = build_pilotnet(config)
    try:
        model.load_state_dict(state)
    except RuntimeError as exc:
        raise CheckpointError(
            f"{weights_path(path)}: the weights do not fit the header config "
            f"({_first_line(exc, 1)})"
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
    is: data and settings) in the JSON metadata.  Written atomically
    (:func:`uvnav.stages.write_atomic`), so an interruption while writing leaves the previous
    epoch's state.

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
    from safetensors.torch import save as save_torch

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
    write_atomic(path, save_torch(tensors, metadata={"uvnav": json.dumps(header)}))
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
