"""Atomic file writes and JSON-normalised keys, the bottom of every resumable artefact.

Every resumable artefact of uvnav — a stage of the stage cache (:mod:`uvnav.bench.stages`: a
Chapter 5 data set or network, a Chapter 6 or 7 stage), a per-epoch training state, a
checkpoint — is written through :func:`write_atomic`: the bytes go to a temporary file in the
destination's folder, are flushed and ``fsync``-ed, and the file is renamed over the destination
(``os.replace``, atomic on POSIX and Windows).  An interrupted or failing writer leaves the
previous file (or none), never a partial one that a resumed run would trust.
:func:`normalise_key` is a key as it reads back from JSON, which the stage cache hashes.

Standard library only (no torch, no numpy, no other uvnav module), so any layer may use it.
"""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any


def write_atomic(path: Path | str, content: bytes | str | Callable[[IO[bytes]], None]) -> Path:
    """Write ``path`` atomically: a temporary file in its folder, fsync, then ``os.replace``.

    Args:
        path: destination (its folder is created).
        content: bytes, text (UTF-8) or a function writing to the open binary file.

    Returns:
        ``path``.

    Raises:
        Whatever ``content`` raises: the temporary file is removed and ``path`` is untouched.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            if isinstance(content, str):
                fh.write(content.encode("utf-8"))
            elif isinstance(content, bytes | bytearray | memoryview):
                fh.write(content)
            else:
                content(fh)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    _fsync_dir(path.parent)
    return path


def _fsync_dir(folder: Path) -> None:
    """Make a rename durable (POSIX; a no-op where folders cannot be opened)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        with contextlib.suppress(OSError):
            os.fsync(fd)
    finally:
        os.close(fd)


def _json_default(value: Any) -> Any:
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return value.tolist()
    if hasattr(value, "item"):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not JSON-able")


def normalise_key(key: Any) -> Any:
    """``key`` as it reads back from JSON (tuples → lists, numpy → numbers, paths → strings).

    Raises:
        ValueError: a NaN/±inf (a key that could never match itself again).
        TypeError: a value JSON cannot hold.
    """
    return json.loads(json.dumps(key, default=_json_default, allow_nan=False, sort_keys=True))


__all__ = ["normalise_key", "write_atomic"]
