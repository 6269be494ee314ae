"""The stage cache: named products an experiment computes once and reuses (a trained network, a
planned tour, a generated data set), kept in the results folder beside the results database.

A stage is named and keyed by its inputs (a JSON-able dict): its key is a hash of the name and
the canonical JSON of the inputs, and its files live in ``<results>/stages/<key>/`` with
``stage.json`` = ``{"format", "name", "inputs", "fingerprint", "id", "created", "value"}``.
``fingerprint`` is the code that made it (:func:`stage_fingerprint` of the modules that compute
it, or :func:`uvnav.bench.fingerprint.code_fingerprint`).

* :meth:`StageCache.run` returns the stored stage when its folder holds this name and these inputs
  made by this code; otherwise it calls ``build(work)``, which writes the stage's files into the
  folder ``work`` and returns its JSON-able value, and the finished folder is renamed into place.
  Only a finished stage is ever in ``stages/<key>/``: an interrupt leaves the previous stage (or
  none), never half of one.  ``work`` (``stages/.work-<key>-<fingerprint>``) outlives an
  interrupt, so a builder that resumes from what it finds there (recorded episodes, a training
  state) continues where it stopped.  One process builds a stage at a time (a ``flock`` on
  ``stages/.<key>.lock``; another is refused at once, :class:`~uvnav.bench.store.StoreInUseError`).
* A stage stored under another code fingerprint is refused (:class:`StaleStageError`, one line)
  rather than silently reused or replaced; ``fresh=True`` remakes every stage the run reaches.
* :attr:`Stage.ref` is what a stage built on another puts in its inputs: the other's key and the
  random id of its product, so remaking a stage gives every stage built on it new keys.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import secrets
import shutil
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from datetime import UTC, datetime
from importlib import metadata
from pathlib import Path
from typing import Any

from uvnav.bench.store import (
    StaleCampaignError,
    extend_fingerprint,
    pid_lock,
)
from uvnav.stages import normalise_key, write_atomic

#: the folder of the stages inside a results folder
STAGES_DIR = "stages"
#: the record of a finished stage, inside its folder
STAGE_FILE = "stage.json"
STAGE_FORMAT = "uvnav-stage-v2"


class StaleStageError(StaleCampaignError):
    """A stage whose inputs are stored, made by other code: refused (one line naming the stage,
    its folder and how to remake it) instead of reusing or replacing another run's product."""

    def __init__(self, folder: str | Path, name: str, stored: str, now: str) -> None:
        RuntimeError.__init__(
            self,
            f"stage {name!r} in {folder} was made by other code (fingerprint {stored}, now "
            f"{now}); it is kept, not mixed with new results: remake it with --fresh or use "
            "another --results folder",
        )
        self.db = Path(folder)
        self.campaigns = [name]


def stage_fingerprint(*parts: str, packages: tuple[str, ...] = ("numpy",)) -> str:
    """The fingerprint of the code that makes a stage: uvnav's version, the installed versions
    of ``packages`` and the files under ``parts`` (paths relative to the ``uvnav`` package,
    :func:`uvnav.bench.store.extend_fingerprint`).

    Returns:
        16 hex digits.
    """
    import uvnav

    versions = [f"uvnav {getattr(uvnav, '__version__', '')}"]
    for pkg in packages:
        try:
            versions.append(f"{pkg} {metadata.version(pkg)}")
        except metadata.PackageNotFoundError:
            versions.append(f"{pkg} absent")
    return extend_fingerprint("|".join(versions), *parts)


