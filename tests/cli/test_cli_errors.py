"""The CLI's one error path: user errors are one line and exit 2; a bug is one line naming a
crash log that holds the traceback, exit 70; --debug / UVNAV_DEBUG re-raise; Ctrl-C is 130; a
closed pipe is a quiet 141."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
from typer.testing import CliRunner

from uvnav.cli.app import app
from uvnav.cli.errors import EX_IOERR, EX_PIPE, EX_SOFTWARE, crash_log_dir

runner = CliRunner()


@pytest.fixture()
def log_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    folder = tmp_path / "logs"
    monkeypatch.setenv("UVNAV_LOG_DIR", str(folder))
    monkeypatch.delenv("UVNAV_DEBUG", raising=False)
    return folder


def _boom(*args: Any, **kwargs: Any) -> Any:
    raise RuntimeError("boom in the catalogue\nsecond line")


@pytest.fixture()
def broken_catalog(monkeypatch: pytest.MonkeyPatch) -> None:
    import uvnav.scenarios.catalog as catalog

    monkeypatch.setattr(catalog, "builtin_names", _boom)
    monkeypatch.setattr(catalog, "resolve", _boom)


def test_a_bug_is_one_line_exit_70_and_a_crash_log(log_dir: Path, broken_catalog: None) -> None:
    for args in (["scenarios", "list"], ["simulate", "open-field", "--json"]):
        result = runner.invoke(app, args)
        assert result.exit_code == EX_SOFTWARE == 70, result.output
        assert result.stdout == ""
        lines = result.stderr.splitlines()
        assert len(lines) == 1, result.stderr
        line = lines[0]
        assert line.startswith("internal error: RuntimeError: boom in the catalogue second line")
        assert "please report it" in line and "Traceback" not in result.stderr
        assert not line.startswith("error:")  # a bug is not disguised as a user error
        logs = sorted(log_dir.glob("crash-*.log"))
        assert logs, "no crash log written"
        assert str(logs[-1]) in line
        text = logs[-1].read_text()
        assert "Traceback (most recent call last)" in text
        assert "RuntimeError: boom in the catalogue" in text
        assert "_boom" in text  # the frame that raised


def test_user_error_stays_one_line_exit_2(log_dir: Path) -> None:
    result = runner.invoke(app, ["simulate", "no-such-scene.yaml"])
    assert result.exit_code == 2
    assert result.stderr.splitlines() == [result.stderr.strip()]
    assert result.stderr.startswith("error: ") and "no-such-scene.yaml" in result.stderr
    assert not log_dir.exists()


def test_errors_of_the_chapter_apps_take_the_same_path(log_dir: Path, tmp_path: Path) -> None:
    missing = tmp_path / "missing.npz"
    cases = [
        ["sonar", "train", str(missing)],
        ["recon", "plan", "--out", str(tmp_path / "o"), "--dem", str(tmp_path / "x.npy")],
        ["drive", "evaluate", str(tmp_path / "m.safetensors"), "--seeds", "x-y"],
    ]
    for args in cases:
        result = runner.invoke(app, args)
        assert result.exit_code == 2, (args, result.output)
        lines = result.stderr.splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: "), (args, result.stderr)


def test_usage_error_of_the_root_is_one_line(log_dir: Path) -> None:
    result = runner.invoke(app, ["no-such-command"])
    assert result.exit_code == 2
    assert result.stderr.startswith("error: ") and len(result.stderr.splitlines()) == 1


def test_debug_reraises(
    log_dir: Path, broken_catalog: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    result = runner.invoke(app, ["--debug", "scenarios", "list"])
    assert isinstance(result.exception, RuntimeError)
    assert result.exit_code != EX_SOFTWARE
    monkeypatch.setenv("UVNAV_DEBUG", "1")
    result = runner.invoke(app, ["scenarios", "list"])
    assert isinstance(result.exception, RuntimeError)
    assert not log_dir.exists()


def test_ctrl_c_is_exit_130(log_dir: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import uvnav.scenarios.catalog as catalog

    def interrupted(*args: Any) -> Any:
        raise KeyboardInterrupt

    monkeypatch.setattr(catalog, "builtin_names", interrupted)
    result = runner.invoke(app, ["scenarios", "list"])
    assert result.exit_code == 130
    assert not log_dir.exists()


def test_a_closed_pipe_ends_the_command_quietly(log_dir: Path) -> None:
    """``uvnav scenarios list | head -1``: the reader is gone before the command writes."""
    cmd = [sys.executable, "-c", "from uvnav.cli.app import main; main()", "scenarios", "list"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert proc.stdout is not None and proc.stderr is not None
    proc.stdout.close()  # before the imports are done: the first write meets a closed pipe
    err = proc.stderr.read()
    assert proc.wait(timeout=120) == EX_PIPE and err == b"", err
    assert not log_dir.exists()  # not a bug: no crash log


def test_crash_log_folder(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.delenv("UVNAV_LOG_DIR", raising=False)
    monkeypatch.setenv("XDG_STATE_HOME", str(tmp_path / "state"))
    assert crash_log_dir() == tmp_path / "state" / "uvnav"
    monkeypatch.delenv("XDG_STATE_HOME")
    assert crash_log_dir() == Path.home() / ".local" / "state" / "uvnav"
    monkeypatch.setenv("UVNAV_LOG_DIR", str(tmp_path / "mine"))
    assert crash_log_dir() == tmp_path / "mine"


def test_unwritable_log_folder_falls_back_to_the_temp_dir(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, broken_catalog: None
) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("UVNAV_LOG_DIR", str(blocker / "logs"))
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path / "tmp"))
    result = runner.invoke(app, ["scenarios", "list"])
    assert result.exit_code == 70
    logs = list((tmp_path / "tmp" / "uvnav").glob("crash-*.log"))
    assert len(logs) == 1 and str(logs[0]) in result.stderr


def test_a_name_too_long_for_the_file_system_is_one_clipped_line(log_dir: Path) -> None:
    name = "a" * 5000
    for command in (["simulate", name], ["bench", name], ["scenarios", "validate", name]):
        res = runner.invoke(app, command)
        assert res.exit_code == 2, res.output
        assert res.output.startswith("error: ") and "File name too long" in res.output
        assert "aaa..." in res.output, "the name is clipped"
        assert res.output.count("\n") == 1 and len(res.output) < 260, res.output
    assert not log_dir.exists(), "not a bug: no crash log"


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs Linux's /dev/full")
def test_a_full_disk_is_one_line_exit_74_not_a_bug(log_dir: Path) -> None:
    with open("/dev/full", "w") as full:
        proc = subprocess.run(
            [sys.executable, "-m", "uvnav.cli", "scenarios", "show", "random-ch2:1"],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            timeout=120,
        )
    assert proc.returncode == EX_IOERR, proc.stderr
    assert proc.stderr == "error: No space left on device\n"
    assert not log_dir.exists(), "not a bug: no crash log"


def test_a_full_or_read_only_results_database_is_one_line() -> None:
    import sqlite3

    from uvnav.cli.errors import user_error

    full = sqlite3.OperationalError("database or disk is full")
    assert user_error(full) == ("results database: database or disk is full", EX_IOERR)
    locked = sqlite3.OperationalError("attempt to write a readonly database")
    assert user_error(locked) == (
        "results database: attempt to write a readonly database",
        EX_IOERR,
    )
    assert user_error(sqlite3.OperationalError("no such table: episodes")) is None  # a bug
