"""Shared helpers of the tests that start real processes: the process tree from Linux ``/proc``,
the episode count of a results database read without locking it, and a child started as a
terminal starts a foreground job."""

from __future__ import annotations

import signal
import sqlite3
import subprocess
from pathlib import Path
from typing import IO, Any

#: ``pytestmark`` of a test module that reads ``/proc``
LINUX_PROC = Path("/proc/self/task").is_dir()


def _terminal_signals() -> None:
    """In the child, before exec: Ctrl-C's default action, as a terminal's foreground job has."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def start_foreground(cmd: list[str], stderr: IO[Any]) -> subprocess.Popen[bytes]:
    """Start ``cmd`` (stdout discarded) as a terminal starts a foreground job that a test will
    press Ctrl-C on: in its own session (the signal goes to its whole process group, as a
    terminal sends it), with SIGINT's default action whatever this process inherited.  A test
    run started in the background of a shell without job control inherits SIGINT ignored;
    Python then installs no ``KeyboardInterrupt`` handler in the child and the Ctrl-C is lost."""
    return subprocess.Popen(
        cmd,
        stdout=subprocess.DEVNULL,
        stderr=stderr,
        start_new_session=True,
        preexec_fn=_terminal_signals,
    )


def children(pid: int) -> list[int]:
    """The direct children of ``pid`` (every thread's), from ``/proc``."""
    out: list[int] = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            out += [int(c) for c in (task / "children").read_text().split()]
        except OSError:
            continue
    return out


def descendants(pid: int) -> list[int]:
    """Every process below ``pid`` (not ``pid`` itself)."""
    found, todo = [], children(pid)
    while todo:
        p = todo.pop()
        found.append(p)
        todo += children(p)
    return found


def running(pid: int) -> bool:
    """Whether ``pid`` exists and is not a zombie."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state != "Z"


def stored_episodes(db: Path) -> int:
    """Episodes stored in the results database ``db`` (0 while it does not exist or is busy);
    read-only, so it never takes the writer's lock."""
    if not db.exists():
        return 0
    try:
        with sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=5) as conn:
            return int(conn.execute("SELECT COUNT(*) FROM episodes").fetchone()[0])
    except sqlite3.Error:
        return 0
