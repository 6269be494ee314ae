"""SIGTERM stops ``uvnav bench`` like Ctrl-C, and no worker outlives the campaign (issue 17)."""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

# 400 episodes on two workers: far from done when the signal comes
CAMPAIGN = """\
name: long
scenarios:
  - generator: random-ch2
    seeds: [0, 200]
controllers:
  - name: zhang2019-v1
  - name: savkin-wang2013-v1
"""

pytestmark = pytest.mark.skipif(
    not Path("/proc/self/task").is_dir(), reason="reads the process tree from Linux /proc"
)


def _children(pid: int) -> list[int]:
    out: list[int] = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            out += [int(c) for c in (task / "children").read_text().split()]
        except OSError:
            continue
    return out


def _descendants(pid: int) -> list[int]:
    found, todo = [], _children(pid)
    while todo:
        p = todo.pop()
        found.append(p)
        todo += _children(p)
    return found


def _running(pid: int) -> bool:
    """Whether ``pid`` exists and is not a zombie."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state != "Z"


def _stored(db: Path) -> int:
    if not db.exists():
        return 0
    try:
        with sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=5) as conn:
            return int(conn.execute("SELECT COUNT(*) FROM episodes").fetchone()[0])
    except sqlite3.Error:
        return 0


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
def test_no_worker_survives_the_campaign_process(tmp_path: Path, sig: signal.Signals) -> None:
    campaign = tmp_path / "long.yaml"
    campaign.write_text(CAMPAIGN)
    db = tmp_path / "r.sqlite"
    err = tmp_path / "stderr.txt"
    cmd = [sys.executable, "-m", "uvnav.cli", "bench", str(campaign), "--db", str(db)]
    with err.open("w") as fh:
        proc = subprocess.Popen([*cmd, "--workers", "2"], stdout=subprocess.DEVNULL, stderr=fh)
    tree: set[int] = set()
    try:
        deadline = time.monotonic() + 60
        while proc.poll() is None and time.monotonic() < deadline:
            tree.update(_descendants(proc.pid))
            if _stored(db) >= 2 and len(tree) >= 3:  # fork server and two busy workers
                break
            time.sleep(0.05)
        assert proc.poll() is None, "the campaign ended before it could be interrupted"
        tree.update(_descendants(proc.pid))
        proc.send_signal(sig)
        code = proc.wait(timeout=60)
        deadline = time.monotonic() + 10  # workers check their main process twice a second
        while any(_running(p) for p in tree) and time.monotonic() < deadline:
            time.sleep(0.1)
        survivors = sorted(p for p in tree if _running(p))
        assert survivors == [], f"processes of the campaign survived it: {survivors}"
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        for p in tree:
            if _running(p):
                os.kill(p, signal.SIGKILL)
    stored = _stored(db)
    assert 2 <= stored < 400
    if sig == signal.SIGTERM:  # handled as Ctrl-C: a clean stop with the resume hint
        assert code == 130
        assert err.read_text().splitlines()[-1] == (
            f"interrupted: {stored} episode(s) of 'long' are stored in {db}; run again with "
            "--resume to finish"
        )
    else:
        assert code == -signal.SIGKILL
