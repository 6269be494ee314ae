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

Every task returns its worker's code fingerprint (:func:`worker_fingerprint`, the
:func:`~uvnav.bench.fingerprint.code_fingerprint` of the uvnav that worker imported), and
before the first task one small task pinned to each node asks it (:func:`check_node_code`): a
worker running other code than the driver stops the campaign (:class:`CodeMismatchError`) and
its outcomes are never stored.  A task whose worker or node dies is run again by Ray
(:data:`MAX_RETRIES`), elsewhere if its node is gone; its outcomes exist only once it returned,
so a dead node leaves nothing half-stored.  Ray's driver prints such notices on stdout; they
go to this module's log instead (:func:`_ray_notices_logged`), so that stdout carries only the
command's output and stderr its errors.

Like the local pool, at most ``2 × workers`` tasks are in flight: large campaigns do not flood the
object store, and a killed driver loses at most those tasks' episodes (about half a second of each
worker's work).  Ray is started here only when it is not running yet (``ray.init(address=...,
num_cpus=workers)``; with no address a local instance) and is shut down again at the end; a caller
that already called ``ray.init`` keeps its instance (tests start Ray once per module this way;
``uvnav bench --address`` connects first, :func:`cluster_session`, so that a cluster that
cannot be used is refused before the results database is created).

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

import functools
import io
import ipaddress
import logging
import os
import socket
import sys
import threading
import warnings
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from contextlib import ExitStack, contextmanager, redirect_stdout
from pathlib import Path
from types import FrameType, ModuleType
from typing import Any, TextIO

