"""The results database's name and the code fingerprint of stored campaigns.

Every experiment writes into ``<results>/``:data:`DB_NAME`.  A campaign carries
:func:`code_fingerprint` (or that fingerprint extended with the experiment's own code,
:func:`uvnav.bench.store.extend_fingerprint`) in its stored config, and a run refuses to resume a
campaign stored by other code (:class:`~uvnav.bench.store.StaleCampaignError`;
:func:`uvnav.experiments.campaigns.run_checked`), so a table never mixes episodes of different
code and no run deletes another run's episodes.

This module imports no other module of uvnav at import time (the Ray engine's workers import it).
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np

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
