"""The results database's name, the code fingerprint of stored campaigns, and checked runs.

Every experiment writes into ``<results>/``:data:`DB_NAME`.  A campaign carries
:func:`code_fingerprint` (or that fingerprint extended with the experiment's own code,
:func:`uvnav.bench.store.extend_fingerprint`) in its stored config; :func:`run_checked` refuses to
resume a campaign stored by other code (:class:`~uvnav.bench.store.StaleCampaignError`, one line
naming the campaigns to remove with ``uvnav forget``) before running any, so a table never mixes
episodes of different code and no run deletes another run's episodes.

This module imports only the campaign engine and the store.
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from uvnav.bench.campaign import run_campaign
from uvnav.bench.jobs import Job
from uvnav.bench.store import ResultsStore, StaleCampaignError

#: The results database every reproduction writes, in its results folder.
DB_NAME = "uvnav.sqlite"

#: Package parts whose code decides 2D episode outcomes (hashed by :func:`code_fingerprint`).
FINGERPRINT_PARTS: tuple[str, ...] = (
    "geometry",
    "dynamics",
    "obstacles",
    "sensors",
    "prediction",
    "controllers",
    "sim",
    "scenarios",
    "bench/campaign.py",
    "bench/jobs.py",
)


def code_fingerprint() -> str:
    """Hash of the code and data that decide 2D episode outcomes.

    Covers the sources and scenario files under :data:`FINGERPRINT_PARTS` and the numpy version
    (results are bitwise only for one numpy); not ``viz``, ``cli``, the experiments or other
    packages, so editing those does not invalidate stored results.

    Returns:
        16 hex digits.
    """
    import uvnav

    root = Path(uvnav.__file__).parent
    h = hashlib.sha256(f"{getattr(uvnav, '__version__', '')}|numpy {np.__version__}".encode())
    for part in FINGERPRINT_PARTS:
        base = root / part
        paths = [base] if base.is_file() else sorted(base.rglob("*")) if base.is_dir() else []
        for p in paths:
            if not p.is_file() or p.suffix not in {".py", ".yaml", ".yml", ".json"}:
                continue
            if "__pycache__" in p.parts:
                continue
            h.update(str(p.relative_to(root)).encode())
            h.update(p.read_bytes())
    return h.hexdigest()[:16]


def check_campaigns(store: ResultsStore, configs: dict[str, dict[str, Any]]) -> None:
    """Check that every stored campaign of ``configs`` (name -> config) was made by the same code
    (fingerprint); never deletes one.

    Raises:
        StaleCampaignError: naming every stored campaign whose fingerprint differs (its episodes
            cannot be resumed and would be mixed with new ones; the user removes them).
    """
    stale = []
    for c in store.campaigns():
        cfg = configs.get(c["name"])
        if cfg is not None and c["config"].get("fingerprint") != cfg["fingerprint"]:
            stale.append(c["name"])
    if stale:
        raise StaleCampaignError(
            store.path, stale, f"{'was' if len(stale) == 1 else 'were'} stored by other code"
        )


def run_checked(
    store: ResultsStore,
    plans: Sequence[tuple[str, dict[str, Any], list[Job]]],
    *,
    workers: int,
    progress: bool,
    statuses: bool = False,
) -> dict[str, dict[str, Any]]:
    """Check the stored campaigns of ``plans`` ((name, config, jobs); :func:`check_campaigns`),
    then run each; returns name -> its counts: jobs, ran, skipped, errors, the status counts (with
    ``statuses``) and the wall time [s]."""
    check_campaigns(store, {name: cfg for name, cfg, _ in plans})
    out: dict[str, dict[str, Any]] = {}
    for name, cfg, jobs in plans:
        run = run_campaign(store, name, jobs, config=cfg, workers=workers, progress=progress)
        counts: dict[str, Any] = {"jobs": run.total, "ran": run.ran, "skipped": run.skipped}
        counts["errors"] = run.errors
        if statuses:
            counts["statuses"] = dict(run.statuses)
        out[name] = {**counts, "wall_time": round(run.wall_time, 2)}
    return out
