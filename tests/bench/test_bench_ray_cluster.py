"""``uvnav bench --engine ray --address`` on a Ray cluster uvnav did not start.

A real head (``ray start --head --block``, 1 CPU, no dashboard, its node address given as
127.0.0.1, token authentication on: ``RAY_AUTH_MODE=token``, the token in ``RAY_AUTH_TOKEN``,
which a worker node needs both of) and, where a test needs one, a second node (``ray start
--address HEAD``, 1 CPU of its own) on this machine.  Campaigns through ``HOST:PORT`` and
through ``auto`` store the rows the local engine stores; a node killed mid-campaign loses
nothing (Ray runs its tasks again elsewhere); a node whose workers import other uvnav code is
refused before the database is created; a wrong token, an unreachable address, a malformed one and
a Ray Client address without Ray Client are each one ``error:`` line, exit status 2, within
seconds.

Every Ray process here runs with its own ``RAY_TMPDIR`` (sessions, logs, sockets and the
current-cluster record that ``auto`` reads), removed at the end, so ``auto`` finds this
cluster and no other.  A node is stopped by ending the processes of its session (``ray start``
is started in a new session; its raylet, agents and workers stay in it), never by ``ray stop``,
which would stop every Ray instance of this user on the machine.  Skipped when Ray is not
installed or ``ray start`` cannot start a head here.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import socket
import sqlite3
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd
import pytest

import uvnav
from uvnav.sim import METRIC_NAMES

pytest.importorskip("ray")
pytestmark = pytest.mark.slow

TOKEN = "uvnav-test-token-0123456789abcdef0123456789abcdef"
TINY = """\
name: tiny
scenarios: [{generator: random-ch2, seeds: [0, 2]}]
controllers: [{name: straight-v1}, {name: zhang2019-v1}]
"""
#: long enough to kill a node while it runs a task: the second node's worker starts cold
#: (imports, compiled kernels) and, under the load of the whole suite, a campaign of 240 or 600
#: episodes (2-4 s) has ended on the head before it took one
LARGE = """\
name: large
scenarios: [{generator: random-ch2, seeds: [0, 1000]}]
controllers: [{name: straight-v1}, {name: zhang2019-v1}]
"""
LARGE_EPISODES = 2000
COLUMNS = ["scenario", "controller", "params_hash", "seed", "status"]
DETERMINISTIC = [m for m in METRIC_NAMES if not m.startswith("decision_us")]
SRC = str(Path(uvnav.__file__).resolve().parents[1])


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def _ray_cli() -> str:
    return str(Path(sys.executable).with_name("ray"))


def _session(sid: int) -> list[int]:
    """The living processes of session ``sid``."""
    pids = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                if os.getsid(int(entry)) == sid:
                    pids.append(int(entry))
            except OSError:
                pass
    return pids


def _kill(node: subprocess.Popen[bytes]) -> None:
    """SIGKILL every process of the node's session (``ray start``, raylet, agents, workers)."""
    for pid in _session(node.pid):
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)
    node.wait(timeout=10)


def _stop(node: subprocess.Popen[bytes]) -> None:
    """SIGTERM ``ray start --block`` (it stops the node's processes), then :func:`_kill` what
    is left of its session."""
    if node.poll() is None:
        node.send_signal(signal.SIGTERM)
        with contextlib.suppress(subprocess.TimeoutExpired):
            node.wait(timeout=20)
    deadline = time.monotonic() + 10
    while _session(node.pid) and time.monotonic() < deadline:
        time.sleep(0.2)
    _kill(node)


def _env(**extra: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("RAY_")}
    env["PYTHONPATH"] = SRC  # the nodes' workers import this checkout's uvnav
    env.update(extra)
    return env