def stage_key(name: str, inputs: Mapping[str, Any]) -> str:
    """The key of a stage: 16 hex digits of the hash of its name and canonical inputs."""
    text = json.dumps([name, normalise_key(dict(inputs))], sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class Stage:
    """A finished stage.

    Attributes:
        name: what the experiment calls it.
        key: :func:`stage_key` of its name and inputs.
        folder: its files (``stages/<key>``).
        value: the JSON value its builder returned.
        id: a random id of this product (a remade stage gets a new one).
        reused: it was found stored (not built by this run).
    """

    name: str
    key: str
    folder: Path
    value: Any
    id: str
    reused: bool

    @property
    def ref(self) -> dict[str, str]:
        """What a stage built on this one puts in its inputs."""
        return {"stage": self.name, "key": self.key, "id": self.id}


def _read(path: Path) -> dict[str, Any] | None:
    try:
        rec = json.loads(path.read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError):
        return None
    return rec if isinstance(rec, dict) and rec.get("format") == STAGE_FORMAT else None


@dataclass
class StageCache:
    """The stages of one results folder, made by the code of ``fingerprint``.

    Args:
        results_dir: the results folder (stages in ``results_dir/stages``).
        fingerprint: the code that makes the stages this cache runs.
        fresh: remake every stage :meth:`run` is asked for (once per cache object).

    Attributes:
        reused: names of the stages found stored, in order.
        built: names of the stages built, in order.
    """

    results_dir: Path
    fingerprint: str
    fresh: bool = False
    reused: list[str] = field(default_factory=list)
    built: list[str] = field(default_factory=list)
    _made: set[str] = field(default_factory=set)

    @property
    def folder(self) -> Path:
        """``results_dir/stages``."""
        return Path(self.results_dir) / STAGES_DIR

    def get(self, name: str, inputs: Mapping[str, Any]) -> Stage | None:
        """The stored stage ``name`` of ``inputs`` made by this code (``None``: not stored, or
        ``fresh`` and not yet remade by this cache).

        Raises:
            StaleStageError: it is stored, made by other code, and the cache is not ``fresh``.
        """
        key = stage_key(name, inputs)
        rec = _read(self.folder / key / STAGE_FILE)
        if rec is None or (self.fresh and key not in self._made):
            return None
        if rec.get("fingerprint") != self.fingerprint:
            raise StaleStageError(
                self.folder / key, name, str(rec.get("fingerprint")), self.fingerprint
            )
        return Stage(name, key, self.folder / key, rec.get("value"), str(rec["id"]), True)

    def run(self, name: str, inputs: Mapping[str, Any], build: Callable[[Path], Any]) -> Stage:
        """The stage ``name`` of ``inputs``: the stored one (:meth:`get`), else ``build(work)``'s,
        stored atomically once ``build`` returned (module docstring).

        Raises:
            StaleStageError: stored by other code and not ``fresh``.
            Whatever ``build`` raises: nothing is stored; ``work`` keeps what it wrote.
        """
        found = self.get(name, inputs)
        if found is not None:
            if found.key not in self._made:
                self.reused.append(name)
            return found
        key = stage_key(name, inputs)
        with _building(self.folder / f".{key}.lock", name):
            found = self.get(name, inputs)  # another process may have just finished it
            if found is not None:
                self.reused.append(name)
                return found
            return self._build(name, key, inputs, build)

    def _build(
        self, name: str, key: str, inputs: Mapping[str, Any], build: Callable[[Path], Any]
    ) -> Stage:
        work = self.folder / f".work-{key}-{self.fingerprint}"
        if self.fresh and work.exists() and key not in self._made:
            shutil.rmtree(work)
        work.mkdir(parents=True, exist_ok=True)
        value = build(work)
        stage_id = secrets.token_hex(8)
        record = {
            "format": STAGE_FORMAT,
            "name": name,
            "inputs": normalise_key(dict(inputs)),
            "fingerprint": self.fingerprint,
            "id": stage_id,
            "created": datetime.now(UTC).isoformat(timespec="seconds"),
            "value": value,
        }
        text = json.dumps(record, indent=2, default=_plain)
        write_atomic(work / STAGE_FILE, text)
        self._install(work, self.folder / key)
        self._made.add(key)
        self.built.append(name)
        stored = json.loads(text)["value"]  # as a later run reads it back
        return Stage(name, key, self.folder / key, stored, stage_id, False)

    def _install(self, work: Path, final: Path) -> None:
        """Rename the finished ``work`` folder to ``final`` (a stage it replaces is moved aside
        first and removed after)."""
        old = final.with_name(f".old-{final.name}-{secrets.token_hex(4)}")
        if final.exists():
            os.replace(final, old)
        os.replace(work, final)
        with contextlib.suppress(OSError):
            shutil.rmtree(old)

    def stored(self) -> list[dict[str, Any]]:
        """Every finished stage of the folder: name, key, fingerprint, created (by name, key)."""
        out = []
        for path in sorted(self.folder.glob(f"*/{STAGE_FILE}")):
            rec = _read(path)
            if rec is not None:
                keep = ("name", "fingerprint", "created")
                out.append({"key": path.parent.name, **{k: rec.get(k) for k in keep}})
        return sorted(out, key=lambda r: (str(r["name"]), r["key"]))


@contextlib.contextmanager
def _building(lock: Path, name: str) -> Iterator[None]:
    """Hold the exclusive right to build one stage (:func:`uvnav.bench.store.pid_lock` on
    ``lock``).

    Raises:
        StoreInUseError: another process is building it (at once, without waiting).
    """

    def refused(pid: str) -> str:
        return (f"stage {name!r} in {lock.parent} is being made by another uvnav process (pid "
                f"{pid}); wait for it to finish or use another --results folder")  # fmt: skip

    lock.parent.mkdir(parents=True, exist_ok=True)
    with pid_lock(lock, refused):
        yield


def _plain(value: Any) -> Any:
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON-able")


__all__ = [
    "STAGES_DIR",
    "STAGE_FILE",
    "Stage",
    "StageCache",
    "StaleStageError",
    "stage_fingerprint",
    "stage_key",
]
