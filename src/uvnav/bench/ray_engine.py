"""Ray engine: a campaign's jobs as Ray tasks, results streamed back to the driver.

The same picklable :class:`~uvnav.bench.campaign.Job` s that the local process pool runs are sent to
:func:`~uvnav.bench.campaign.run_job` as Ray tasks (one CPU each).  Workers only compute; each
:class:`~uvnav.bench.campaign.JobOutcome` comes back to the driver, which writes it to the SQLite
store in its own transaction (DESIGN §5) — exactly as with the local engine, so resume, progress and
the stored metrics are the same whatever the engine.

Like the local pool, at most ``2 × workers`` tasks are in flight: large campaigns do not flood the
object store, and a killed driver loses at most those episodes.  Ray is started here only when it is
not running yet (``ray.init(address=..., num_cpus=workers)``; with no address a local instance) and
is shut down again at the end; a caller that already called ``ray.init`` keeps its instance (tests
start Ray once per module this way).

Ray is an optional dependency (extra ``uvnav[bench]``), imported only when this engine is used.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from types import ModuleType
from typing import Any

from uvnav.bench.campaign import Job, JobOutcome, run_job
from uvnav.bench.store import STATUS_ERROR


class EngineUnavailableError(RuntimeError):
    """The requested engine cannot run here (its optional dependency is missing)."""


def import_ray() -> ModuleType:
    """The ``ray`` module, or a one-line :class:`EngineUnavailableError` naming the extra."""
    try:
        import ray
    except ImportError as exc:
        raise EngineUnavailableError(
            f"the ray engine needs Ray: pip install 'uvnav[bench]' (cannot import ray: {exc})"
        ) from None
    return ray


def _crash_outcome(job: Job, exc: BaseException) -> JobOutcome:
    """A task that Ray could not complete (its worker died, even after retries) is an error row."""
    first = (str(exc).strip().splitlines() or [""])[0]
    return JobOutcome(job, STATUS_ERROR, None, f"{type(exc).__name__}: {first}", 0.0)


def run_ray(
    todo: Sequence[Job],
    handle: Callable[[JobOutcome], None],
    *,
    workers: int = 1,
    address: str | None = None,
) -> None:
    """Run ``todo`` as Ray tasks, handing each outcome to ``handle`` (in this process) as it ends.

    Args:
        todo: jobs to run.
        handle: called with each outcome, in completion order (it stores the episode).
        workers: CPUs of the local Ray instance started here, and half the tasks kept in flight.
        address: Ray cluster to connect to (``"auto"``, ``"ray://host:10001"``...); ``None`` starts
            a local instance with ``num_cpus=workers``.  Ignored when Ray is already initialised.

    Raises:
        EngineUnavailableError: Ray is not installed.
        KeyboardInterrupt: re-raised after cancelling the tasks in flight.
    """
    ray = import_ray()
    started = False
    if not ray.is_initialized():
        kwargs: dict[str, Any] = {
            "address": address,
            "include_dashboard": False,
            "log_to_driver": False,
            "logging_level": logging.WARNING,
        }
        if address is None:
            kwargs["num_cpus"] = max(1, workers)
        ray.init(**kwargs)
        started = True
    remote = ray.remote(num_cpus=1, max_retries=2)(run_job)
    window = 2 * max(1, workers)
    queue = iter(todo)
    pending: dict[Any, Job] = {}
    try:
        while True:
            while len(pending) < window:
                job = next(queue, None)
                if job is None:
                    break
                pending[remote.remote(job)] = job
            if not pending:
                break
            ready, _ = ray.wait(list(pending), num_returns=1)
            for ref in ready:
                job = pending.pop(ref)
                try:
                    out = ray.get(ref)
                except ray.exceptions.RayError as exc:
                    out = _crash_outcome(job, exc)
                handle(out)
    except BaseException:
        for ref in pending:
            ray.cancel(ref, force=True)
        raise
    finally:
        if started:
            ray.shutdown()
