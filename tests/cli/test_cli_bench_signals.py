"""SIGTERM stops ``uvnav bench`` like Ctrl-C, and no worker outlives the campaign (issue 17)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from processes import LINUX_PROC, descendants, running, stored_episodes

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

pytestmark = pytest.mark.skipif(not LINUX_PROC, reason="reads the process tree from Linux /proc")


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
            tree.update(descendants(proc.pid))
            if stored_episodes(db) >= 2 and len(tree) >= 3:  # fork server and two busy workers
                break
            time.sleep(0.05)
        assert proc.poll() is None, "the campaign ended before it could be interrupted"
        tree.update(descendants(proc.pid))
        proc.send_signal(sig)
        code = proc.wait(timeout=60)
        deadline = time.monotonic() + 10  # workers check their main process twice a second
        while any(running(p) for p in tree) and time.monotonic() < deadline:
            time.sleep(0.1)
        survivors = sorted(p for p in tree if running(p))
        assert survivors == [], f"processes of the campaign survived it: {survivors}"
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        for p in tree:
            if running(p):
                os.kill(p, signal.SIGKILL)
    stored = stored_episodes(db)
    assert 2 <= stored < 400
    if sig == signal.SIGTERM:  # handled as Ctrl-C: a clean stop with the resume hint
        assert code == 130
        assert err.read_text().splitlines()[-1] == (
            f"interrupted: {stored} episode(s) of 'long' are stored in {db}; run again with "
            "--resume to finish"
        )
    else:
        assert code == -signal.SIGKILL
