"""The evidence command (:mod:`uvnav.experiments.evidence`): the figures quoted in the notes and the
docstrings are the recorded ones, and the quick size re-run today equals its record."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from uvnav.experiments import evidence
from uvnav.experiments.evidence import CLAIMS, check_text, read_record, run_claims

ROOT = Path(__file__).resolve().parents[2]
RECORD = ROOT / "docs" / "evidence.json"
NOTES = ROOT / "docs" / "thesis-notes.md"
SOURCES = sorted((ROOT / "src" / "uvnav").rglob("*.py"))


@pytest.fixture(scope="module")
def record() -> dict[str, dict[str, dict[str, float]]]:
    return read_record(RECORD)


def test_check_text_rounds_as_written() -> None:
    figures = {"c": {"path": 8.4195, "pct": 99.5, "n": 1818.0, "neg": -1.528}}
    text = (
        "collides at 8.42 m [ev:c.path]; 8.4 [ev:c.path]; 99.5 % [ev:c.pct]; "
        "1,818 [ev:c.n] episodes; −1.528 [ev:c.neg]"
    )
    assert check_text(text, figures) == (5, [])
    n, problems = check_text("8.43 m [ev:c.path] and 98 % [ev:c.pct]", figures, "notes")
    assert n == 2 and len(problems) == 2
    assert problems[0] == "notes: 8.43 [ev:c.path] but the figure is 8.42"
    _, missing = check_text("3 [ev:c.nothing] 4 [ev:other.path]", figures)
    assert all("names no recorded figure" in p for p in missing) and len(missing) == 2


def test_claims_are_registered_once() -> None:
    with pytest.raises(ValueError, match="registered twice"):
        evidence.claim("ch2-notes", "again")(lambda quick: {})
    with pytest.raises(KeyError, match="unknown evidence claim"):
        run_claims(["no-such-claim"], quick=True)


def test_record_holds_both_sizes_of_every_claim(record: dict[str, dict]) -> None:
    assert set(record["full"]) == set(CLAIMS) == set(record["quick"])
    for key in CLAIMS:
        assert set(record["quick"][key]) <= set(record["full"][key]), key


def test_every_tagged_figure_equals_the_recorded_one(record: dict[str, dict]) -> None:
    """The notes and the docstrings quote the last full run, to the digits they show."""
    total = 0
    problems: list[str] = []
    for path in [NOTES, *SOURCES]:
        n, p = check_text(path.read_text(), record["full"], str(path.relative_to(ROOT)))
        total += n
        problems += p
    assert not problems, "\n".join(problems)
    assert total >= 40, total  # the notes do quote the claims (a guard against lost tags)
    quoted = {
        (m["key"], m["field"]) for m in evidence.TAG.finditer(NOTES.read_text())
    }  # every claim is quoted somewhere in the notes
    assert {k for k, _ in quoted} == set(CLAIMS)


@pytest.mark.slow
@pytest.mark.parametrize("key", sorted(CLAIMS))
def test_quick_run_today_equals_its_record(record: dict[str, dict], key: str) -> None:
    """Re-running the quick size gives the recorded quick figures: a change of behaviour that
    moves a quoted figure fails here until the record (and the notes) are regenerated with
    ``python -m uvnav.experiments.evidence --write docs/evidence.json``.  One test per claim, so the
    test workers share them (the whole quick size is about two CPU-minutes)."""
    fresh = run_claims([key], quick=True)[key]
    figs = record["quick"][key]
    assert set(fresh) == set(figs), key
    tol = CLAIMS[key].rel_tol
    for field, value in figs.items():
        assert math.isclose(fresh[field], value, rel_tol=tol, abs_tol=1e-9), (
            key,
            field,
            fresh[field],
            value,
        )


def test_cli_check_and_errors(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    rec = tmp_path / "r.json"
    evidence.write_record(rec, {"c": {"x": 1.26}}, {"c": {"x": 1.0}})
    assert json.loads(rec.read_text())["full"] == {"c": {"x": 1.26}}
    good, bad = tmp_path / "good.md", tmp_path / "bad.md"
    good.write_text("x is 1.26 [ev:c.x] or 1.3 [ev:c.x]\n")
    bad.write_text("x is 1.2 [ev:c.x]\n")
    assert evidence.main(["--check", str(good), "--record", str(rec)]) == 0
    assert evidence.main(["--check", str(bad), "--record", str(rec)]) == 1
    out = capsys.readouterr()
    assert "bad.md: 1.2 [ev:c.x] but the figure is 1.26" in out.out
    assert evidence.main(["--only", "nope"]) == 2
    assert "error: --only: unknown evidence claim(s): nope" in capsys.readouterr().err
    assert evidence.main(["--check", str(good), "--record", str(tmp_path / "none.json")]) == 2
    assert "error: --record" in capsys.readouterr().err
    assert evidence.main(["--check", str(tmp_path / "none.md"), "--record", str(rec)]) == 2
    assert "none.md: no such file" in capsys.readouterr().err


def test_the_notes_are_checked_from_any_working_directory(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Without arguments, --check reads the checkout's notes and record, wherever it runs."""
    monkeypatch.chdir(tmp_path)
    assert evidence.main(["--check"]) == 0
    assert "0 problem(s)" in capsys.readouterr().err
