"""Ray engine: a campaign's jobs as Ray tasks, results streamed back to the driver.

The same tasks as on the local process pool — scene groups of picklable
:class:`~uvnav.bench.jobs.Job` s (:func:`~uvnav.bench.campaign.scene_groups`: the jobs of one
scene and seed go to one worker, which builds the scene once), as many groups to a task as run
about :data:`~uvnav.bench.jobs.TASK_SECONDS` (a quarter of a second,
:class:`~uvnav.bench.jobs.TaskSizer`), since each task costs Ray a fixed overhead — run by the
batch function the campaign passes in (:func:`~uvnav.bench.campaign.run_group_batch`) as Ray
tasks (one CPU each).  Workers only compute;
each group's :class:`~uvnav.bench.jobs.JobOutcome` s come back to the driver, which writes
them to the SQLite store in one transaction (DESIGN §5) — exactly as with the local engine, so
resume, progress and the stored metrics are the same whatever the engine.

Like the local pool, at most ``2 × workers`` tasks are in flight: large campaigns do not flood the
object store, and a killed driver loses at most those tasks' episodes (about half a second of each
worker's work).  Ray is started here only when it is not running yet (``ray.init(address=...,
num_cpus=workers)``; with no address a local instance) and is shut down again at the end; a caller
that already called ``ray.init`` keeps its instance (tests start Ray once per module this way).

What Ray adds to a campaign's CPU is measured by ``benchmarks/bench_ray.py``: on 2,000
episodes of the default generator's scenes and 2 workers, 0.8-1.6 CPU-ms per episode over the
local pool (4-7 % of an episode's 20-21 CPU-ms; one job per task added 5.2), and its start-up
about 3 CPU-s per campaign.

A local instance started here listens on the loopback interface only (:func:`start_local_ray`):
its GCS server, raylet, object manager, workers and agents accept no connection from the network.
Ray itself would bind them to every interface (``*:port``) on Linux; a campaign on a laptop or a
shared machine must not open an unauthenticated remote-execution service to its network.  Running
on a real cluster is the user's choice: start Ray there and pass ``address``.

Ray is an optional dependency (extra ``uvnav[bench]``), imported only when this engine is used.
"""

from __future__ import annotations

import ipaddress
import logging
import os
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from types import ModuleType
from typing import Any

from uvnav.bench.jobs import TASK_SECONDS, Job, JobOutcome, TaskSizer, sized_batches
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


#: the only address a Ray instance started by uvnav listens on
LOOPBACK = "127.0.0.1"


def is_loopback(host: str) -> bool:
    """Whether ``host`` (an IP address, IPv4-mapped IPv6 included, or ``localhost``) is this
    machine's loopback interface."""
    if host == "localhost":
        return True
    try:
        ip = ipaddress.ip_address(host.strip("[]"))
    except ValueError:
        return False
    mapped = getattr(ip, "ipv4_mapped", None)
    return bool((mapped or ip).is_loopback)


@contextmanager
def _loopback_node_ip(ray: ModuleType) -> Iterator[None]:
    """Let ``ray.init(_node_ip_address="127.0.0.1")`` keep the loopback address.

    Ray (2.x, Linux) replaces a loopback node address by the machine's reachable address
    (``ray._private.services.resolve_ip_for_localhost``) unless clusters are disabled, as they are
    on macOS and Windows (``ray_constants.ENABLE_RAY_CLUSTER``); its servers listen on every
    interface unless the node address is the loopback one.  This disables clusters for the
    duration of ``ray.init`` in this process only; :func:`start_local_ray` checks the outcome.
    """
    constants = getattr(getattr(ray, "_private", None), "ray_constants", None)
    if constants is None or not hasattr(constants, "ENABLE_RAY_CLUSTER"):
        yield  # another Ray layout: the check after ray.init decides
        return
    before = constants.ENABLE_RAY_CLUSTER
    constants.ENABLE_RAY_CLUSTER = False
    try:
        yield
    finally:
        constants.ENABLE_RAY_CLUSTER = before


def start_local_ray(ray: ModuleType, workers: int) -> None:
    """Start a local Ray instance of ``workers`` CPUs that listens on 127.0.0.1 only.

    No dashboard; the node address, hence every gRPC server, agent and worker, is the loopback
    one (see the module docstring).

    Raises:
        EngineUnavailableError: Ray started on another address (it is shut down again).
    """
    with _loopback_node_ip(ray):
        ray.init(
            num_cpus=max(1, workers),
            include_dashboard=False,
            dashboard_host=LOOPBACK,
            log_to_driver=False,
            logging_level=logging.WARNING,
            _node_ip_address=LOOPBACK,
        )
    node_ip = str(ray.util.get_node_ip_address())
    if not is_loopback(node_ip):
        ray.shutdown()
        raise EngineUnavailableError(
            f"Ray started on {node_ip}, not on the loopback interface, so it would accept "
            "connections from the network; refused (start Ray yourself and pass --address "
            "to use a cluster)"
        )


