"""Shared set-up of the chapter reproduction tests: interrupting a run after k episodes, the
stored rows of a results database in a comparable form, and a campaign made stale."""

from __future__ import annotations

import json
import sqlite3
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from uvnav.bench.store import FINGERPRINT_KEY, ResultsStore

#: metrics that measure this machine's speed, not the episode (they differ run to run)
TIMING_METRICS = ("decision_us_median", "decision_us_p99")
#: columns of a stored row that say when or how fast it ran, not what it measured
NOT_COMPARED = ("id", "campaign_id", "created", "wall_time", *TIMING_METRICS)


@dataclass
class Interruption:
    """What :func:`interrupt_after` saw: the episodes run before the interrupt and after it."""

    before: list[str] = field(default_factory=list)
    after: list[str] = field(default_factory=list)
    fired: bool = False


@pytest.fixture
def interrupt_after(monkeypatch: pytest.MonkeyPatch) -> Callable[..., Interruption]:
    """``interrupt_after(k)``: the one scene runner
    (:func:`uvnav.scenarios.episodes.run_scene`, which every campaign job runs through) raises
    :class:`KeyboardInterrupt` (a Ctrl-C) once, when asked for episode ``k + 1``; the episodes
    asked for after that run as usual (a resumed run)."""
    import uvnav.scenarios.episodes as episodes

    def arm(k: int) -> Interruption:
        real = episodes.run_scene
        seen = Interruption()

        def runner(resolved: Any, law: Any = None, *args: Any, **kw: Any) -> Any:
            if not seen.fired and len(seen.before) == k:
                seen.fired = True
                raise KeyboardInterrupt
            (seen.after if seen.fired else seen.before).append(f"{resolved.spec} {law}")
            return real(resolved, law, *args, **kw)

        monkeypatch.setattr(episodes, "run_scene", runner)
        return seen

    return arm


Rows = dict[str, list[tuple[Any, ...]]]


def _stored_rows(db: Path) -> Rows:
    """Every campaign's episodes (campaign name -> rows sorted by resume key), each row its
    columns but those of :data:`NOT_COMPARED`, as comparable tuples."""
    out: Rows = {}
    with ResultsStore(db, readonly=True) as store:
        for c in store.campaigns():
            frame = store.episodes_frame(c["name"]).drop(columns=list(NOT_COMPARED))
            rows = frame.astype(object).where(frame.notna(), None).to_dict("records")
            out[c["name"]] = sorted(tuple(sorted(r.items())) for r in rows)
    return out


def _set_fingerprint(db: Path, campaign: str, fingerprint: str = "0" * 16) -> None:
    """Give a stored campaign another code fingerprint (as if other code had stored it)."""
    conn = sqlite3.connect(db)
    try:
        (config,) = conn.execute(
            "SELECT config FROM campaigns WHERE name = ?", (campaign,)
        ).fetchone()
        cfg = {**json.loads(config), FINGERPRINT_KEY: fingerprint}
        with conn:
            conn.execute(
                "UPDATE campaigns SET config = ? WHERE name = ?", (json.dumps(cfg), campaign)
            )
    finally:
        conn.close()


@pytest.fixture
def stored_rows() -> Callable[[Path], Rows]:
    """``stored_rows(db)``: every campaign's rows, comparable between two runs."""
    return _stored_rows


@pytest.fixture
def set_fingerprint() -> Callable[..., None]:
    """``set_fingerprint(db, campaign)``: the campaign now looks stored by other code."""
    return _set_fingerprint
