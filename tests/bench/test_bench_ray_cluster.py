"""``uvnav bench --engine ray --address`` on a Ray cluster uvnav did not start: a real head
(``ray start --head --block`` on 127.0.0.1, 1 CPU, no dashboard, token authentication on) runs a
campaign whose stored rows equal the local engine's; a wrong token, an unreachable address and a
malformed one are each one ``error:`` line, exit status 2, within seconds.

The head is stopped by ending its process group (the processes ``ray start`` started), not by
``ray stop``, which would stop every Ray instance of this user on the machine; its record in
Ray's temporary folder is removed, so later tests start their own local Ray.  Skipped when Ray
is not installed or ``ray start`` cannot start a head here.
"""

from __future__ import annotations

import os
import signal
import socket
import sqlite3
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

import pandas as pd
import pytest

import uvnav
from uvnav.sim import METRIC_NAMES

pytest.importorskip("ray")
pytestmark = pytest.mark.slow

TOKEN = "uvnav-test-token-0123456789abcdef0123456789abcdef"
CAMPAIGN = """\
name: tiny
scenarios: [{generator: random-ch2, seeds: [0, 2]}]
controllers: [{name: straight-v1}, {name: zhang2019-v1}]
"""
COLUMNS = ["scenario", "controller", "params_hash", "seed", "status"]
DETERMINISTIC = [m for m in METRIC_NAMES if not m.startswith("decision_us")]
SRC = str(Path(uvnav.__file__).resolve().parents[1])


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def _ray_cli() -> str:
    return str(Path(sys.executable).with_name("ray"))


def _stop(head: subprocess.Popen[bytes]) -> None:
    """End the head's process group: SIGTERM (``--block`` stops its processes), then SIGKILL."""
    for sig, wait in ((signal.SIGTERM, 20.0), (signal.SIGKILL, 5.0)):
        try:
            os.killpg(head.pid, sig)
        except ProcessLookupError:
            return
        try:
            head.wait(timeout=wait)
            os.killpg(head.pid, 0)  # raises once every process of the group is gone
        except (subprocess.TimeoutExpired, ProcessLookupError):
            pass


def _env(**extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("RAY_")}
    env["PYTHONPATH"] = SRC  # the head's workers import this checkout's uvnav
    env.update(extra)
    return env


@pytest.fixture(scope="module")
def head(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    """``127.0.0.1:PORT`` of a Ray head with token authentication, stopped at the end."""
    port = _free_port()
    log = tmp_path_factory.mktemp("head") / "ray-start.log"
    cmd = [_ray_cli(), "start", "--head", "--block", f"--port={port}", "--num-cpus=1",
           "--node-ip-address=127.0.0.1", "--include-dashboard=false"]  # fmt: skip
    with open(log, "wb") as out:
        proc = subprocess.Popen(
            cmd, stdout=out, stderr=subprocess.STDOUT, start_new_session=True,
            env=_env(RAY_AUTH_MODE="token", RAY_AUTH_TOKEN=TOKEN),
        )  # fmt: skip
    try:
        deadline = time.monotonic() + 60
        while b"Ray runtime started" not in log.read_bytes():
            if proc.poll() is not None or time.monotonic() > deadline:
                pytest.skip(f"ray start cannot start a head here: {log.read_text()[-300:]}")
            time.sleep(0.5)
        yield f"127.0.0.1:{port}"
    finally:
        _stop(proc)
        _forget(port)


def _forget(port: int) -> None:
    """Remove Ray's record of the current cluster if it names this head (a ``ray.init()`` without
    address would otherwise try to connect to it instead of starting Ray)."""
    record = Path(tempfile.gettempdir()) / "ray" / "ray_current_cluster"
    try:
        if record.read_text(encoding="utf-8").strip().endswith(f":{port}"):
            record.unlink()
    except OSError:
        pass


def _bench(tmp_path: Path, db: str, *args: str, **env: str) -> subprocess.CompletedProcess[str]:
    campaign = tmp_path / "tiny.yaml"
    campaign.write_text(CAMPAIGN, encoding="utf-8")
    cmd = [sys.executable, "-m", "uvnav", "bench", str(campaign), "--db", str(tmp_path / db)]
    return subprocess.run(
        [*cmd, *args], env=_env(**env), capture_output=True, text=True, timeout=180
    )


def _rows(path: Path) -> pd.DataFrame:
    with sqlite3.connect(path) as con:
        df = pd.read_sql_query("SELECT * FROM episodes", con)
    return df.sort_values(["controller", "seed"]).reset_index(drop=True)[COLUMNS + DETERMINISTIC]


def test_campaign_on_a_cluster_equals_local(tmp_path: Path, head: str) -> None:
    local = _bench(tmp_path, "local.sqlite", "--engine", "local", "--workers", "1")
    assert local.returncode == 0, local.stderr
    ran = _bench(tmp_path, "ray.sqlite", "--engine", "ray", "--address", head,
                 RAY_AUTH_TOKEN=TOKEN)  # fmt: skip
    assert ran.returncode == 0, ran.stderr
    assert "ran 4 episode(s) (0 error(s))" in ran.stdout
    want, got = _rows(tmp_path / "local.sqlite"), _rows(tmp_path / "ray.sqlite")
    assert len(want) == 4 and set(want["status"]) - {"error"} == set(want["status"])
    pd.testing.assert_frame_equal(got, want)


@pytest.mark.parametrize(
    ("address", "env", "expected"),
    [
        ("HEAD", {"RAY_AUTH_TOKEN": "wrong-token"}, "refused this driver's authentication token"),
        ("HEAD", {"RAY_AUTH_MODE": "disabled"}, "set RAY_AUTH_MODE=token"),
        ("UNREACHABLE", {}, "cannot reach the Ray cluster at 127.0.0.1:"),
        ("no-port", {}, "expected auto, HOST:PORT or ray://HOST:PORT"),
    ],
)
def test_unusable_cluster_is_one_error_line(
    tmp_path: Path, head: str, address: str, env: dict[str, str], expected: str
) -> None:
    target = {"HEAD": head, "UNREACHABLE": f"127.0.0.1:{_free_port()}"}.get(address, address)
    tic = time.monotonic()
    out = _bench(tmp_path, "x.sqlite", "--engine", "ray", "--address", target, **env)
    assert time.monotonic() - tic < 15
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: --address: "), out.stderr
    assert expected in lines[0]
    assert not (tmp_path / "x.sqlite").exists()  # checked before the database is created