@dataclass
class Cluster:
    """A head on this machine, and the worker nodes the tests start."""

    address: str
    tmp: Path
    nodes: list[subprocess.Popen[bytes]] = field(default_factory=list)

    def env(self, **extra: str) -> dict[str, str]:
        return _env(**{"RAY_TMPDIR": str(self.tmp), "RAY_AUTH_TOKEN": TOKEN, **extra})

    def start(self, log: Path, *args: str, pythonpath: str = SRC) -> subprocess.Popen[bytes]:
        """``ray start --block ARGS`` in a new session, once it says it started (the head:
        skip the module if it cannot start; another node: fail)."""
        with open(log, "wb") as out:
            proc = subprocess.Popen(
                [_ray_cli(), "start", "--block", "--num-cpus=1",
                 "--node-ip-address=127.0.0.1", *args],
                stdout=out, stderr=subprocess.STDOUT, start_new_session=True,
                env=self.env(RAY_AUTH_MODE="token", PYTHONPATH=pythonpath),
            )  # fmt: skip
        self.nodes.append(proc)
        deadline = time.monotonic() + 60
        while b"Ray runtime started" not in log.read_bytes():
            if proc.poll() is not None or time.monotonic() > deadline:
                why = f"ray start cannot start a node here: {log.read_text()[-300:]}"
                if self.nodes[1:]:
                    pytest.fail(why)
                pytest.skip(why)
            time.sleep(0.3)
        return proc

    def add_node(self, log: Path, pythonpath: str = SRC) -> subprocess.Popen[bytes]:
        """A second raylet of 1 CPU joining the head."""
        return self.start(log, f"--address={self.address}", pythonpath=pythonpath)


@pytest.fixture(scope="module")
def cluster(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Cluster]:
    """A Ray head with token authentication and its own ``RAY_TMPDIR``; every node started
    from it is stopped, and the folder removed, at the end."""
    port = _free_port()
    tmp = Path(tempfile.mkdtemp(prefix="uvr-"))  # short: Ray's socket paths must fit 107 bytes
    head = Cluster(f"127.0.0.1:{port}", tmp)
    try:
        log = tmp_path_factory.mktemp("head") / "ray-start.log"
        head.start(log, "--head", f"--port={port}", "--include-dashboard=false")
        yield head
    finally:
        for node in reversed(head.nodes):
            _stop(node)
        shutil.rmtree(tmp, ignore_errors=True)


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / f"{text.split()[1]}.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def _bench_cmd(tmp_path: Path, campaign: str, db: str, *args: str) -> list[str]:
    path = _write(tmp_path, campaign)
    return [sys.executable, "-m", "uvnav", "bench", str(path), "--db", str(tmp_path / db), *args]


def _bench(
    tmp_path: Path, campaign: str, db: str, *args: str, env: dict[str, str] | None = None
) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        _bench_cmd(tmp_path, campaign, db, *args), env=env or _env(), cwd=tmp_path,
        capture_output=True, text=True, timeout=180,
    )  # fmt: skip


def _rows(path: Path) -> pd.DataFrame:
    with sqlite3.connect(path) as con:
        df = pd.read_sql_query("SELECT * FROM episodes", con)
    return df.sort_values(["controller", "seed"]).reset_index(drop=True)[COLUMNS + DETERMINISTIC]


def _count(path: Path) -> int:
    """Episodes stored in ``path`` (-1 before its table exists)."""
    try:
        with sqlite3.connect(f"file:{path}?mode=ro", uri=True) as con:
            return int(con.execute("SELECT COUNT(*) FROM episodes").fetchone()[0])
    except sqlite3.Error:
        return -1


def _running_task(node: subprocess.Popen[bytes]) -> bool:
    """Whether a worker of ``node`` runs a campaign task (Ray names it after the function)."""
    for pid in _session(node.pid):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as fh:
                if fh.read().startswith(b"ray::fingerprinted"):
                    return True
        except OSError:
            pass
    return False


def _local(tmp_path: Path, campaign: str) -> pd.DataFrame:
    name = campaign.split()[1]
    out = _bench(tmp_path, campaign, f"{name}-local.sqlite", "--engine", "local", "--workers", "1")
    assert out.returncode == 0, out.stderr
    rows = _rows(tmp_path / f"{name}-local.sqlite")
    assert set(rows["status"]) - {"error"} == set(rows["status"])
    return rows


