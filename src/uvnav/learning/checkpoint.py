"""Safe checkpoints for the Chapter 6 CNN: safetensors weights + a JSON header.

One ``.safetensors`` file holds the weights and, in its string metadata, the network
configuration (``PilotNetConfig`` as JSON) and any training record (loss curves, data counts).
Loading never executes code (no pickle): safetensors reads raw tensors, the configuration is JSON.
A JSON copy of the header is written beside the weights for people and tools.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from uvnav.learning.config import PilotNetConfig

FORMAT = "uvnav-pilotnet-v1"


def save_checkpoint(model: Any, path: Path | str, *, record: dict[str, Any] | None = None) -> Path:
    """Write ``path`` (``.safetensors``) and ``path.with_suffix('.json')``.

    Args:
        model: a network from :func:`uvnav.learning.pilotnet.build_pilotnet`.
        path: output file.
        record: JSON-able training record stored in the header.

    Returns:
        The weights path.
    """
    from safetensors.torch import save_file

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    header = {"format": FORMAT, "config": model.config.to_dict(), "record": record or {}}
    state = {k: v.detach().cpu().contiguous() for k, v in model.state_dict().items()}
    save_file(state, str(path), metadata={"uvnav": json.dumps(header)})
    path.with_suffix(".json").write_text(json.dumps(header, indent=2))
    return path


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
    header: dict[str, Any] = json.loads(meta["uvnav"])
    if header.get("format") != FORMAT:
        raise ValueError(f"{path}: header format {header.get('format')!r} (expected {FORMAT!r})")
    return header


def load_checkpoint(path: Path | str) -> tuple[Any, dict[str, Any]]:
    """Rebuild the network from a checkpoint: ``(model in eval mode, header)``."""
    from safetensors.torch import load_file

    from uvnav.learning.pilotnet import build_pilotnet

    header = read_header(path)
    model = build_pilotnet(PilotNetConfig.from_dict(header["config"]))
    model.load_state_dict(load_file(str(path)))
    model.eval()
    return model, header
