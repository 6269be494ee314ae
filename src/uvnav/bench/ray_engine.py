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
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
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
        address: Ray cluster to connect to (``"auto"``, ``"ray://host:10001"``...; default
            ``$RAY_ADDRESS``); none starts
            a local instance with ``num_cpus=workers`` that listens on 127.0.0.1 only
            (:func:`start_local_ray`).  Ignored when Ray is already initialised.

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