def test_two_nodes_equal_local_and_a_dead_node_loses_nothing(
    tmp_path: Path, cluster: Cluster
) -> None:
    node = cluster.add_node(tmp_path / "node.log")
    want = _local(tmp_path, TINY)
    for address in (cluster.address, "auto"):
        name = f"tiny-{address.replace(':', '-')}.sqlite"
        out = _bench(tmp_path, TINY, name, "--engine", "ray", "--address", address,
                     env=cluster.env())  # fmt: skip
        assert out.returncode == 0, out.stderr
        assert "ran 4 episode(s) (0 error(s))" in out.stdout
        pd.testing.assert_frame_equal(_rows(tmp_path / name), want)

    # the second node is killed (SIGKILL, all its processes) while it runs a task
    db = tmp_path / "large.sqlite"
    cmd = _bench_cmd(tmp_path, LARGE, db.name, "--engine", "ray", "--address", cluster.address)
    with open(tmp_path / "out", "w") as sink, open(tmp_path / "err", "w") as err:
        run = subprocess.Popen(cmd, env=cluster.env(), cwd=tmp_path, stdout=sink, stderr=err)
    killed_at = None
    try:
        while run.poll() is None:
            if killed_at is None and _count(db) >= 4 and _running_task(node):
                _kill(node)
                killed_at = _count(db)
            time.sleep(0.05)
    finally:
        if run.poll() is None:
            run.kill()
    stdout, stderr = (tmp_path / "out").read_text(), (tmp_path / "err").read_text()
    assert killed_at is not None, f"the campaign ended before the node ran a task: {stderr}"
    assert run.returncode == 0, stderr
    assert f"ran {LARGE_EPISODES} episode(s) (0 error(s))" in stdout
    assert "(raylet)" not in stdout  # Ray's notices go to stderr, never into --json output
    got = _rows(db)
    assert killed_at < len(got) == LARGE_EPISODES
    pd.testing.assert_frame_equal(got, _local(tmp_path, LARGE))


def test_a_node_running_other_code_is_refused(tmp_path: Path, cluster: Cluster) -> None:
    """A node whose workers import a uvnav with one campaign file changed (an honest stale
    install) is refused by the start-up check, before the database is created."""
    stale = tmp_path / "stale"
    shutil.copytree(Path(SRC) / "uvnav", stale / "uvnav",
                    ignore=shutil.ignore_patterns("__pycache__"))  # fmt: skip
    with open(stale / "uvnav" / "bench" / "jobs.py", "a", encoding="utf-8") as fh:
        fh.write("\n# an older uvnav\n")
    node = cluster.add_node(tmp_path / "node.log", pythonpath=str(stale))
    try:
        out = _bench(tmp_path, TINY, "x.sqlite", "--engine", "ray", "--address",
                     cluster.address, env=cluster.env())  # fmt: skip
    finally:
        _stop(node)
    assert out.returncode == 2, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: --address: the Ray workers on node ")
    assert "run other uvnav code than this driver" in lines[0]
    assert not (tmp_path / "x.sqlite").exists()  # refused before the database is created


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
    tmp_path: Path, cluster: Cluster, address: str, env: dict[str, str], expected: str
) -> None:
    target = {"HEAD": cluster.address, "UNREACHABLE": f"127.0.0.1:{_free_port()}"}.get(
        address, address
    )
    _one_error_line(tmp_path, target, expected, cluster.env(**env))


def _one_error_line(tmp_path: Path, address: str, expected: str, env: dict[str, str]) -> None:
    tic = time.monotonic()
    out = _bench(tmp_path, TINY, "x.sqlite", "--engine", "ray", "--address", address, env=env)
    assert time.monotonic() - tic < 15
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: --address: "), out.stderr
    assert expected in lines[0]
    assert not (tmp_path / "x.sqlite").exists()  # checked before the database is created


def test_ray_client_address_without_ray_client(tmp_path: Path) -> None:
    """Ray 2.60's ``ray://`` addresses need Ray Client (extra ``ray[client]``: grpcio), which
    ``uvnav[bench]`` does not install; without it the address is refused in one line saying
    what to pass instead (``ray start --head --ray-client-server-port`` refuses to start too)."""
    from ray._private.utils import get_ray_client_dependency_error

    if get_ray_client_dependency_error() is None:
        pytest.skip("Ray Client is installed here")
    port = _free_port()
    _one_error_line(tmp_path, f"ray://127.0.0.1:{port}", "Ray Client is not installed", _env())
    started = subprocess.run(
        [_ray_cli(), "start", "--head", f"--port={_free_port()}", "--num-cpus=1",
         f"--ray-client-server-port={port}", "--include-dashboard=false"],
        env=_env(RAY_TMPDIR=str(tmp_path)), capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert started.returncode != 0 and "ray[client]" in started.stdout + started.stderr
