"""``uvnav bench``: table, JSON, resume rules, one-line errors, and resume after a SIGKILL."""

from __future__ import annotations

import json
import os
import shlex
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from uvnav.bench.summary import TIMING_COLUMNS
from uvnav.cli.app import app

runner = CliRunner()

CAMPAIGN = """\
name: cli-small
scenarios:
  - generator: random-ch2
    seeds: [0, 2]
controllers:
  - name: straight-v1
  - name: zhang2019-v1
    grid: {switch_distance: [1.0, 1.5]}
"""

# 30 episodes, long enough (~0.1-0.2 s each) to be killed in the middle
KILLED = """\
name: kill-me
scenarios:
  - generator: random-ch2
    seeds: [0, 15]
controllers:
  - name: zhang2019-v1
  - name: savkin-wang2013-v1
"""


def invoke(*args: str) -> Any:
    return runner.invoke(app, list(args))


def deterministic(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    return [{k: v for k, v in r.items() if k not in TIMING_COLUMNS} for r in rows]


@pytest.fixture
def campaign(tmp_path: Path) -> Path:
    path = tmp_path / "campaign.yaml"
    path.write_text(CAMPAIGN)
    return path


def test_the_summary_fits_an_80_column_terminal_and_says_what_it_leaves_out(
    campaign: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from rich.console import Console

    import uvnav.cli.bench as cb

    monkeypatch.setattr(cb, "_console", lambda: Console(width=80, highlight=False))
    db = tmp_path / "r.sqlite"
    result = invoke("bench", str(campaign), "--db", str(db), "--workers", "1")
    assert result.exit_code == 0, result.output
    table = result.stdout.split("ran 6 episode(s)")[0].splitlines()
    assert max(len(line) for line in table) <= 80
    assert "not shown at this width: decide µs p99 (--json has all)" in result.stdout
    assert "success" in result.stdout and "median" in result.stdout


def test_bench_prints_the_per_controller_table(campaign: Path, tmp_path: Path) -> None:
    db = tmp_path / "r.sqlite"
    args = ["bench", str(campaign), "--db", str(db), "--workers", "1"]
    result = runner.invoke(app, args, env={"COLUMNS": "160"})
    assert result.exit_code == 0, result.output
    out = result.stdout
    assert "campaign cli-small (6 episodes)" in out
    for text in ("straight-v1", "switch_distance=1.0", "switch_distance=1.5", "success", "µs"):
        assert text in out
    assert "ran 6 episode(s)" in out and str(db) in out

    again = invoke("bench", str(campaign), "--db", str(db))
    line = assert_one_line_error(again, 2)
    assert "campaign 'cli-small' is already in this database" in line
    assert "--resume" in line and "--db" in line

    resumed = invoke("bench", str(campaign), "--db", str(db), "--resume", "--json")
    assert resumed.exit_code == 0, resumed.output
    record = json.loads(resumed.stdout)
    assert (record["total"], record["ran"], record["skipped"]) == (6, 0, 6)
    rows = record["controllers"]
    assert [(r["controller"], r["params"], r["episodes"]) for r in rows] == [
        ("straight-v1", "-", 2),
        ("zhang2019-v1", "switch_distance=1.0", 2),
        ("zhang2019-v1", "switch_distance=1.5", 2),
    ]
    assert rows[1]["success_rate"] == 1.0 and rows[1]["collision_rate"] == 0.0
    assert rows[1]["detour_ratio"] >= 1.0 and rows[1]["decision_us_median"] > 0


def run_with_failures(path: Path, db: Path) -> tuple[Any, dict[str, Any]]:
    """Run campaign ``path`` with ``--failures`` (table, 160 columns), then read its JSON record
    with ``--resume`` (nothing runs again)."""
    res = runner.invoke(
        app, ["bench", str(path), "--db", str(db), "--workers", "1", "--failures"],
        env={"COLUMNS": "160"},
    )  # fmt: skip
    assert res.exit_code == 0, res.output
    fresh = invoke("bench", str(path), "--db", str(db), "--resume", "--failures", "--json")
    return res, json.loads(fresh.stdout)


def test_bench_failures_lists_each_failed_episode(tmp_path: Path) -> None:
    """--failures: one row per episode that did not succeed, with its seed and cause; also in
    the JSON record, and from a finished campaign with --resume (nothing runs again)."""
    path = tmp_path / "c.yaml"
    path.write_text(CAMPAIGN.replace("cli-small", "fails").replace("[0, 2]", "[0, 4]"))
    db = tmp_path / "r.sqlite"
    res, record = run_with_failures(path, db)
    assert record["ran"] == 0
    failed = record["failures"]
    assert failed, "straight-v1 collides on random-ch2 seeds 0-3"
    assert {f["controller"] for f in failed} == {"straight-v1"}
    for f in failed:
        assert f["status"] in ("collision", "timeout")
        assert f["cause"] in ("robot-driven", "obstacle-driven", "timeout")
    assert f"{len(failed)} episode(s) did not succeed" in res.stdout
    for f in failed:  # each failure's line, then its command on one line
        assert f"- straight-v1, seed {f['seed']}: {f['cause']}" in res.stdout
        assert f"\n  {f['command']}\n" in res.stdout
        assert f["command"].startswith(f"uvnav simulate random-ch2:{f['seed']} -c straight-v1 ")
    assert "failures" not in json.loads(
        invoke("bench", str(path), "--db", str(db), "--resume", "--json").stdout
    )


def test_every_failure_line_reruns_its_stored_episode_exactly(tmp_path: Path) -> None:
    """Each --failures line carries the ``uvnav simulate`` command of its episode: generator
    parameters, the law's grid parameters and --beyond-assumptions; run, it gives the stored
    status, clearance and path length."""
    path = tmp_path / "fails.yaml"
    path.write_text(
        "name: fails-params\nscenarios:\n  - generator: random-ch2\n    seeds: [0, 4]\n"
        "    params: {n_obstacles: 4, body: disc}\ncontrollers:\n  - name: straight-v1\n"
        "  - name: apf-v1\n    grid: {repulse_gain: [0.0], escape: [false]}\n"
        "beyond_assumptions: true\n"
    )
    db = tmp_path / "r.sqlite"
    res, record = run_with_failures(path, db)
    failed = record["failures"]
    assert {f["controller"] for f in failed} == {"straight-v1", "apf-v1"}, failed
    stored = {
        (r[0], r[1]): r[2:]
        for r in sqlite3.connect(db).execute(
            "SELECT controller, seed, status, min_clearance, path_length FROM episodes"
        )
    }
    for f in failed:
        cmd = shlex.split(f["command"])
        assert cmd[:2] == ["uvnav", "simulate"] and f["command"] in res.stdout
        if f["controller"] == "apf-v1":
            assert {"repulse_gain=0.0", "escape=false"} <= set(cmd), cmd
        assert "--beyond-assumptions" in cmd and 'body="disc"' in cmd
        again = json.loads(invoke(*cmd[1:], "--json").stdout)
        got = (again["status"], again["min_clearance"], again["path_length"])
        assert got == stored[(f["controller"], f["seed"])], f
    plain = json.loads(invoke("simulate", f"random-ch2:{f['seed']}", "-c", "straight-v1",
                              "--json").stdout)  # fmt: skip
    assert plain["min_clearance"] != stored[("straight-v1", f["seed"])][1], "params change it"


def assert_one_line_error(result: Any, code: int, *fragments: str) -> str:
    assert result.exit_code == code, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("error: ") and "Traceback" not in result.output
    for fragment in fragments:
        assert fragment in lines[0]
    return lines[0]


def test_bench_errors_are_one_line(
    campaign: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(CAMPAIGN.replace("switch_distance", "switch_distanse"))
    assert_one_line_error(
        invoke("bench", str(bad)), 2, str(bad), "controllers.1.grid", "switch_distanse"
    )
    assert_one_line_error(invoke("bench", str(tmp_path / "none.yaml")), 2, "no such campaign file")
    assert_one_line_error(invoke("bench", str(tmp_path)), 2, "is a directory, not a campaign")
    endless = tmp_path / "endless.yaml"
    os.mkfifo(endless)  # reading it would block for ever
    assert_one_line_error(invoke("bench", str(endless)), 2, "endless.yaml: is not a regular file")
    assert_one_line_error(invoke("bench", str(campaign), "--engine", "dask"), 2, "--engine")
    assert_one_line_error(invoke("bench", str(campaign), "--address", "auto"), 2, "--engine ray")
    monkeypatch.setitem(sys.modules, "ray", None)  # as if Ray were not installed
    db = tmp_path / "r.sqlite"
    assert_one_line_error(
        invoke("bench", str(campaign), "--engine", "ray", "--db", str(db)), 1, "uvnav[bench]"
    )
    assert not db.exists()  # nothing was started


def stored(db: Path) -> int:
    try:
        with sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=1.0) as conn:
            return int(conn.execute("SELECT COUNT(*) FROM episodes").fetchone()[0])
    except sqlite3.OperationalError:  # not created yet
        return 0


def test_sigkill_then_resume_equals_an_uninterrupted_run(tmp_path: Path) -> None:
    path = tmp_path / "kill.yaml"
    path.write_text(KILLED)
    db = tmp_path / "killed.sqlite"
    cmd = [sys.executable, "-m", "uvnav.cli", "bench", str(path), "--db", str(db), "--workers", "2"]
    # own session, so the kill reaches the fork server and the workers too (a machine going down)
    proc = subprocess.Popen(
        cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True
    )
    try:
        deadline = time.monotonic() + 60
        while stored(db) < 5 and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    at_kill = stored(db)
    assert 5 <= at_kill < 30, f"killed with {at_kill} of 30 episodes stored"

    resumed = invoke("bench", str(path), "--db", str(db), "--resume", "--workers", "2", "--json")
    assert resumed.exit_code == 0, resumed.output
    record = json.loads(resumed.stdout)
    assert record["skipped"] == at_kill and record["ran"] == 30 - at_kill

    fresh = invoke("bench", str(path), "--db", str(tmp_path / "fresh.sqlite"), "--json")
    assert fresh.exit_code == 0, fresh.output
    assert deterministic(record["controllers"]) == deterministic(
        json.loads(fresh.stdout)["controllers"]
    )
    with sqlite3.connect(db) as conn:
        n, keys = conn.execute(
            "SELECT COUNT(*), COUNT(DISTINCT scenario || controller || params_hash || seed) "
            "FROM episodes"
        ).fetchone()
    assert n == keys == 30


def test_bad_generator_parameters_stop_the_campaign_before_it_runs(tmp_path: Path) -> None:
    path = tmp_path / "broken.yaml"
    path.write_text(
        "name: broken\nscenarios:\n  - generator: random-ch2\n    seeds: [0, 1]\n"
        "    params: {n_obstacles: -3}\ncontrollers:\n  - name: straight-v1\n"
    )
    db = tmp_path / "b.sqlite"
    res = invoke("bench", str(path), "--db", str(db), "--workers", "1")
    assert res.exit_code == 2, res.output
    assert res.output.count("\n") == 1
    assert "scenarios.0.params.n_obstacles: must be >= 0 (got -3)" in res.output
    assert not db.exists()


def test_errored_episodes_exit_non_zero_with_the_first_error(
    campaign: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import uvnav.scenarios.episodes as episodes

    def broken(*args: Any, **kwargs: Any) -> Any:
        raise RuntimeError("law exploded")

    monkeypatch.setattr(episodes, "run_scene", broken)  # one worker runs in this process
    db = tmp_path / "b.sqlite"
    res = invoke("bench", str(campaign), "--db", str(db), "--workers", "1", "--json")
    assert res.exit_code == 1, res.output
    last = res.stderr.strip().splitlines()[-1]
    assert last.startswith("error: 6 episode(s) errored; the first: random-ch2")
    assert "RuntimeError: law exploded" in last and "Traceback" not in res.output
    assert json.loads(res.stdout)["errors"] == 6


def test_a_local_pool_of_more_workers_than_the_machine_can_run_is_refused(
    campaign: Path, tmp_path: Path
) -> None:
    from uvnav.cli.checks import max_pool_workers

    db = tmp_path / "r.sqlite"
    too_many = str(max_pool_workers() + 1)
    res = invoke("bench", str(campaign), "--db", str(db), "--workers", too_many)
    assert_one_line_error(res, 2, "--workers", "per CPU of this machine")
    assert not db.exists()  # refused before the database is created
