"""One resumable stage cache for the reproductions, with atomic file writes.

Every resumable artefact of uvnav — a Chapter 5 data set and learning row, a Chapter 6 stage
(training, readout, DAgger round, closed loop), a per-epoch training state, a checkpoint — is
written through :func:`write_atomic`: the bytes go to a temporary file in the destination's
folder, are flushed and ``fsync``-ed, and the file is renamed over the destination
(``os.replace``, atomic on POSIX and Windows).  An interrupted or failing writer leaves the
previous file (or none), never a partial one that a resumed run would trust.

:class:`Stages` records finished stages as ``<folder>/<name>.json`` =
``{"format", "key", "id", "value"}``:

* :meth:`Stages.get` returns the stored ``value`` when the file exists, its ``key`` equals the
  given one (both JSON-normalised: tuples are lists, numpy scalars numbers, paths strings) and
  the stage's own files (checkpoints, arrays) exist; otherwise ``None`` (compute the stage).
* :meth:`Stages.put` records a computed stage under a new ``id``.
* :meth:`Stages.ref` is what a stage built on another puts in its key: the other's ``id``.  A
  recomputed stage gets a new ``id``, so every stage built on it no longer matches and is
  recomputed too.

A ``stages/`` folder written by the older Chapter 6 code (``{"key", "id", "value"}``, no
``format``) has the same layout and is reused.

Standard library only (no torch, no numpy, no other uvnav module), so any layer may use it.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import secrets
import shutil
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import IO, Any

#: ``format`` of a stage file
STAGE_FORMAT = "uvnav-stage-v1"

_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*$")


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


class Stages:
    """Finished stages in ``folder`` (module docstring).

    Args:
        folder: where ``<name>.json`` files live (created).
        fresh: forget every stage first (the folder is emptied).

    Attributes:
        reused: names of the stages :meth:`get` returned, in order.
    """

    def __init__(self, folder: Path | str, *, fresh: bool = False) -> None:
        self.dir = Path(folder)
        if fresh and self.dir.exists():
            shutil.rmtree(self.dir)
        self.dir.mkdir(parents=True, exist_ok=True)
        self.reused: list[str] = []
        self._ids: dict[str, str] = {}

    def path(self, name: str) -> Path:
        """The stage file of ``name``."""
        if not _NAME.match(name):
            raise ValueError(f"stage name {name!r}: letters, digits, '.', '_' and '-' only")
        return self.dir / f"{name}.json"

    def get(self, name: str, key: Any, files: Iterable[Path | str] = ()) -> Any | None:
        """The stored value of ``name`` if it was computed with ``key`` and its ``files`` exist,
        else ``None``.  A stage file that cannot be read counts as absent."""
        path = self.path(name)
        if not path.is_file() or not all(Path(f).is_file() for f in files):
            return None
        try:
            stored = json.loads(path.read_text())
        except (OSError, UnicodeDecodeError, json.JSONDecodeError):
            return None
        if not isinstance(stored, dict) or stored.get("format", STAGE_FORMAT) != STAGE_FORMAT:
            return None
        if "value" not in stored or stored.get("key") != normalise_key(key):
            return None
        self.reused.append(name)
        self._ids[name] = str(stored.get("id"))
        return stored["value"]

    def put(self, name: str, key: Any, value: Any) -> None:
        """Record ``name`` as computed with ``key`` (a new id); ``value`` must be JSON-able
        (NaN/±inf are kept as JSON's ``NaN``/``Infinity``)."""
        stage_id = secrets.token_hex(8)
        text = json.dumps(
            {"format": STAGE_FORMAT, "key": normalise_key(key), "id": stage_id, "value": value},
            indent=2,
            default=_json_default,
        )
        write_atomic(self.path(name), text)
        self._ids[name] = stage_id

    def ref(self, name: str) -> dict[str, str]:
        """What a stage built on ``name`` puts in its key (``name`` must have been got or put
        by this object)."""
        if name not in self._ids:
            raise KeyError(f"stage {name!r} was neither reused nor computed in this run")
        return {"stage": name, "id": self._ids[name]}


__all__ = ["STAGE_FORMAT", "Stages", "normalise_key", "write_atomic"]
