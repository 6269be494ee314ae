"""A Ray instance started by uvnav listens on the loopback interface only (issue 17).

Ray's start-up costs several seconds, so this module is one test.  The listening TCP sockets of
this process and all its descendants (the GCS server, raylet, agents and workers Ray started) are
read while the campaign runs: with psutil where it can be imported, else from ``/proc``.
"""

from __future__ import annotations

import ipaddress
import os
from pathlib import Path

import pytest

from processes import descendants
from uvnav.bench.campaign import Job, run_campaign
from uvnav.bench.ray_engine import is_loopback
from uvnav.bench.store import ResultsStore

ray = pytest.importorskip("ray")

_TCP_LISTEN = "0A"


def _proc_address(hex_addr: str) -> str:
    """``/proc/net/tcp{,6}`` local address (``0100007F:1F90``) → its IP as text."""
    raw = bytes.fromhex(hex_addr.split(":")[0])
    # each 32-bit word is in host (little-endian) byte order
    words = b"".join(raw[i : i + 4][::-1] for i in range(0, len(raw), 4))
    return str(ipaddress.ip_address(words))


def _listening_proc(root: int) -> list[tuple[str, int]]:
    """``(ip, pid)`` of every listening TCP socket of ``root``'s process tree, from /proc."""
    listening: dict[str, str] = {}  # socket inode -> local ip
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        for line in Path(table).read_text().splitlines()[1:]:
            fields = line.split()
            if fields[3] == _TCP_LISTEN:
                listening[fields[9]] = _proc_address(fields[1])
    found = []
    for pid in [root, *descendants(root)]:
        for fd in Path(f"/proc/{pid}/fd").glob("*"):
            try:
                target = os.readlink(fd)
            except OSError:
                continue
            if target.startswith("socket:[") and target[8:-1] in listening:
                found.append((listening[target[8:-1]], pid))
    return found


def listening_sockets(root: int) -> list[tuple[str, int]]:
    """``(ip, pid)`` of every listening TCP socket of the process tree of ``root``."""
    try:
        import psutil
    except ImportError:
        return _listening_proc(root)
    me = psutil.Process(root)
    found = []
    for proc in [me, *me.children(recursive=True)]:
        try:
            conns = proc.net_connections(kind="inet")
        except (psutil.NoSuchProcess, psutil.AccessDenied):
            continue
        found += [(c.laddr.ip, proc.pid) for c in conns if c.status == psutil.CONN_LISTEN]
    return found


def test_ray_started_by_uvnav_listens_on_loopback_only(tmp_path: Path) -> None:
    if not Path("/proc/net/tcp").is_file():
        pytest.skip("needs Linux /proc to list the sockets of Ray's processes")
    if ray.is_initialized():
        pytest.skip("Ray is already running in this process (started by someone else)")
    seen: list[list[tuple[str, int]]] = []

    def snapshot(*_: object) -> None:
        seen.append(listening_sockets(os.getpid()))
        seen.append(_listening_proc(os.getpid()))  # the /proc reading too, psutil or not

    jobs = [Job(controller="straight-v1", seed=s, generator_seed=s) for s in (0, 1)]
    with ResultsStore(tmp_path / "r.sqlite") as store:
        try:
            run = run_campaign(store, "net", jobs, engine="ray", workers=1, on_outcome=snapshot)
        except Exception as exc:
            if "loopback" in str(exc):
                raise
            pytest.skip(f"Ray cannot start on this machine: {type(exc).__name__}: {exc}")
    assert run.ran == 2 and not ray.is_initialized()
    assert seen and all(seen), "Ray's processes listen on no TCP socket: nothing was checked"
    exposed = sorted({(ip, pid) for snap in seen for ip, pid in snap if not is_loopback(ip)})
    assert exposed == [], f"listening on a non-loopback address: {exposed}"


@pytest.mark.parametrize(
    ("host", "loopback"),
    [
        ("127.0.0.1", True),
        ("::ffff:127.0.0.1", True),
        ("::1", True),
        ("localhost", True),
        ("0.0.0.0", False),
        ("::", False),
        ("192.0.2.7", False),
        ("not-an-ip", False),
    ],
)
def test_is_loopback(host: str, loopback: bool) -> None:
    assert is_loopback(host) is loopback


def test_proc_address_decoding() -> None:
    assert _proc_address("0100007F:1F90") == "127.0.0.1"
    assert _proc_address("00000000000000000000000000000000:0050") == "::"
    mapped = _proc_address("0000000000000000FFFF00000100007F:0050")
    assert ipaddress.ip_address(mapped) == ipaddress.ip_address("::ffff:127.0.0.1")