def _crash_outcome(job: Job, exc: BaseException) -> JobOutcome:
    """A task that Ray could not complete (its worker died, even after retries) is an error row."""
    first = (str(exc).strip().splitlines() or [""])[0]
    return JobOutcome(job, STATUS_ERROR, None, f"{type(exc).__name__}: {first}", 0.0)


Batch = list[list[Job]]


def _split(batch: Batch) -> list[Batch] | None:
    """A failed task's work, smaller: its groups one per task, a lone group's jobs one per task;
    ``None`` for a lone job (it is the one that fails)."""
    if len(batch) > 1:
        return [[group] for group in batch]
    if len(batch[0]) > 1:
        return [[[job]] for job in batch[0]]
    return None


def run_ray(
    groups: Sequence[Sequence[Job]],
    handle: Callable[[list[JobOutcome]], None],
    *,
    run_batch: Callable[[Batch], list[list[JobOutcome]]],
    workers: int = 1,
    address: str | None = None,
    task_seconds: float = TASK_SECONDS,
) -> None:
    """Run ``groups`` (scene groups, :func:`~uvnav.bench.campaign.scene_groups`) as Ray tasks,
    handing each group's outcomes to ``handle`` (in this process) as its task ends.

    A task runs ``run_batch`` on a batch of groups, as many as
    take about ``task_seconds`` (:class:`~uvnav.bench.jobs.TaskSizer`: one until the first
    come back).  A task that Ray cannot complete (its worker died, even after Ray's retries) is
    run again split (its groups one per task, a lone group's jobs one per task), so only the job
    that kills its worker is stored as an error.

    Args:
        groups: the jobs, grouped by scene.
        handle: called with each group's outcomes, in completion order (it stores them).
        run_batch: a module-level (picklable) function running a batch of groups in a worker
            and returning each group's outcomes (:func:`uvnav.bench.campaign.run_group_batch`).
        workers: CPUs of the local Ray instance started here, and half the tasks kept in flight.
        address: Ray cluster to connect to (``"auto"``, ``"ray://host:10001"``...; default
            ``$RAY_ADDRESS``); none starts
            a local instance with ``num_cpus=workers`` that listens on 127.0.0.1 only
            (:func:`start_local_ray`).  Ignored when Ray is already initialised.
        task_seconds: the worker time a task is sized to.

    Raises:
        EngineUnavailableError: Ray is not installed, or a local instance would not be
            loopback-only.
        KeyboardInterrupt: re-raised after cancelling the tasks in flight.
    """
    ray = import_ray()
    started = False
    address = address or os.environ.get("RAY_ADDRESS") or None  # Ray's own variable: the user's
    if not ray.is_initialized():
        if address is None:
            start_local_ray(ray, workers)
        else:
            ray.init(
                address=address,
                include_dashboard=False,
                log_to_driver=False,
                logging_level=logging.WARNING,
            )
        started = True
    remote = ray.remote(num_cpus=1, max_retries=2)(run_batch)
    window = 2 * max(1, workers)
    sizer = TaskSizer(task_seconds)
    queue = sized_batches(deque(list(g) for g in groups), sizer)
    again: deque[Batch] = deque()  # the pieces of failed tasks, run first
    pending: dict[Any, Batch] = {}
    try:
        while True:
            while len(pending) < window:
                batch = again.popleft() if again else next(queue, None)
                if batch is None:
                    break
                pending[remote.remote(batch)] = batch
            if not pending:
                break
            ready, _ = ray.wait(list(pending), num_returns=1)
            for ref in ready:
                batch = pending.pop(ref)
                try:
                    outcomes = ray.get(ref)
                except ray.exceptions.RayError as exc:
                    pieces = _split(batch)
                    if pieces is not None:
                        again.extend(pieces)
                        continue
                    outcomes = [[_crash_outcome(batch[0][0], exc)]]
                for group in outcomes:
                    sizer.add(group)
                    handle(group)
    except BaseException:
        for ref in pending:
            ray.cancel(ref, force=True)
        raise
    finally:
        if started:
            ray.shutdown()
