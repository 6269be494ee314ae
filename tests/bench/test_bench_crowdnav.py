"""``benchmarks/bench_crowdnav.py``: the crowd size and the reported social figures (one short
episode each)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest

BENCH = Path(__file__).resolve().parents[2] / "benchmarks"
if str(BENCH) not in sys.path:
    sys.path.insert(0, str(BENCH))

import bench_crowdnav  # noqa: E402


def test_humans_sets_the_crowd_size_of_every_case(monkeypatch: pytest.MonkeyPatch) -> None:
    built: list[int] = []
    scenario = bench_crowdnav.crowdnav_scenario

    def spy(case: int, **kw: Any) -> Any:
        scn = scenario(case, **kw)
        built.append(len(scn.obstacles))
        return scn

    monkeypatch.setattr(bench_crowdnav, "crowdnav_scenario", spy)
    r = bench_crowdnav.run(1, rule="circle_crossing", substeps=1, pref="uvnav", first=0,
                           humans=2)  # fmt: skip
    assert built == [2] and r["humans"] == 2
    assert "2 humans" in bench_crowdnav.report(r)
    assert sum(x["count"] for x in r["rates"].values()) == 1


def test_humans_out_of_range_is_a_one_line_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        bench_crowdnav.main(["--cases", "1", "--humans", "-1"])
    assert exc.value.code == 2
    assert "--humans must be in 0..1000" in capsys.readouterr().err


def test_report_gives_the_mean_intrusion_ratio_with_an_interval() -> None:
    r = bench_crowdnav.run(2, rule="circle_crossing", substeps=1, pref="uvnav", first=0,
                           humans=5)  # fmt: skip
    ir = r["intrusion_ratio"]
    assert ir["episodes"] == 2 and 0.0 <= ir["ci95"][0] <= ir["mean"] <= ir["ci95"][1] <= 1.0
    assert f"intrusion ratio (mean of 2 episodes) {ir['mean']:.3f}" in bench_crowdnav.report(r)


def test_mean_interval_is_a_bootstrap_of_the_mean() -> None:
    flat = bench_crowdnav.mean_interval([0.2] * 10)
    assert flat["mean"] == pytest.approx(0.2) and flat["ci95"] == pytest.approx([0.2, 0.2])
    spread = bench_crowdnav.mean_interval([0.0] * 50 + [1.0] * 50)
    lo, hi = spread["ci95"]
    # the normal approximation: 0.5 +- 1.96 * 0.5 / sqrt(100) = [0.402, 0.598]
    assert spread["mean"] == 0.5 and lo == pytest.approx(0.402, abs=0.02)
    assert hi == pytest.approx(0.598, abs=0.02)
    assert bench_crowdnav.mean_interval([])["mean"] is None


def test_unplaceable_cases_are_left_out_and_listed(monkeypatch: pytest.MonkeyPatch) -> None:
    scenario = bench_crowdnav.crowdnav_scenario

    def crowded(case: int, **kw: Any) -> Any:
        if case == 1:
            raise bench_crowdnav.ScenarioError("crowdnav-circle:1", "n_humans", "cannot place")
        return scenario(case, **kw)

    monkeypatch.setattr(bench_crowdnav, "crowdnav_scenario", crowded)
    r = bench_crowdnav.run(2, rule="circle_crossing", substeps=1, pref="uvnav", first=0,
                           humans=2)  # fmt: skip
    assert r["unplaceable"] == [1] and r["case_numbers"] == [0] and r["cases"] == 1
    assert sum(x["count"] for x in r["rates"].values()) == 1
    assert "cases 0..1 (2), 1 unplaceable left out" in bench_crowdnav.report(r)


def test_no_placeable_case_is_a_one_line_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        bench_crowdnav.main(["--cases", "1", "--first", "0", "--humans", "1000"])
    assert exc.value.code == 2
    assert "no case's humans could be placed apart" in capsys.readouterr().err


def test_sensing_range_reaches_every_case(monkeypatch: pytest.MonkeyPatch) -> None:
    ranges: list[float] = []
    scenario = bench_crowdnav.crowdnav_scenario

    def spy(case: int, **kw: Any) -> Any:
        scn = scenario(case, **kw)
        ranges.append(float(scn.sensing.range))
        return scn

    monkeypatch.setattr(bench_crowdnav, "crowdnav_scenario", spy)
    r = bench_crowdnav.run(1, rule="circle_crossing", substeps=1, pref="uvnav", first=0,
                           sensing_range=5.0)  # fmt: skip
    assert ranges == [5.0] and "humans seen within 5 m" in r["sensing"]


def test_a_bad_sensing_range_is_a_one_line_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        bench_crowdnav.main(["--cases", "1", "--sensing-range", "nan"])
    assert exc.value.code == 2
    assert "--sensing-range must be a number > 0" in capsys.readouterr().err


def test_a_law_with_no_target_is_reported_not_judged(capsys: pytest.CaptureFixture[str]) -> None:
    """Only the paper's ORCA row and the v2 laws have a verdict; any other law's run exits 0
    with its figures and says so (the paper's ORCA success is not its target)."""
    assert bench_crowdnav.main(["--cases", "1", "--law", "straight-holonomic-v1"]) == 0
    out = capsys.readouterr().out
    assert "no target: only orca-holonomic-v1" in out and "FAIL" not in out


def test_robot_visible_scenes_and_no_verdict(capsys: pytest.CaptureFixture[str]) -> None:
    """``--robot-visible``: every human avoids the robot, and the run is not judged against
    the invisible-robot protocol's target."""
    scn = bench_crowdnav._scene(0, "circle_crossing", 1, "turn-then-move", 5, {}, (None, None),
                                robot_visible=True)  # fmt: skip
    assert [o.motion.sees_robot for o in scn.obstacles] == [True] * 5
    blind = bench_crowdnav._scene(0, "circle_crossing", 1, "turn-then-move", 5, {}, (None, None))
    assert not any(o.motion.sees_robot for o in blind.obstacles)
    args = ["--cases", "1", "--first", "0", "--law", "zhang2019-holonomic-v2", "--robot-visible"]
    assert bench_crowdnav.main(args) == 0
    out = capsys.readouterr().out
    assert "robot visible to the humans" in out and "no target: the test protocol" in out


def test_control_period_is_the_robots_alone(capsys: pytest.CaptureFixture[str]) -> None:
    """``--control-period``: the robot's decision period; the humans keep CrowdNav's 0.25 s;
    a period that is not a whole number of integration steps is a one-line error."""
    scn = bench_crowdnav._scene(0, "circle_crossing", 5, "turn-then-move", None, {},
                                (1.0, 2.0), control_period=0.1)  # fmt: skip
    assert scn.control_period == pytest.approx(0.1)
    assert {o.motion.period for o in scn.obstacles} == {0.25}
    with pytest.raises(SystemExit) as exc:
        bench_crowdnav.main(["--cases", "1", "--substeps", "5", "--control-period", "0.12"])
    assert exc.value.code == 2
    assert "--control-period: must be a positive multiple of dt" in capsys.readouterr().err
