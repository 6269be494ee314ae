"""One campaign writer per database: a second ``uvnav bench`` on it refuses at once (issue 17)."""

from __future__ import annotations

import json
import os
import sqlite3
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from uvnav.bench.store import ResultsStore, lock_path, writer_lease

CAMPAIGN = """\
name: shared
scenarios:
  - generator: random-ch2
    seeds: [0, 3]
controllers:
  - name: straight-v1
"""

# a campaign runner that stops after its first stored episode until its stdin is closed
HOLDER = textwrap.dedent(
    """
    import sys
    from uvnav.bench.campaign import run_campaign
    from uvnav.bench.spec import load_campaign
    from uvnav.bench.store import ResultsStore

    spec = load_campaign(sys.argv[1])

    def pause(*_):
        print("stored one", flush=True)
        sys.stdin.read()

    with ResultsStore(sys.argv[2]) as store:
        run = run_campaign(store, spec.name, spec.jobs(), config=spec.config(), on_outcome=pause)
    print(run.ran, flush=True)
    """
)


def _bench(*args: str) -> subprocess.CompletedProcess[str]:
    cmd = [sys.executable, "-m", "uvnav.cli", "bench", *args]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120)


def test_a_second_bench_on_a_database_in_use_refuses_at_once(tmp_path: Path) -> None:
    campaign = tmp_path / "c.yaml"
    campaign.write_text(CAMPAIGN)
    db = tmp_path / "r.sqlite"
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLDER, str(campaign), str(db)],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout is not None and holder.stdin is not None
        assert holder.stdout.readline().strip() == "stored one"  # mid-campaign, lease held
        for extra in (["--resume"], []):
            second = _bench(str(campaign), "--db", str(db), "--workers", "1", *extra)
            assert second.returncode == 2, second.stderr
            lines = [ln for ln in second.stderr.splitlines() if ln.strip()]
            assert lines == [
                f"error: database {db} is in use by another uvnav process (pid {holder.pid}); "
                "wait for it to finish or use another --db"
            ]
            assert second.stdout == ""
        holder.stdin.close()
        assert holder.wait(timeout=120) == 0
        assert holder.stdout.read().split()[-1] == "3"  # the holder ran all three episodes
    finally:
        if holder.poll() is None:
            holder.kill()
            holder.wait()
    after = _bench(str(campaign), "--db", str(db), "--workers", "1", "--resume", "--json")
    assert after.returncode == 0, after.stderr
    record = json.loads(after.stdout)
    assert (record["ran"], record["skipped"]) == (0, 3)
    with sqlite3.connect(db) as conn:
        assert conn.execute("SELECT COUNT(*) FROM episodes").fetchone()[0] == 3


def test_the_lease_is_reentrant_in_one_process_and_released(tmp_path: Path) -> None:
    db = tmp_path / "r.sqlite"
    with ResultsStore(db) as store, store.writer_lease():
        assert lock_path(db).read_text().strip() == str(os.getpid())
        with writer_lease(db):  # the same process may nest (uvnav run opens stores inside)
            pass
        code = f"from uvnav.bench.store import writer_lease\nwith writer_lease({str(db)!r}): pass"
        other = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
        assert other.returncode == 1 and "StoreInUseError" in other.stderr
        assert f"(pid {os.getpid()})" in other.stderr
    with writer_lease(db):  # released: free again
        pass
    assert lock_path(db).read_text() == ""


def test_every_command_reports_a_database_in_use_as_one_line() -> None:
    from uvnav.bench.store import StoreInUseError
    from uvnav.cli.errors import user_error

    msg = "database r.sqlite is in use by another uvnav process (pid 7); wait for it to finish"
    assert user_error(StoreInUseError(msg)) == (msg, 2)


@pytest.mark.parametrize("at", ["ftruncate", "pwrite"])
def test_an_interrupt_while_taking_the_lease_leaves_it_free(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, at: str
) -> None:
    """Ctrl-C lands between any two bytecodes: one right after the lock is taken must not leave
    it held by this process (a later run here would be refused, naming its own pid)."""
    db = tmp_path / "i.sqlite"
    real = getattr(os, at)
    calls = [0]

    def interrupted(*args: object) -> object:
        calls[0] += 1
        if calls[0] == 1:
            raise KeyboardInterrupt
        return real(*args)

    monkeypatch.setattr(os, at, interrupted)
    with pytest.raises(KeyboardInterrupt), writer_lease(db):
        pass
    monkeypatch.setattr(os, at, real)
    with writer_lease(db):  # free again, in this process and for another
        code = f"from uvnav.bench.store import writer_lease\nwith writer_lease({str(db)!r}): pass"
        other = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
        assert other.returncode == 1 and "StoreInUseError" in other.stderr
    other = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert other.returncode == 0, other.stderr
