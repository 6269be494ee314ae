"""torch, imported on demand with a clear message when the ``learning`` extra is missing."""

from __future__ import annotations

from typing import Any


def require_torch(max_threads: int | None = None) -> Any:
    """The ``torch`` module; with ``max_threads``, torch's intra-op threads capped to it.

    Raises:
        ImportError: torch is not installed (names the extra to install).
    """
    try:
        import torch
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(
            "uvnav.learning needs torch: pip install 'uvnav[learning]' (torch==2.13.0 first)"
        ) from exc
    if max_threads is not None:
        torch.set_num_threads(min(max_threads, max(1, torch.get_num_threads())))
    return torch
