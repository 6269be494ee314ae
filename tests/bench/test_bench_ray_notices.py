"""While a campaign runs on Ray, Ray's driver notices go to the engine's log and not to stdout,
whichever thread prints them (:func:`uvnav.bench.ray_engine._ray_notices_logged`); the
command's own output is unchanged.  Ray's own printer is used; no Ray instance is started.

Skipped when Ray (extra ``uvnav[bench]``) is not installed."""

from __future__ import annotations

import logging
import sys
import threading

import pytest

from uvnav.bench.ray_engine import RAY_NOTICE_THREAD, _ray_notices_logged

ray_worker = pytest.importorskip("ray._private.worker")

NOTICE = {"lines": ["A worker died or was killed while executing a task."], "pid": "raylet",
          "ip": "127.0.0.1", "localhost": "127.0.0.1"}  # fmt: skip


def _print_notice() -> None:
    ray_worker.print_worker_logs(dict(NOTICE), sys.stdout)


def test_notices_printed_from_any_thread_go_to_the_log(
    capsys: pytest.CaptureFixture[str], caplog: pytest.LogCaptureFixture
) -> None:
    """A notice Ray prints from the main thread (the repeats it flushes as it disconnects) or
    from its notice thread is logged; a line the command prints stays on stdout."""
    caplog.set_level(logging.INFO, logger="uvnav.bench.ray_engine")
    with _ray_notices_logged():
        print("ran 4 episode(s) (0 error(s))")
        _print_notice()
        thread = threading.Thread(target=_print_notice, name=RAY_NOTICE_THREAD)
        thread.start()
        thread.join()
    out = capsys.readouterr().out
    assert out == "ran 4 episode(s) (0 error(s))\n"
    logged = [r.getMessage() for r in caplog.records if "worker died" in r.getMessage()]
    assert len(logged) == 2 and all("(raylet" in m for m in logged)


def test_outside_a_campaign_ray_prints_as_it_always_does(
    capsys: pytest.CaptureFixture[str],
) -> None:
    _print_notice()
    assert "(raylet" in capsys.readouterr().out
