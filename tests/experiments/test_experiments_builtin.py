"""One experiment at a time (``uvnav reproduce NAME``): every reproduction adds to the store,
none deletes."""

from __future__ import annotations

from pathlib import Path

import pytest

from uvnav.bench.store import ResultsStore
from uvnav.experiments import ExperimentContext, ExperimentError, run_experiment
from uvnav.experiments import ch3 as r3
from uvnav.experiments.sections import SECTIONS_DIR, ChapterSection, load_sections, save_section


@pytest.fixture
def no_prediction(monkeypatch: pytest.MonkeyPatch) -> None:
    """Chapter 3's AR-vs-constant prediction errors and the what-prediction-buys comparison
    take seconds to minutes (tested in test_experiments_ch3)."""
    fake = {"ar_rms": 1.0, "constant_rms": 2.0, "series": 1.0, "ratio": 0.5}
    monkeypatch.setattr(r3, "prediction_errors", lambda: fake)
    monkeypatch.setattr(r3, "prediction_study", lambda store, **kw: {})


def _keys(db: Path, campaign: str) -> set[tuple[str, str, str, int]]:
    with ResultsStore(db) as store:
        df = store.episodes_frame(campaign)
    return {
        (str(s), str(c), str(p), int(k))
        for s, c, p, k in zip(
            df["scenario"], df["controller"], df["params"], df["seed"], strict=True
        )
    }


def test_a_later_ch3_run_with_one_controller_keeps_the_other_controllers_rows(
    tmp_path: Path, no_prediction: None
) -> None:
    """The bug of issue 16: a Ch. 3 run with one law replaced the campaigns of an earlier run."""
    res = tmp_path / "results"
    db = res / "uvnav.sqlite"
    first = r3.reproduce_ch3(
        res, tmp_path / "report", n_random=1, controllers=("apf3d-v1", "vo3d-v1"), workers=1
    )
    scenes, random = _keys(db, r3.SCENES_CAMPAIGN), _keys(db, r3.RANDOM_CAMPAIGN)
    assert {c for _, c, _, _ in random} == {"apf3d-v1", "vo3d-v1"} and len(random) == 4
    # the same law alone, one more seed: only the new seed runs; vo3d-v1's rows stay
    second = r3.reproduce_ch3(
        res, tmp_path / "report", n_random=2, controllers=("apf3d-v1",), workers=1
    )
    assert _keys(db, r3.SCENES_CAMPAIGN) == scenes
    after = _keys(db, r3.RANDOM_CAMPAIGN)
    assert random < after and len(after) == 6
    assert {k for k in after if k[1] == "vo3d-v1"} == {k for k in random if k[1] == "vo3d-v1"}
    # the table is the run's own (its law and seeds), read from the stored rows
    rand_rows = [r for r in second.table if r["quantity"].startswith("random-ch3 success")]
    assert len(rand_rows) == 2 and all("apf3d-v1" in r["quantity"] for r in rand_rows)
    assert all(r["measured"].endswith("of 2") for r in rand_rows)
    # a chosen seed alone (--seeds 1 --start-seed 1): read back, nothing runs, nothing is lost
    third = r3.reproduce_ch3(
        res, tmp_path / "report", n_random=1, start_seed=1, controllers=("apf3d-v1",), workers=1
    )
    assert _keys(db, r3.RANDOM_CAMPAIGN) == after
    assert {f["seed"] for f in third.failures} <= {1}
    assert first.db_path == second.db_path == db


def test_run_experiment_checks_its_options(tmp_path: Path) -> None:
    def ctx(**kw: int) -> ExperimentContext:
        return ExperimentContext(tmp_path, tmp_path, **kw)

    with pytest.raises(ExperimentError, match="unknown experiment 'ch9'"):
        run_experiment("ch9", ctx())
    with pytest.raises(ExperimentError, match="ch7 runs no random seeds"):
        run_experiment("ch7", ctx(seeds=2))
    with pytest.raises(ExperimentError, match="ch6 runs no random seeds"):
        run_experiment("ch6", ctx(start_seed=3))
    with pytest.raises(ExperimentError, match="--seeds 0: at least one seed"):
        run_experiment("ch3", ctx(seeds=0))
    assert not (tmp_path / "uvnav.sqlite").exists()


def test_run_experiment_ch3_saves_its_section(tmp_path: Path, no_prediction: None) -> None:
    ctx = ExperimentContext(tmp_path / "res", tmp_path / "rep", seeds=1, start_seed=4, workers=1)
    out = run_experiment("ch3", ctx)
    (section,) = out.sections
    assert section.key == "ch3" and "seeds 4–4" in section.intro
    assert out.section_paths == [tmp_path / "res" / SECTIONS_DIR / "ch3.json"]
    assert out.table == out.runs["ch3"].summary.table
    (loaded,) = load_sections(tmp_path / "res" / SECTIONS_DIR)
    assert loaded.rows == section.rows and loaded.intro == section.intro
    assert {k[3] for k in _keys(out.db_path, r3.RANDOM_CAMPAIGN)} == {4}


def test_saved_sections_load_in_report_order_without_missing_files(tmp_path: Path) -> None:
    fig = tmp_path / "a.png"
    fig.write_bytes(b"png")
    gone = tmp_path / "gone.png"
    gone.write_bytes(b"png")
    beyond = ChapterSection("beyond", "Beyond", "b", rows=[{"quantity": "q", "measured": "1"}])
    ch4 = ChapterSection("ch4", "Ch 4", "x")
    ch4.add_files([_file(fig), _file(gone)])
    for s in (beyond, ch4):
        save_section(s, tmp_path / "sections")
    gone.unlink()
    loaded = load_sections(tmp_path / "sections")
    assert [s.key for s in loaded] == ["ch4", "beyond"]
    assert [f.path for f in loaded[0].figures] == [fig.resolve()]
    assert "1 file(s)" in loaded[0].notes[-1]
    assert loaded[1].rows == [{"quantity": "q", "measured": "1"}]
    assert load_sections(tmp_path / "nothing") == []


def _file(p: Path):  # type: ignore[no-untyped-def]
    from uvnav.experiments.sections import SectionFile

    return SectionFile(p, p.stem)
