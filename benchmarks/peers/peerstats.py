"""What the peer benchmarks share: the CPU clock, medians of repetitions, ratios and targets.

Pure helpers, no timing of their own beyond :func:`cpu_s` (unit-tested in
``tests/bench/test_bench_peers.py``).  Conventions:

* every run is timed with :func:`time.process_time` (CPU time of the whole process, so that a
  peer's helper threads would be counted too) around a single-threaded loop;
* a side's figure is the **median** over its runs of CPU µs per step (each run: CPU s / steps
  done), never a best-of;
* a ratio is a quotient of two medians measured in the same run; a difference of two timings is
  reported only when it is positive (:func:`positive_or_none`): a negative or zero estimate is
  noise, left out and said so.
"""

from __future__ import annotations

import math
import os
import statistics
import time
from collections.abc import Sequence
from typing import Any

#: fewer repetitions than this and a median is marked as indicative only
MIN_REPEATS = 5
#: environment variables that keep numerical libraries on one thread
ONE_THREAD = (
    "OMP_NUM_THREADS",
    "OPENBLAS_NUM_THREADS",
    "MKL_NUM_THREADS",
    "NUMEXPR_NUM_THREADS",
    "NUMBA_NUM_THREADS",
)


def single_threaded() -> None:
    """Ask numerical libraries for one thread (call before numpy is imported)."""
    for key in ONE_THREAD:
        os.environ.setdefault(key, "1")


def cpu_s() -> float:
    """This process's CPU time [s] (:func:`time.process_time`)."""
    return time.process_time()


def us_per_step(run: dict[str, Any]) -> float | None:
    """CPU µs per step of one run (``cpu_s``, ``steps``); ``None`` when it did no step."""
    steps = run.get("steps") or 0
    return 1e6 * float(run["cpu_s"]) / steps if steps > 0 else None


def summarize(runs: Sequence[dict[str, Any]]) -> dict[str, Any]:
    """Median (and range) of the runs' CPU µs per step, and the steps per CPU second it means.

    ``runs``: dicts with ``cpu_s`` and ``steps``; runs without a step are left out.
    """
    per = [u for u in (us_per_step(r) for r in runs) if u is not None and u > 0]
    if not per:
        return {"repeats": 0, "median_us_per_step": None, "steps_per_s": None}
    med = statistics.median(per)
    out: dict[str, Any] = {
        "repeats": len(per),
        "steps_per_run": [int(r["steps"]) for r in runs],
        "us_per_step_runs": per,
        "median_us_per_step": med,
        "min_us_per_step": min(per),
        "max_us_per_step": max(per),
        "steps_per_s": 1e6 / med,
    }
    if len(per) < MIN_REPEATS:
        out["note"] = f"median of {len(per)} runs (< {MIN_REPEATS}): indicative only"
    return out


def ratio(numerator: float | None, denominator: float | None) -> float | None:
    """``numerator / denominator``, or ``None`` when either is missing or not positive."""
    if numerator is None or denominator is None or numerator <= 0 or denominator <= 0:
        return None
    return numerator / denominator


def positive_or_none(value: float | None) -> float | None:
    """An estimate made as a difference of timings: kept when positive, else ``None``."""
    return value if value is not None and value > 0 else None


def judge(measured: float | None, limit: float, direction: str) -> dict[str, Any]:
    """A target record: ``limit``, ``direction`` (``"<="`` or ``">="``), ``measured``, ``pass``
    (``None`` when nothing was measured) and ``ratio`` = measured / limit."""
    if direction not in ("<=", ">="):
        raise ValueError(f"direction must be '<=' or '>=' (got {direction!r})")
    ok: bool | None
    if measured is None:
        ok = None
    elif direction == "<=":
        ok = bool(measured <= limit)
    else:
        ok = bool(measured >= limit)
    return {
        "limit": limit,
        "direction": direction,
        "measured": measured,
        "ratio": ratio(measured, limit),
        "pass": ok,
    }


def fmt(x: float | None, width: int, digits: int) -> str:
    """``x`` right-aligned in ``width`` with ``digits`` decimals, ``-`` when missing."""
    if x is None or not math.isfinite(x):
        return f"{'-':>{width}}"
    return f"{x:{width}.{digits}f}"
