"""Issue 17: a campaign interrupted 50 times and resumed each time stores, row for row, what an
uninterrupted run stores (every column but the wall-clock timings and the row ids/dates).

The interruption points are drawn by a seeded generator.  Most interruptions happen in-process
(the local engine on one worker, so nothing forks): a ``KeyboardInterrupt`` before or after an
episode runs, after its row is stored, inside the store's transaction, or from a timer signal at
an arbitrary moment, the way Ctrl-C arrives.  The slow test adds real ones: Ctrl-C (SIGINT to the
process group) and SIGKILL of ``uvnav bench`` on two workers.
"""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager, nullcontext
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import pandas as pd
import pytest

import uvnav.bench.campaign as campaign_mod
from processes import start_foreground
from processes import stored_episodes as stored
from uvnav.bench.spec import load_campaign, run_campaign_spec
from uvnav.bench.store import ResultsStore

# 48 short episodes (~0.03 s each): 24 generated scenes × 2 controllers
CAMPAIGN = """\
name: fifty
scenarios:
  - generator: random-ch2
    seeds: [0, 24]
controllers:
  - name: straight-v1
  - name: zhang2019-v1
"""
N_EPISODES = 48
KEY = ["scenario", "controller", "params_hash", "seed"]
# what may differ between two runs of the same episodes: row ids and dates, wall-clock timings
VOLATILE = ["id", "created", "wall_time", "decision_us_median", "decision_us_p99"]

IN_PROCESS_KINDS = ("before-episode", "after-episode", "after-store", "in-transaction", "timer")


def rows(db: Path) -> pd.DataFrame:
    with ResultsStore(db) as store:
        df = store.episodes_frame("fifty")
    return df.drop(columns=VOLATILE).sort_values(KEY).reset_index(drop=True)


@pytest.fixture(scope="module")
def campaign_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("fifty") / "fifty.yaml"
    path.write_text(CAMPAIGN)
    return path


class Timing(NamedTuple):
    """How long an uninterrupted run takes on this machine, warm: its start (reading the file,
    the store's resume query) and each episode [s].  Timed interruptions are drawn in these
    units, so that a fast machine does not finish the campaign between them, nor a slow one
    never reach an episode."""

    start_s: float
    episode_s: float


def timed_run(db: Path, campaign_file: Path) -> float:
    """Wall time [s] of an uninterrupted ``--resume`` run into ``db``."""
    wall = time.perf_counter()
    with ResultsStore(db) as store:
        run_campaign_spec(store, load_campaign(campaign_file), resume=True, workers=1)
    return time.perf_counter() - wall


@pytest.fixture(scope="module")
def reference(campaign_file: Path) -> pd.DataFrame:
    """The rows of an uninterrupted run."""
    db = campaign_file.parent / "reference.sqlite"
    with ResultsStore(db) as store:
        run = run_campaign_spec(store, load_campaign(campaign_file), workers=1)
    assert (run.ran, run.errors) == (N_EPISODES, 0)
    df = rows(db)
    assert len(df) == N_EPISODES and set(df["status"]) <= {"success", "collision", "timeout"}
    return df


@pytest.fixture(scope="module")
def timing(campaign_file: Path, reference: pd.DataFrame) -> Timing:
    """:class:`Timing` of a second whole run (the first loaded the compiled kernels), its start
    timed by a resume that finds every episode stored."""
    db = campaign_file.parent / "timing.sqlite"
    whole = timed_run(db, campaign_file)
    start = min(timed_run(db, campaign_file) for _ in range(3))
    return Timing(start, max(whole - start, 0.0) / N_EPISODES)


def assert_same_rows(db: Path, reference: pd.DataFrame) -> None:
    got = rows(db)
    assert len(got) == N_EPISODES
    assert not got.duplicated(KEY).any()
    pd.testing.assert_frame_equal(got, reference, check_exact=True)


@contextmanager
def raising_on_call(obj: Any, name: str, n: int, *, after: bool) -> Iterator[None]:
    """``obj.name`` raises ``KeyboardInterrupt`` on its ``n``-th call, before or after it runs."""
    original = getattr(obj, name)
    calls = [0]

    def wrapped(*args: Any, **kwargs: Any) -> Any:
        calls[0] += 1
        if calls[0] == n and not after:
            raise KeyboardInterrupt
        out = original(*args, **kwargs)
        if calls[0] == n:
            raise KeyboardInterrupt
        return out

    setattr(obj, name, wrapped)
    try:
        yield
    finally:
        setattr(obj, name, original)


@contextmanager
def interrupting_transaction(n: int) -> Iterator[None]:
    """The store's ``n``-th transaction is interrupted just before its COMMIT (rolled back)."""
    original = ResultsStore._transaction
    calls = [0]

    @contextmanager
    def transaction(self: ResultsStore) -> Iterator[sqlite3.Connection]:
        with original(self) as conn:
            yield conn
            calls[0] += 1
            if calls[0] == n:
                raise KeyboardInterrupt

    ResultsStore._transaction = transaction  # type: ignore[method-assign]
    try:
        yield
    finally:
        ResultsStore._transaction = original  # type: ignore[method-assign]


