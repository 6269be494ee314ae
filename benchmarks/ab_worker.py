"""A/B benchmarking against another uvnav source tree, shared by the benchmark scripts.

A :class:`SourceTreeWorker` is a child process running ``SCRIPT --worker`` with ``uvnav`` imported
from another tree (``--against DIR``), so two versions are timed alternately in one run on the same
machine and load.  The worker's protocol: on start it prints ``{"uvnav": <package dir>}``, then
answers each JSON line on stdin with one JSON line (see :func:`serve`).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any


def source_dir(path: Path) -> Path:
    """``path`` if it holds ``uvnav/``, else ``path/src`` (exit with a message if neither)."""
    path = Path(path).resolve()
    if (path / "uvnav" / "__init__.py").exists():
        return path
    if (path / "src" / "uvnav" / "__init__.py").exists():
        return path / "src"
    raise SystemExit(f"--against {path}: no uvnav/ or src/uvnav/ there")


def serve(handle: Callable[[dict[str, Any]], dict[str, Any]]) -> int:
    """The ``--worker`` side: announce which ``uvnav`` was imported, then answer every job with
    ``handle(job)`` (an exception becomes ``{"error": ...}``)."""
    import uvnav

    print(json.dumps({"uvnav": str(Path(uvnav.__file__).parent)}), flush=True)
    for line in sys.stdin:
        try:
            out = handle(json.loads(line))
        except Exception as exc:
            out = {"error": f"{type(exc).__name__}: {exc}"}
        print(json.dumps(out), flush=True)
    return 0


class SourceTreeWorker:
    """``python SCRIPT --worker`` with ``src`` first on ``PYTHONPATH``."""

    def __init__(self, script: Path, src: Path, timeout_s: float = 120.0) -> None:
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join(
            [str(src), *([env["PYTHONPATH"]] if env.get("PYTHONPATH") else [])]
        )
        self.timeout_s = timeout_s
        self.proc = subprocess.Popen(
            [sys.executable, str(Path(script).resolve()), "--worker"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            env=env,
        )
        self.uvnav = str(self._read().get("uvnav"))

    def _read(self) -> dict[str, Any]:
        assert self.proc.stdout is not None
        line = self.proc.stdout.readline()
        if not line:
            raise RuntimeError("benchmark worker exited (see its stderr above)")
        out: dict[str, Any] = json.loads(line)
        return out

    def run(self, job: dict[str, Any]) -> dict[str, Any]:
        """Send one job, return its answer."""
        assert self.proc.stdin is not None
        self.proc.stdin.write(json.dumps(job) + "\n")
        self.proc.stdin.flush()
        return self._read()

    def close(self) -> None:
        if self.proc.stdin is not None:
            self.proc.stdin.close()
        self.proc.wait(timeout=self.timeout_s)