from uvnav.bench.jobs import TASK_SECONDS, Job, JobOutcome, TaskSizer, sized_batches
from uvnav.bench.store import STATUS_ERROR
from uvnav.validation import clip, one_line


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
    one (see the module docstring).  Always a new instance: ``ray.init()`` alone would connect
    to a cluster that ``ray start`` recorded on this machine (another user's, say).

    Raises:
        EngineUnavailableError: Ray started on another address (it is shut down again).
    """
    with _loopback_node_ip(ray):
        ray.init(
            address="local",  # a new instance, even where `ray start` recorded a cluster here
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


#: seconds to wait for a cluster's address to accept a TCP connection
CONNECT_TIMEOUT = 5.0
#: Ray's default token file (``ray get-auth-token`` prints its token)
TOKEN_FILE = Path.home() / ".ray" / "auth_token"


class ClusterConnectionError(RuntimeError):
    """A Ray cluster given by address cannot be used: bad address, unreachable, or it refuses
    this driver's authentication token.  The message is one line naming the address and a fix."""


def parse_address(address: str) -> tuple[str, str, int]:
    """``(scheme, host, port)`` of ``HOST:PORT`` (scheme ``""``) or ``ray://HOST:PORT``
    (scheme ``"ray://"``, Ray Client); IPv6 hosts in brackets.

    Raises:
        ClusterConnectionError: not of that form.
    """
    scheme = "ray://" if address.startswith("ray://") else ""
    host, sep, port = address[len(scheme) :].rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise ClusterConnectionError(
            f"Ray address {address!r}: expected auto, HOST:PORT or ray://HOST:PORT"
        )
    return scheme, host.strip("[]"), int(port)


def resolve_address(ray: ModuleType, address: str) -> str:
    """``address`` with ``auto`` replaced by the address of the cluster running on this machine.

    Raises:
        ClusterConnectionError: ``auto`` and no cluster runs here.
    """
    if address != "auto":
        return address
    try:
        found = ray._private.services.canonicalize_bootstrap_address(address)
    except Exception:  # Ray raises ConnectionError; any failure means "none found"
        found = None
    if not found:
        raise ClusterConnectionError(
            "Ray address auto: no Ray cluster runs on this machine (start one with "
            "`ray start --head`, or pass the head's HOST:PORT)"
        )
    return str(found)


def _token_given() -> bool:
    """Whether the user named a token for this process (Ray's ``RAY_AUTH_TOKEN`` or
    ``RAY_AUTH_TOKEN_PATH``)."""
    return bool(os.environ.get("RAY_AUTH_TOKEN") or os.environ.get("RAY_AUTH_TOKEN_PATH"))


@contextmanager
def _token_auth(ray: ModuleType, local: bool) -> Iterator[None]:
    """Token authentication for the connection, as Ray decides it for ``ray.init("auto")``.

    ``RAY_AUTH_MODE`` set by the user is kept as it is.  Unset, token mode is turned on (for
    this process, until the context ends) when the user named a token (``RAY_AUTH_TOKEN``,
    ``RAY_AUTH_TOKEN_PATH``) or, for a cluster on this machine, when Ray's token file exists:
    ``ray start`` enables token authentication whenever that file exists, and Ray's own
    ``ray.init`` sends it only for an address it found itself, never for an explicit one.  A
    remote cluster's token is sent only when the user asks for it.
    """
    turn_on = "RAY_AUTH_MODE" not in os.environ and (
        _token_given() or (local and TOKEN_FILE.is_file())
    )
    if turn_on:
        os.environ["RAY_AUTH_MODE"] = "token"
    _reload_auth(ray)
    try:
        yield
    finally:
        if turn_on:
            os.environ.pop("RAY_AUTH_MODE", None)
        _reload_auth(ray)


def _reload_auth(ray: ModuleType) -> None:
    """Make Ray read the authentication mode and token again: it caches both per process (its
    configuration, its token loader), so a second connection of a process (another cluster,
    another token) would otherwise send the first one's."""
    raylet = getattr(ray, "_raylet", None)
    config = getattr(raylet, "Config", None)
    if config is not None:
        config.initialize("")
    loader = getattr(raylet, "AuthenticationTokenLoader", None)
    if loader is not None:
        loader.instance().reset_cache()


@contextmanager
def _quiet_stderr() -> Iterator[None]:
    """Silence file descriptor 2 (Ray's C++ logging writes there directly) for the duration."""
    saved = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(devnull)


def _auth_hint(local: bool) -> str:
    """How to give this driver the cluster's token."""
    where = "" if local else " on this machine"
    mode = "" if os.environ.get("RAY_AUTH_MODE") == "token" else "set RAY_AUTH_MODE=token and "
    return (
        f"{mode}give the cluster's token"
        f"{where} in RAY_AUTH_TOKEN, RAY_AUTH_TOKEN_PATH or ~/.ray/auth_token "
        "(`ray get-auth-token` on the head prints it)"
    )


def probe_cluster(ray: ModuleType, address: str) -> None:
    """Check, within :data:`CONNECT_TIMEOUT` seconds, that the Ray cluster at ``address``
    (``HOST:PORT`` or ``ray://HOST:PORT``, already resolved) accepts a connection and, for a
    GCS address, this process's token; a ``ray://`` address needs Ray Client installed here
    (extra ``ray[client]``, which ``uvnav[bench]`` does not install).  Call it inside
    :func:`_token_auth`.

    Raises:
        ClusterConnectionError: bad address, no Ray Client for a ``ray://`` one, unreachable,
            or the token is missing or refused.
    """
    scheme, host, port = parse_address(address)
    if scheme and _client_missing(ray) is not None:
        raise ClusterConnectionError(
            f"{address} is a Ray Client address, and Ray Client is not installed here "
            f"({clip(one_line(str(_client_missing(ray))), 60)}): pass the head's GCS address "
            f"HOST:PORT instead (`ray start --head --port PORT`, default 6379), or "
            "pip install 'ray[client]' here and on the head"
        )
    try:
        socket.create_connection((host, port), timeout=CONNECT_TIMEOUT).close()
    except OSError as exc:
        start = "ray start --head" + (" --ray-client-server-port" if scheme else " --port")
        raise ClusterConnectionError(
            f"cannot reach the Ray cluster at {address}: {one_line(str(exc) or type(exc).__name__)}"
            f" (is `{start} {port}` running there, and is the port open to this machine?)"
        ) from None
    if scheme:
        return  # Ray Client: its server checks the token when ray.init connects
    auth_error = getattr(getattr(ray, "exceptions", None), "AuthenticationError", ())
    try:
        with _quiet_stderr():
            ray._raylet.GcsClient(address=f"{host}:{port}")
    except auth_error:
        raise ClusterConnectionError(
            f"the Ray cluster at {address} refused this driver's authentication token: "
            + _auth_hint(is_loopback(host) or _is_own_address(host))
        ) from None
    except Exception as exc:  # Ray's RPC errors: whatever answers there is no GCS
        raise ClusterConnectionError(
            f"{address} does not answer as a Ray cluster's head "
            f"({clip(one_line(str(exc)), 120)}): pass the head's GCS address, HOST:PORT of "
            "`ray start --head --port PORT` (default 6379), or ray://HOST:10001"
        ) from None


def _client_missing(ray: ModuleType) -> ImportError | None:
    """Why Ray Client (``ray://`` addresses, extra ``ray[client]``) cannot run here, or
    ``None`` when it can."""
    utils = getattr(getattr(ray, "_private", None), "utils", None)
    check = getattr(utils, "get_ray_client_dependency_error", None)
    if check is None:  # another Ray layout: ray.init says
        return None
    error = check()
    return error if isinstance(error, ImportError) else None


def _local_target(ray: ModuleType, address: str) -> tuple[str, bool]:
    """``address`` resolved (:func:`resolve_address`), and whether its cluster is on this
    machine (``auto``, or a host that is one of this machine's addresses)."""
    target = resolve_address(ray, address)
    _, host, _ = parse_address(target)
    return target, address == "auto" or is_loopback(host) or _is_own_address(host)


def _is_own_address(host: str) -> bool:
    """Whether ``host`` (an IP address) is one of this machine's: a socket can bind to it."""
    try:
        family = socket.AF_INET6 if ":" in host else socket.AF_INET
        with socket.socket(family, socket.SOCK_STREAM) as sock:
            sock.bind((host, 0))
    except OSError:
        return False
    return True


@contextmanager
def cluster_connection(ray: ModuleType, address: str) -> Iterator[None]:
    """Connected (``ray.init``) to the existing cluster at ``address`` (``auto``,
    ``HOST:PORT``, ``ray://HOST:PORT``) for the duration, with token authentication as
    :func:`_token_auth` decides; checked first by :func:`probe_cluster` so that a cluster that
    cannot be used fails in seconds with one line (through Ray Client, ``ray://``, a refused
    token is only seen as Ray Client's connection timeout, after about half a minute).  Shut
    down (``ray.shutdown``) at the end.

    Raises:
        ClusterConnectionError: the cluster cannot be reached or refuses the token.
    """
    target, local = _local_target(ray, address)
    with _token_auth(ray, local):
        probe_cluster(ray, target)
        try:
            with warnings.catch_warnings():  # Ray Client warns what the error below says
                warnings.simplefilter("ignore")
                ray.init(
                    address=target,
                    include_dashboard=False,
                    log_to_driver=False,
                    logging_level=logging.WARNING,
                )
        except (ConnectionError, RuntimeError, ray.exceptions.RayError) as exc:
            hint = (
                f" (its token too may be refused: {_auth_hint(local)})"
                if target.startswith("ray://")
                else ""
            )
            raise ClusterConnectionError(
                f"cannot connect to the Ray cluster at {target}: "
                f"{clip(one_line(str(exc)), 200)}{hint}"
            ) from None
        try:
            yield
        finally:
            ray.shutdown()


class CodeMismatchError(ClusterConnectionError):
    """A Ray worker runs other uvnav code than the driver (its code fingerprint differs); its
    outcomes are not stored.  The message is one line naming the node and what to do."""


#: seconds the start-up check waits for each node's code fingerprint; a node that has not
#: answered by then (busy starting workers, or dead) is checked by its tasks' fingerprints
PROBE_SECONDS = 20.0
#: Ray's retries of a task whose worker or node died (after them the task is split)
MAX_RETRIES = 3


@functools.cache
def worker_fingerprint() -> str:
    """The code fingerprint (:func:`uvnav.bench.fingerprint.code_fingerprint`) of the uvnav
    this process imported, computed once per process."""
    from uvnav.bench.fingerprint import code_fingerprint

    return code_fingerprint()


def _this_node() -> str:
    """This Ray worker's node: its address and the start of its id."""
    import ray

    return f"node {ray.util.get_node_ip_address()} ({ray.get_runtime_context().get_node_id()[:8]})"


def fingerprinted(
    run_batch: Callable[[Batch], list[list[JobOutcome]]], batch: Batch, expected: str
) -> tuple[str, str, list[list[JobOutcome]]]:
    """The Ray task: ``(fingerprint, node, outcomes)``.  ``run_batch(batch)`` runs only when
    this worker's code fingerprint is the driver's ``expected``; otherwise the outcomes are
    empty and ``node`` says where the worker runs."""
    theirs = worker_fingerprint()
    if theirs != expected:
        return theirs, _this_node(), []
    return theirs, "", run_batch(batch)


def _mismatch(where: str, theirs: str, ours: str) -> CodeMismatchError:
    return CodeMismatchError(
        f"the Ray workers on {where} run other uvnav code than this driver (code fingerprint "
        f"{theirs}, here {ours}): install the same uvnav on every node (or start every node "
        "from the same checkout with its src/ on PYTHONPATH); their episodes were not stored"
    )


def check_node_code(ray: ModuleType, expected: str, timeout: float = PROBE_SECONDS) -> None:
    """Check, before any task runs, that the workers of every alive node with CPUs compute
    the driver's code fingerprint ``expected``: one small task pinned to each node.  A node
    that does not answer within ``timeout`` seconds, or whose probe fails (it died), is left
    to the per-task check of :func:`run_ray`.

    Raises:
        CodeMismatchError: a node's workers run other code.
    """
    from ray.util.scheduling_strategies import NodeAffinitySchedulingStrategy

    probe = ray.remote(num_cpus=0, max_retries=0)(_probe)
    refs = []
    for node in ray.nodes():
        if node.get("Alive") and node.get("Resources", {}).get("CPU", 0) > 0:
            strategy = NodeAffinitySchedulingStrategy(node["NodeID"], soft=False)
            refs.append(probe.options(scheduling_strategy=strategy).remote())
    ready, _ = ray.wait(refs, num_returns=len(refs), timeout=timeout)
    for ref in ready:
        try:
            theirs, where = ray.get(ref)
        except ray.exceptions.RayError:
            continue  # the node died meanwhile: its tasks go elsewhere
        if theirs != expected:
            raise _mismatch(where, theirs, expected)


def _probe() -> tuple[str, str]:
    """This worker's code fingerprint and node (:func:`check_node_code`'s task)."""
    return worker_fingerprint(), _this_node()


#: the thread of Ray's driver that prints cluster notices (``ray._private.worker``)
RAY_NOTICE_THREAD = "ray_listen_error_messages"
#: the function of Ray's driver that prints its notices and the workers' log lines
RAY_PRINTER = "print_worker_logs"
log = logging.getLogger(__name__)


def _from_ray_printer() -> bool:
    """Whether :meth:`_NoticeFilter.write` was called from Ray's :data:`RAY_PRINTER` (through
    at most three frames: it prints with a ``print`` of Ray's own), as the notices are that
    Ray held back as repeats and prints from the main thread when it disconnects."""
    frame: FrameType | None = sys._getframe(2)
    for _ in range(4):
        if frame is None:
            return False
        code = frame.f_code
        if code.co_name == RAY_PRINTER and "ray" in code.co_filename:
            return True
        frame = frame.f_back
    return False


class _NoticeFilter(io.TextIOBase):
    """``sys.stdout`` less what Ray's notice thread writes and what Ray's log printer writes
    from any thread, which go to this module's log.  (The workers' own output never reaches
    the printer here: every ``ray.init`` of this module passes ``log_to_driver=False``.)"""

    def __init__(self, target: TextIO) -> None:
        self._target = target

    def write(self, text: str) -> int:
        if threading.current_thread().name == RAY_NOTICE_THREAD or _from_ray_printer():
            if text.strip():
                log.info("ray: %s", text.strip())
            return len(text)
        return self._target.write(text)

    def flush(self) -> None:
        self._target.flush()


@contextmanager
def _ray_notices_logged() -> Iterator[None]:
    """Ray's driver prints cluster notices on stdout from a thread of its own: a task retried
    because its node died, a node marked dead (even one of an earlier session); the repeats it
    held back it prints from the main thread as it disconnects.  For the duration they go to
    this module's log instead, so that stdout carries only the command's
    output (``--json``) and stderr its one-line errors; everything else printed is unchanged."""
    with redirect_stdout(_NoticeFilter(sys.stdout)):
        yield


@contextmanager
def cluster_session(address: str) -> Iterator[None]:
    """Connected to the Ray cluster at ``address`` (:func:`cluster_connection`), every node's
    code checked (:func:`check_node_code`), for the duration; :func:`run_ray` uses this
    connection.  The CLI holds it across a campaign, so that a cluster that cannot be used
    stops the run in one line before the database is created.  Ray's notices go to the log
    meanwhile (:func:`_ray_notices_logged`).

    Raises:
        EngineUnavailableError: Ray is not installed.
        ClusterConnectionError: the cluster cannot be reached, refuses the token, or a node
            runs other uvnav code (:class:`CodeMismatchError`).
    """
    ray = import_ray()
    with _ray_notices_logged(), cluster_connection(ray, address):
        check_node_code(ray, worker_fingerprint())
        yield


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
    come back), in a worker whose code fingerprint is the driver's (:func:`check_node_code`
    first, then each task's).  A task whose worker or node dies is retried by Ray
    (:data:`MAX_RETRIES` times); one that Ray cannot complete even so is run again split (its
    groups one per task, a lone group's jobs one per task), so only the job that kills its
    worker is stored as an error.

    Args:
        groups: the jobs, grouped by scene.
        handle: called with each group's outcomes, in completion order (it stores them).
        run_batch: a module-level (picklable) function running a batch of groups in a worker
            and returning each group's outcomes (:func:`uvnav.bench.campaign.run_group_batch`).
        workers: CPUs of the local Ray instance started here, and half the tasks kept in flight.
        address: Ray cluster to connect to (``"auto"``, ``"host:port"``, ``"ray://host:10001"``;
            default ``$RAY_ADDRESS``; :func:`cluster_connection`); none starts
            a local instance with ``num_cpus=workers`` that listens on 127.0.0.1 only
            (:func:`start_local_ray`).  Ignored when Ray is already initialised (by the
            caller, or by :func:`cluster_session`).
        task_seconds: the worker time a task is sized to.

    Raises:
        EngineUnavailableError: Ray is not installed, or a local instance would not be
            loopback-only.
        ClusterConnectionError: ``address`` names a cluster that cannot be used
            (:func:`cluster_connection`), or a worker runs other uvnav code than this process
            (:class:`CodeMismatchError`; the outcomes of its tasks are not handed on).
        KeyboardInterrupt: re-raised after cancelling the tasks in flight.
    """
    ray = import_ray()
    address = address or os.environ.get("RAY_ADDRESS") or None  # Ray's own variable: the user's
    with ExitStack() as stack:
        stack.enter_context(_ray_notices_logged())
        if not ray.is_initialized():
            if address is None:
                start_local_ray(ray, workers)
                stack.callback(ray.shutdown)
            else:
                stack.enter_context(cluster_connection(ray, address))
        expected = worker_fingerprint()
        check_node_code(ray, expected)
        _run_tasks(ray, groups, handle, run_batch, workers, task_seconds, expected)


def _run_tasks(
    ray: ModuleType,
    groups: Sequence[Sequence[Job]],
    handle: Callable[[list[JobOutcome]], None],
    run_batch: Callable[[Batch], list[list[JobOutcome]]],
    workers: int,
    task_seconds: float,
    expected: str,
) -> None:
    """The task loop of :func:`run_ray`, on an initialised Ray; a task whose worker's code
    fingerprint is not ``expected`` stops it (:class:`CodeMismatchError`) unstored."""
    remote = ray.remote(num_cpus=1, max_retries=MAX_RETRIES)(fingerprinted)
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
                pending[remote.remote(run_batch, batch, expected)] = batch
            if not pending:
                break
            ready, _ = ray.wait(list(pending), num_returns=1)
            for ref in ready:
                batch = pending.pop(ref)
                try:
                    theirs, where, outcomes = ray.get(ref)
                except ray.exceptions.RayError as exc:
                    pieces = _split(batch)
                    if pieces is not None:
                        again.extend(pieces)
                        continue
                    theirs, outcomes = expected, [[_crash_outcome(batch[0][0], exc)]]
                if theirs != expected:
                    raise _mismatch(where, theirs, expected)
                for group in outcomes:
                    sizer.add(group)
                    handle(group)
    except BaseException:
        for ref in pending:
            ray.cancel(ref, force=True)
        raise