@contextmanager
def timer_interrupt(delay: float) -> Iterator[None]:
    """A signal raises ``KeyboardInterrupt`` in the main thread ``delay`` seconds from now,
    wherever it is (between two bytecodes), as Ctrl-C does."""
    previous = signal.signal(signal.SIGALRM, signal.default_int_handler)
    try:
        signal.setitimer(signal.ITIMER_REAL, delay)
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def run_in_process(db: Path, campaign_file: Path, interrupt: Any = None) -> bool:
    """One ``uvnav bench --resume`` in this process (one worker); whether it finished."""
    sigterm = signal.getsignal(signal.SIGTERM)
    try:
        # a fresh connection each time, as a new process has
        with interrupt if interrupt is not None else nullcontext(), ResultsStore(db) as store:
            run_campaign_spec(store, load_campaign(campaign_file), resume=True, workers=1)
    except KeyboardInterrupt:
        return False
    finally:  # an interrupt may land between the campaign's own signal set-up and restore
        signal.signal(signal.SIGTERM, sigterm)
    return True


def in_process_interrupt(rng: np.random.Generator, timing: Timing) -> tuple[str, Any]:
    """A random in-process interruption: its kind and context manager (a timer goes off
    between the run's start and the end of its second episode)."""
    kind = str(rng.choice(IN_PROCESS_KINDS))
    n = int(rng.integers(1, 3))  # the first or the second call: about one episode per resume
    if kind == "before-episode":
        return kind, raising_on_call(campaign_mod, "run_job", n, after=False)
    if kind == "after-episode":
        return kind, raising_on_call(campaign_mod, "run_job", n, after=True)
    if kind == "after-store":
        return kind, raising_on_call(campaign_mod, "store_outcome", n, after=True)
    if kind == "in-transaction":
        return kind, interrupting_transaction(n)
    return kind, timer_interrupt(float(rng.uniform(0.0, timing.start_s + 2 * timing.episode_s)))


def test_fifty_interruptions_then_resume_equal_an_uninterrupted_run(
    tmp_path: Path, campaign_file: Path, reference: pd.DataFrame, timing: Timing
) -> None:
    rng = np.random.default_rng(2017)
    db = tmp_path / "interrupted.sqlite"
    kinds: dict[str, int] = {}
    interrupted = 0
    for _ in range(50):
        kind, interrupt = in_process_interrupt(rng, timing)
        finished = run_in_process(db, campaign_file, interrupt)
        kinds[kind] = kinds.get(kind, 0) + 1
        interrupted += not finished
        assert stored(db) <= N_EPISODES
    assert 0 < stored(db) < N_EPISODES, "the interruptions should stop the campaign midway"
    assert interrupted >= 45 and len(kinds) == len(IN_PROCESS_KINDS), kinds
    assert run_in_process(db, campaign_file)
    assert_same_rows(db, reference)


def _bench(campaign_file: Path, db: Path, err: Any) -> subprocess.Popen[bytes]:
    """``uvnav bench --resume`` in its own session: signals go to its whole process group."""
    cmd = [sys.executable, "-m", "uvnav.cli", "bench", str(campaign_file), "--db", str(db)]
    return start_foreground([*cmd, "--resume", "--workers", "2", "--json"], err)


def interrupt_process(
    campaign_file: Path, db: Path, sig: signal.Signals, delay: float, log: Path
) -> int | None:
    """Run ``uvnav bench --resume`` on two workers; send ``sig`` to its process group ``delay``
    seconds after its first new episode is stored.  Its exit status (``None``: it finished)."""
    before = stored(db)
    with log.open("a") as err:
        proc = _bench(campaign_file, db, err)
    try:
        deadline = time.monotonic() + 60
        while stored(db) <= before and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.01)
        time.sleep(delay)
        if proc.poll() is not None:
            return None
        os.killpg(proc.pid, sig)
        return proc.wait(timeout=10)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


@pytest.mark.slow
def test_real_interruptions_then_resume_equal_an_uninterrupted_run(
    tmp_path: Path, campaign_file: Path, reference: pd.DataFrame, timing: Timing
) -> None:
    """Ctrl-C and SIGKILL of ``uvnav bench`` on two workers, between in-process ones."""
    rng = np.random.default_rng(4242)
    db = tmp_path / "killed.sqlite"
    log = tmp_path / "stderr.txt"
    real = [signal.SIGINT, signal.SIGKILL, signal.SIGINT, signal.SIGKILL]
    for sig in real:
        delay = float(rng.uniform(0.0, 2.0)) * timing.episode_s
        code = interrupt_process(campaign_file, db, sig, delay, log)
        assert code == (130 if sig == signal.SIGINT else -signal.SIGKILL), log.read_text()
        for _ in range(2):
            run_in_process(db, campaign_file, in_process_interrupt(rng, timing)[1])
        assert stored(db) < N_EPISODES, "the campaign ended before all interruptions"
    assert run_in_process(db, campaign_file)
    assert_same_rows(db, reference)


# A worker killed while it writes a result left the pool's manager thread blocked reading the rest
# of the message, and Python joins that thread at exit: Ctrl-C hung.  Results of 40 MB keep the
# second worker writing when the first result interrupts the pool.
MID_WRITE = """\
import concurrent.futures.process as cfp
from uvnav.bench.campaign import run_in_workers

def stop(result):
    raise KeyboardInterrupt

if __name__ == "__main__":
    try:
        run_in_workers([40_000_000] * 8, bytes, stop, workers=2)
    except KeyboardInterrupt:
        pass
    threads = list(cfp._threads_wakeups)
    for t in threads:
        t.join(10)
    print("stuck:", sum(t.is_alive() for t in threads))
"""


def test_interrupt_while_a_worker_writes_its_result_does_not_hang(tmp_path: Path) -> None:
    script = tmp_path / "mid_write.py"
    script.write_text(MID_WRITE)
    done = subprocess.run(
        [sys.executable, str(script)], capture_output=True, text=True, timeout=30, check=False
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "stuck: 0", done.stdout + done.stderr
