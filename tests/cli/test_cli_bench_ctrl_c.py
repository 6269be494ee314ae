"""Ctrl-C never hangs ``uvnav bench`` (issue 17): at any moment of a campaign on two workers, the
process exits with status 130 within seconds, prints the one ``interrupted`` line, and leaves no
process behind (fork server and workers included)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from processes import LINUX_PROC, descendants, running, start_foreground, stored_episodes

# 400 episodes (~0.1-0.2 s each) on two workers: far from done when Ctrl-C comes
CAMPAIGN = """\
name: ctrl-c
scenarios:
  - generator: random-ch2
    seeds: [0, 200]
controllers:
  - name: zhang2019-v1
  - name: savkin-wang2013-v1
"""

#: how long Ctrl-C may take to end the campaign [s] (workers are killed, not waited for)
EXIT_WITHIN = 5.0
#: how long the workers' watchdogs and the fork server may take to follow [s]
TREE_GONE_WITHIN = 3.0

pytestmark = pytest.mark.skipif(not LINUX_PROC, reason="reads the process tree from Linux /proc")


def _ctrl_c_once(tmp_path: Path, delay: float, k: int) -> tuple[int, float, str, list[int]]:
    """Start a campaign, press Ctrl-C ``delay`` seconds after its first stored episode; return
    (exit status, seconds from Ctrl-C to exit, stderr, processes still running)."""
    campaign = tmp_path / "ctrl-c.yaml"
    campaign.write_text(CAMPAIGN)
    db = tmp_path / f"r{k}.sqlite"
    err = tmp_path / f"stderr{k}.txt"
    cmd = [sys.executable, "-m", "uvnav.cli", "bench", str(campaign), "--db", str(db)]
    with err.open("w") as fh:
        # own session: the Ctrl-C goes to the whole group, as a terminal sends it
        proc = start_foreground([*cmd, "--workers", "2", "--json"], fh)
    tree: set[int] = set()
    try:
        deadline = time.monotonic() + 60
        while proc.poll() is None and time.monotonic() < deadline:
            tree.update(descendants(proc.pid))
            if stored_episodes(db) >= 1 and len(tree) >= 3:  # fork server and two busy workers
                break
            time.sleep(0.02)
        end = time.monotonic() + delay
        while time.monotonic() < end:
            tree.update(descendants(proc.pid))
            time.sleep(0.01)
        assert proc.poll() is None, "the campaign ended before it could be interrupted"
        tree.update(descendants(proc.pid))
        os.killpg(proc.pid, signal.SIGINT)
        tic = time.monotonic()
        try:
            code = proc.wait(timeout=EXIT_WITHIN)
        except subprocess.TimeoutExpired:
            code = -999  # hung
        took = time.monotonic() - tic
        deadline = time.monotonic() + TREE_GONE_WITHIN
        while any(running(p) for p in tree) and time.monotonic() < deadline:
            time.sleep(0.05)
        survivors = sorted(p for p in tree if running(p))
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        for p in tree:  # only processes this test started
            if running(p):
                os.kill(p, signal.SIGKILL)
    return code, took, err.read_text(), survivors


@pytest.mark.slow
def test_ctrl_c_at_random_moments_never_hangs(tmp_path: Path) -> None:
    rng = np.random.default_rng(17)
    for k, delay in enumerate(rng.uniform(0.0, 0.6, size=8)):
        code, took, stderr, survivors = _ctrl_c_once(tmp_path, float(delay), k)
        what = f"Ctrl-C #{k} after {delay:.2f} s"
        assert code == 130, f"{what}: exit status {code} after {took:.1f} s; stderr:\n{stderr}"
        assert took < EXIT_WITHIN
        lines = stderr.strip().splitlines()
        assert [ln for ln in lines if "interrupted" in ln] == lines[-1:], f"{what}: {stderr}"
        assert lines[-1].startswith("interrupted: ") and "--resume" in lines[-1]
        assert "Traceback" not in stderr, f"{what}: {stderr}"
        assert survivors == [], f"{what}: processes of the campaign survived it: {survivors}"
