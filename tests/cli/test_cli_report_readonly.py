"""``uvnav report`` only reads its database and refuses a file that is not a uvnav store."""

from __future__ import annotations

import hashlib
import shlex
import sqlite3
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from typer.testing import CliRunner

from uvnav.bench.store import NotAStoreError, ResultsStore
from uvnav.cli.app import app

runner = CliRunner()


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _foreign(path: Path) -> Path:
    """An SQLite database of another program."""
    with sqlite3.connect(path) as conn:
        conn.execute("CREATE TABLE invoices (id INTEGER PRIMARY KEY, total REAL)")
        conn.execute("INSERT INTO invoices (total) VALUES (12.5)")
    return path


def _empty(path: Path) -> None:
    path.write_bytes(b"")


def _csv(path: Path) -> None:
    path.write_text("name,score\nx,1\n")


def _tables(path: Path) -> set[str]:
    with sqlite3.connect(f"file:{path}?mode=ro", uri=True) as conn:
        return {r[0] for r in conn.execute("SELECT name FROM sqlite_master WHERE type='table'")}


@pytest.mark.parametrize(
    ("make", "problem"),
    [
        (_foreign, "no 'campaigns' table"),
        (_empty, "no 'campaigns' table"),
        (_csv, "file is not a database"),
    ],
    ids=["foreign-sqlite", "empty-file", "csv-file"],
)
def test_report_refuses_a_file_that_is_not_a_store_and_leaves_it_alone(
    tmp_path: Path, make: Callable[[Path], object], problem: str
) -> None:
    db = tmp_path / "input.sqlite"
    make(db)
    before = _digest(db)
    out = tmp_path / "site"
    r = runner.invoke(app, ["report", str(db), "--out", str(out)])
    assert r.exit_code == 2, r.output
    lines = [ln for ln in r.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in r.output
    assert lines[0].startswith(f"error: {db}: not a uvnav results database") and problem in lines[0]
    assert _digest(db) == before  # not one byte written: no tables added
    assert not out.exists()


def test_report_reads_a_store_without_writing_it(tmp_path: Path) -> None:
    pytest.importorskip("jinja2")
    db = tmp_path / "r.sqlite"
    with ResultsStore(db) as store:
        store.add_episode(
            store.campaign("c"), scenario="s", controller="straight-v1", seed=0, status="timeout"
        )
    # an older database: a metric column a newer uvnav adds on write is missing
    with sqlite3.connect(db) as conn:
        conn.execute("ALTER TABLE episodes DROP COLUMN decision_us_p99")
    columns_before, before = _tables(db), _digest(db)
    r = runner.invoke(app, ["report", str(db), "--out", str(tmp_path / "site")])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "site" / "index.html").is_file()
    assert _tables(db) == columns_before and _digest(db) == before
    with sqlite3.connect(db) as conn:
        cols = {row[1] for row in conn.execute("PRAGMA table_info(episodes)")}
    assert "decision_us_p99" not in cols  # not migrated by a reader


def test_readonly_store_cannot_write_and_refuses_foreign_files(tmp_path: Path) -> None:
    db = tmp_path / "r.sqlite"
    ResultsStore(db).close()
    with ResultsStore(db, readonly=True) as store, pytest.raises(sqlite3.OperationalError):
        store.campaign("new")
    with pytest.raises(NotAStoreError, match="no 'campaigns' table"):
        ResultsStore(_foreign(tmp_path / "f.sqlite"), readonly=True)
    with pytest.raises(FileNotFoundError):
        ResultsStore(tmp_path / "missing.sqlite", readonly=True)
    assert not (tmp_path / "missing.sqlite").exists()


def _read_only_mount(src: Path, dst: Path, command: str) -> subprocess.CompletedProcess[str]:
    """``command`` run where ``dst`` is ``src`` mounted read-only (a private mount namespace)."""
    script = f"mount --bind -o ro {shlex.quote(str(src))} {shlex.quote(str(dst))} && {command}"
    return subprocess.run(
        ["unshare", "-m", "sh", "-c", script], capture_output=True, text=True, timeout=120
    )


def test_report_reads_a_store_on_read_only_media(tmp_path: Path) -> None:
    """SQLite cannot create the ``-shm`` file of a WAL database on read-only media."""
    src, mnt = tmp_path / "src", tmp_path / "mnt"
    src.mkdir()
    mnt.mkdir()
    with ResultsStore(src / "r.sqlite") as store:
        store.add_episode(
            store.campaign("c"), scenario="s", controller="straight-v1", seed=0, status="timeout"
        )
    if _read_only_mount(src, mnt, f"touch {shlex.quote(str(mnt / 'x'))}").returncode == 0:
        pytest.skip("the bind mount is not read-only here")
    probe = _read_only_mount(src, mnt, "true")
    if probe.returncode != 0:
        pytest.skip(f"no read-only bind mount here (needs root): {probe.stderr.strip()}")
    code = (
        "from uvnav.bench.store import ResultsStore; "
        f"s = ResultsStore({str(mnt / 'r.sqlite')!r}, readonly=True); "
        "print(s._conn.execute('SELECT count(*) FROM episodes').fetchone()[0])"
    )
    src_dir = Path(__file__).resolve().parents[2] / "src"
    env = f"PYTHONPATH={shlex.quote(str(src_dir))}"
    out = _read_only_mount(src, mnt, f"{env} {shlex.quote(sys.executable)} -c {shlex.quote(code)}")
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "1"
