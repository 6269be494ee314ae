"""Chapters 3, 4 and 5 at their smallest size: a run interrupted after k episodes keeps them, its
resume stores what an uninterrupted run stores, and a resume over a campaign stored by other code
(another fingerprint) is refused in one line, from the library and from ``uvnav reproduce``."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

import pytest
from typer.testing import CliRunner

from uvnav.bench.store import FINGERPRINT_KEY, ResultsStore, StaleCampaignError
from uvnav.cli.app import app
from uvnav.experiments import ch3 as r3
from uvnav.experiments import ch4 as r4

Run = Callable[[Path], Any]


@pytest.fixture
def fast_ch3(monkeypatch: pytest.MonkeyPatch) -> None:
    """Chapter 3's prediction figures that are never stored (errors on sampled series, how
    often the AR fits were used) are constants here: every stored episode runs for real."""
    fake = {"ar_rms": 1.0, "constant_rms": 2.0, "series": 1.0, "ratio": 0.5}
    monkeypatch.setattr(r3, "prediction_errors", lambda: fake)
    errors = {f"{q}{k}_{m}": 1.0 for q in "vp" for k in r3.HORIZONS for m in ("ar", "cv")}
    monkeypatch.setattr(r3, "horizon_errors", lambda motion: {**errors, "series": 1.0})
    monkeypatch.setattr(r3, "ar_usage", lambda fam, seeds: {"decisions": 1.0, "ar_share": 1.0})


def _ch3(results: Path) -> Any:
    """2 laws on the thesis scenes (figures asked for: the scenes run recorded), 1 random scene
    (known and predicted motion), 1 seed of the prediction study: 16 episodes."""
    return r3.reproduce_ch3(
        results, results / "report", n_random=1, controllers=("apf3d-v1", "vo3d-v1"),
        prediction_seeds=1, workers=1, render=lambda db, report, recorded: [],
    )  # fmt: skip


def _ch4(results: Path) -> Any:
    """The thesis scenes and 1 seed of each random campaign: 27 episodes."""
    return r4.reproduce_ch4(results, seeds=1, noise_seeds=1, hard_seeds=1)


def _ch5(results: Path) -> Any:
    """No learning rows but the closed-loop network's (60 samples), one thesis scene and one
    random scene with every locator: 6 episodes."""
    from uvnav.experiments import ch5 as r5

    return r5.reproduce_ch5(
        results, sizes=(), n_seeds=0, literal_seeds=0, n_random=1, n_test=30,
        scenes=["thesis-ch5-scene1"], closed_loop_samples=60, progress=False,
    )  # fmt: skip


def _chapter(name: str) -> tuple[ModuleType, Run]:
    if name == "ch5":
        pytest.importorskip("torch")
        from uvnav.experiments import ch5 as r5

        return r5, _ch5
    return (r3, _ch3) if name == "ch3" else (r4, _ch4)


#: (chapter, episodes run before the interrupt, a campaign the run stores)
CASES = [
    ("ch3", 3, r3.SCENES_CAMPAIGN),  # in the thesis scenes' recorded rerun
    ("ch3", 12, r3.PREDICTION_CAMPAIGN),  # in the prediction study
    ("ch4", 15, r4.NOISE_CAMPAIGN),  # in the noise sweep
    ("ch5", 4, "ch5-random"),  # in the random campaign
]


@pytest.mark.usefixtures("fast_ch3")
@pytest.mark.parametrize(("chapter", "k", "campaign"), CASES)
def test_an_interrupted_run_keeps_its_episodes_and_resumes_to_the_same_rows(
    chapter: str,
    k: int,
    campaign: str,
    tmp_path: Path,
    interrupt_after: Any,
    stored_rows: Any,
    set_fingerprint: Any,
) -> None:
    _, run = _chapter(chapter)
    run(tmp_path / "whole")
    expected = stored_rows(tmp_path / "whole" / "uvnav.sqlite")
    parts = tmp_path / "parts"
    seen = interrupt_after(k)
    with pytest.raises(KeyboardInterrupt):
        run(parts)
    db = parts / "uvnav.sqlite"
    kept = stored_rows(db)
    # every episode that finished is stored (the thesis scenes of Ch. 4 and 5 rerun and are
    # stored as they finish too), and each is an uninterrupted run's
    assert sum(map(len, kept.values())) == k == len(seen.before)
    assert all(set(rows) <= set(expected[name]) for name, rows in kept.items())
    run(parts)  # the resume
    assert stored_rows(db) == expected
    set_fingerprint(db, campaign)  # as if other code had stored it
    seen.after.clear()
    with pytest.raises(StaleCampaignError) as err:
        run(parts)
    message = str(err.value)
    assert "\n" not in message and f"'{campaign}'" in message and "uvnav forget" in message
    assert seen.after == [] and stored_rows(db) == expected  # refused before anything ran


def _stale_store(results: Path, campaign: str) -> Path:
    """A results database holding ``campaign`` as other code stored it (one episode)."""
    db = results / "uvnav.sqlite"
    with ResultsStore(db) as store:
        cid = store.campaign(campaign, {FINGERPRINT_KEY: "0" * 16})
        store.add_episode(cid, scenario="s", controller="c", seed=0, status="success")
    return db


@pytest.mark.parametrize(
    ("chapter", "campaign"),
    [("ch3", r3.RANDOM_CAMPAIGN), ("ch4", r4.HARD_CAMPAIGN), ("ch5", "ch5-thesis-scenes")],
)
def test_uvnav_reproduce_refuses_a_stale_campaign_in_one_line(
    chapter: str, campaign: str, tmp_path: Path, interrupt_after: Any
) -> None:
    _chapter(chapter)
    seen = interrupt_after(0)  # no episode may run
    results = tmp_path / "res"
    db = _stale_store(results, campaign)
    out = CliRunner().invoke(
        app, ["reproduce", chapter, "--seeds", "1", "--workers", "1", "--results", str(results),
              "--report", str(tmp_path / "rep")],
    )  # fmt: skip
    assert out.exit_code == 2, out.output
    (line,) = out.stderr.strip().splitlines()
    assert line.startswith(f"error: campaign '{campaign}' in {db} was stored by other code")
    assert f"'uvnav forget {db} {campaign}'" in line and "Traceback" not in out.output
    assert not seen.fired and not seen.before
    with ResultsStore(db, readonly=True) as store:
        assert [c["name"] for c in store.campaigns()] == [campaign] and store.count() == 1
