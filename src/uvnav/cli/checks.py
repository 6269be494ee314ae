"""Guards shared by the CLI's commands: finite numeric options and strict JSON output.

* :func:`finite` is a Typer/click option callback: ``--set-speed nan`` or ``--lr inf`` is a usage
  error (one ``error:`` line, exit status 2) instead of a NaN that flows into a model or a
  controller.  click's ``min=``/``max=`` bounds do not catch NaN (every comparison with NaN is
  false), so options with bounds need it too.
* :func:`json_safe` / :func:`dumps` print strict JSON (RFC 8259): a NaN or ±inf float, which
  means "no value" in our results, becomes ``null``; bare ``NaN``/``Infinity`` tokens, which
  other JSON readers refuse, are never printed.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import Any

import numpy as np
import typer


def finite(value: float | None) -> float | None:
    """Option callback: ``value`` unchanged when finite (or ``None``: option not given).

    Raises:
        typer.BadParameter: ``value`` is NaN or ±inf (click names the option).
    """
    if value is not None and not math.isfinite(value):
        raise typer.BadParameter(f"{value} is not a finite number")
    return value


def unit_range(value: float | None) -> float | None:
    """Option callback: ``value`` unchanged when finite and within [-1, 1].

    Raises:
        typer.BadParameter: ``value`` is NaN, ±inf or outside [-1, 1].
    """
    finite(value)
    if value is not None and not -1.0 <= value <= 1.0:
        raise typer.BadParameter(f"must be within [-1, 1] (got {value})")
    return value


#: a local process pool runs at most this many workers per CPU of the machine
WORKERS_PER_CPU = 4


def max_pool_workers() -> int:
    """The most worker processes a local pool may start here: :data:`WORKERS_PER_CPU` per CPU
    (episodes are CPU-bound; more would only queue, each holding its memory)."""
    return WORKERS_PER_CPU * (os.cpu_count() or 1)


def too_many_workers(value: int | None) -> str | None:
    """Why ``value`` workers are too many for a local process pool (more than
    :func:`max_pool_workers`: ``--workers 100000`` would start one process per episode), or
    ``None``."""
    if value is None or value <= max_pool_workers():
        return None
    return f"{value} is more than {WORKERS_PER_CPU} per CPU of this machine ({max_pool_workers()})"


def pool_workers(value: int | None) -> int | None:
    """Option callback of ``--workers`` for a local process pool (:func:`too_many_workers`).

    Raises:
        typer.BadParameter: too many (click names the option).
    """
    problem = too_many_workers(value)
    if problem is not None:
        raise typer.BadParameter(problem)
    return value


def json_safe(value: Any) -> Any:
    """``value`` as plain JSON-able data with every NaN/±inf float replaced by ``None``.

    Dicts, lists and tuples are walked; numpy scalars and arrays become Python numbers and lists;
    paths become strings.  Anything else is returned unchanged (``json.dumps`` decides).
    """
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_safe(v) for v in value]
    if isinstance(value, np.ndarray):
        return json_safe(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def dumps(data: Any, *, indent: int | None = None, default: Any = None) -> str:
    """Strict JSON text of ``data`` (non-finite floats as ``null``; never bare ``NaN``).

    Raises:
        TypeError: a value ``json`` cannot serialise (and ``default`` does not handle).
    """
    return json.dumps(json_safe(data), indent=indent, default=default, allow_nan=False)
