"""``benchmarks/paired_crowdnav.py``: two runs on the same cases compared case by case, and a
file that cannot be paired refused in one line with exit status 2."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import pytest

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))

import paired_crowdnav as paired  # noqa: E402


def _write(path: Path, statuses: list[str], **extra: Any) -> Path:
    run = {"law": "zhang2019-v2", "kinematics": "turn-then-move", "humans": 20,
           "rule": "circle_crossing", "case_numbers": list(range(100, 100 + len(statuses))),
           "statuses": statuses, "accel_max": 1.0, "turn_accel_max": 2.0, **extra}  # fmt: skip
    path.write_text(json.dumps(run))
    return path


def test_the_runs_are_compared_case_by_case(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a = _write(tmp_path / "a.json", ["success"] * 8 + ["collision", "timeout"])
    b = _write(tmp_path / "b.json", ["collision", "timeout"] + ["success"] * 6 + ["timeout"] * 2,
               accel_max=None, turn_accel_max=None)  # fmt: skip
    assert paired.main([str(a), str(b)]) == 0
    out = capsys.readouterr().out
    assert "won alone 2" in out and "won alone 0" in out  # cases 100-101 by A alone
    c = paired.compare(paired.load_run(a), paired.load_run(b), ("a", "b"))
    assert c["difference"] == pytest.approx(0.2) and c["ci95"][0] < 0.2 < c["ci95"][1]
    assert all(len(line) <= 80 for line in out.splitlines())
    assert "limits 1 m/s^2" in out and out.count("limits") == 1


@pytest.mark.parametrize(
    ("text", "problem"),
    [("{not json", "cannot be read as JSON"), ("[1, 2]", "not a bench_crowdnav.py results"),
     ('{"statuses": []}', "field 'case_numbers' missing"),
     ('{"case_numbers": [1], "statuses": []}', "1 case numbers for 0 statuses")],
)  # fmt: skip
def test_a_file_that_cannot_be_paired_is_refused_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, problem: str
) -> None:
    good = _write(tmp_path / "good.json", ["success"])
    bad = tmp_path / "bad.json"
    bad.write_text(text)
    assert paired.main([str(good), str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and str(bad) in err and problem in err


def test_runs_on_other_cases_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a = _write(tmp_path / "a.json", ["success"] * 3)
    b = _write(tmp_path / "b.json", ["success"] * 4)
    assert paired.main([str(a), str(b)]) == 2
    assert "'case_numbers' differs" in capsys.readouterr().err
