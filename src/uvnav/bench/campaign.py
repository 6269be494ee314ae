"""Campaigns: scenarios × controllers × seeds on a local process pool, streamed into the store.

A campaign is a list of :class:`~uvnav.bench.jobs.Job` s — small picklable *descriptions*
(scenario name or file, or generator name, parameters and seed; law name and parameters; tags;
seed; :mod:`uvnav.bench.jobs`, whose names are importable from here too).  Every episode is
built and run inside the worker by the one scene runner
(:func:`uvnav.scenarios.episodes.run_scene`, the path of ``uvnav simulate``), so nothing heavy
or stateful crosses process boundaries and the same job replays bit for bit anywhere (DESIGN
§2, randomness): the stored metrics do not depend on the engine or the number of workers.
Campaign files (YAML) are expanded into jobs by :mod:`uvnav.bench.spec`.

:func:`run_campaign` writes each episode to the :class:`~uvnav.bench.store.ResultsStore` in its own
transaction the moment it arrives, so an interrupted campaign (Ctrl-C, a killed machine) loses only
the episodes in flight; run it again with the same name and it skips every key already stored
(resume) and never duplicates.  A job whose code raises is stored with status ``"error"`` and the
message; it does not stop the campaign.

Workers are a :class:`concurrent.futures.ProcessPoolExecutor` started with the ``forkserver`` method
on POSIX (``spawn`` elsewhere): forking a parent that runs a progress-bar thread and holds an open
SQLite connection is unsafe, and the fork server preloads uvnav and runs one short episode
(:func:`warm_up`: lazy imports, compiled kernels loaded) once, so workers start warm.  At
most ``2 × workers`` tasks are submitted ahead, which bounds memory for large campaigns.  With
``workers=1`` everything runs in-process (no pool; easiest to debug and profile).  ``engine="ray"``
runs the same jobs as Ray tasks instead (:mod:`uvnav.bench.ray_engine`); results still come back to
this process, which alone writes the store.  On the local pool and on Ray the jobs of one scene
(the laws and parameter sets run on one generated scene) travel together (:func:`scene_groups`):
one worker builds the scene once for all of them, and their episodes are stored in one transaction
when the group finishes, so an interrupt loses at most the groups in flight.  A task carries as
many groups as run about :data:`~uvnav.bench.jobs.TASK_SECONDS`
(:class:`~uvnav.bench.jobs.TaskSizer`: a task's cost to the engine is fixed), so at most
``2 × workers`` tasks in flight are about half a second of each worker's work.
As with any ``spawn``/``forkserver`` pool, a *script* that starts a campaign with ``workers > 1``
must do so under ``if __name__ == "__main__":`` (console scripts such as ``uvnav`` already do);
pass ``mp_context=multiprocessing.get_context("fork")`` to lift that restriction at fork's usual
risks.
"""

from __future__ import annotations

import dataclasses
import functools
import multiprocessing as mp
import os
import signal
import sys
import threading
import time
import traceback
from collections import deque
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from contextlib import contextmanager, suppress
from dataclasses import dataclass, field
from typing import Any, TypeVar

from uvnav.bench.jobs import Job, JobOutcome, TaskSizer, sized_batches
from uvnav.bench.ray_engine import import_ray, run_ray
from uvnav.bench.store import STATUS_ERROR, STATUS_REFUSED, EpisodeKey, ResultsStore
from uvnav.scenarios.generators import DEFAULT_GENERATOR
from uvnav.sim import Trajectory

ENGINES = ("local", "ray")
T = TypeVar("T")
R = TypeVar("R")


@functools.lru_cache(maxsize=256)
def _generated(name: str, seed: int, params: tuple[tuple[str, Any], ...]) -> Any:
    """A generated scene (any kind), kept for the next jobs on the same scene (other controllers
    or parameter sets): generators are pure functions of their seed and parameters, and building
    an episode never modifies the scenario it instantiates."""
    from uvnav.scenarios.catalog import generate

    return generate(name, seed, dict(params))


@functools.lru_cache(maxsize=64)
def _resolved(spec: str) -> Any:
    from uvnav.scenarios.catalog import resolve

    return resolve(spec)


def job_scene(job: Job) -> Any:
    """The job's scene (a :class:`uvnav.scenarios.catalog.Resolved`; runs in the worker)."""
    if job.scenario is not None and job.scene_params:
        from uvnav.scenarios.catalog import with_fields

        return with_fields(_resolved(job.scenario), dict(job.scene_params))
    if job.scenario is not None:
        return _resolved(job.scenario)
    key = (job.generator, int(job.generator_seed or 0), job.generator_params)
    try:
        hash(key)
    except TypeError:  # list or mapping parameters (crowd-file's start: [x, y]): not cached
        scene = _generated.__wrapped__(*key)
    else:
        scene = _generated(*key)
    if scene.seed != job.seed:  # a scene drawn with one seed, run with another
        scene = dataclasses.replace(scene, seed=None)
    return scene


def _scene_key(job: Job) -> tuple[Any, ...]:
    """What identifies a job's episode set-up but for the law: the scene and the episode seed."""
    if job.scenario is not None:
        return ("scenario", job.scenario, job.scene_params, int(job.seed))
    return ("generator", job.generator_label, int(job.generator_seed or 0), int(job.seed))


def scene_groups(jobs: Sequence[Job]) -> list[list[Job]]:
    """``jobs`` grouped by scene, groups in the order of their first job, jobs in their order."""
    groups: dict[tuple[Any, ...], list[Job]] = {}
    for job in jobs:
        groups.setdefault(_scene_key(job), []).append(job)
    return list(groups.values())


def run_group_batch(groups: Sequence[Sequence[Job]]) -> list[list[JobOutcome]]:
    """:func:`run_job` on each job of each scene group of ``groups`` in turn, in one worker (one
    task; a group's scene is built once)."""
    return [[run_job(job) for job in group] for group in groups]


def _error(job: Job, exc: BaseException, tic: float, params: dict[str, Any]) -> JobOutcome:
    tb = traceback.extract_tb(exc.__traceback__)
    where = f" (at {tb[-1].filename}:{tb[-1].lineno})" if tb else ""
    return JobOutcome(
        job, STATUS_ERROR, None, f"{type(exc).__name__}: {exc}{where}",
        time.perf_counter() - tic, None, params,
    )  # fmt: skip


def run_job(job: Job) -> JobOutcome:
    """Build and run one job; any exception becomes an ``error`` outcome (never raises it), a
    scene that breaks an assumption the law declares a ``refused`` one, and so does a generated
    scene whose bodies cannot all be placed (:class:`~uvnav.scenarios.errors.PlacementError`,
    its one line as the reason).

    Every job runs through :func:`uvnav.scenarios.episodes.run_scene`, the path of ``uvnav
    simulate``; its facts join the law's parameters in ``effective_params``.  The outcome's
    ``cpu_time`` is this thread's.
    """
    cpu = time.thread_time()
    out = _run_job(job)
    out.cpu_time = time.thread_time() - cpu
    return out


def _run_job(job: Job) -> JobOutcome:
    """:func:`run_job` but for its CPU time."""
    from uvnav.scenarios.episodes import AssumptionError, LawMismatchError, run_scene
    from uvnav.scenarios.errors import PlacementError

    tic = time.perf_counter()
    params: dict[str, Any] = job.params_dict
    probes = []
    try:
        probes = list(job.probe_factory(job)) if job.probe_factory is not None else []
        out = run_scene(
            job_scene(job), job.controller, params, int(job.seed), record=job.record,
            use_scene_params=job.use_scenario_params, beyond_assumptions=job.beyond_assumptions,
            probes=probes,
        )  # fmt: skip
    except (AssumptionError, LawMismatchError) as exc:  # the law is refused here
        return JobOutcome(
            job, STATUS_REFUSED, None, exc.problem, time.perf_counter() - tic, None, params
        )
    except PlacementError as exc:  # the scene cannot be built: refused, with the generator's line
        return JobOutcome(
            job, STATUS_REFUSED, None, str(exc), time.perf_counter() - tic, None, params
        )
    except Exception as exc:  # a failing job is data, not a crash of the campaign
        return _error(job, exc, tic, params)
    finally:
        for probe in probes:
            getattr(probe, "close", lambda: None)()
    # a tag named as a parameter stands for it in the store (a checkpoint's digest for its path)
    named = {k: v for k, v in dict(job.tags).items() if k in out.params}
    traj = out.trajectory
    return JobOutcome(
        job=job,
        status=out.status,
        metrics=out.metrics,
        error=None,
        wall_time=time.perf_counter() - tic,
        trajectory=traj if isinstance(traj, Trajectory) and job.record else None,
        effective_params={**out.params, **named, **out.facts},
        result=out.result if job.record else None,
    )


@dataclass
class CampaignRun:
    """Summary of one :func:`run_campaign` call.

    Attributes:
        campaign_id: id in the store.
        total: distinct jobs asked for.
        skipped: jobs already stored (resume).
        ran: jobs run and stored by this call.
        errors: of those, how many ended with status ``error``.
        statuses: status → count over the jobs run by this call.
        episode_ids: resume key → episode id, for the jobs run by this call.
        wall_time: elapsed time of the call [s].
    """

    campaign_id: int
    total: int
    skipped: int
    ran: int = 0
    errors: int = 0
    statuses: dict[str, int] = field(default_factory=dict)
    episode_ids: dict[EpisodeKey, int] = field(default_factory=dict)
    wall_time: float = 0.0


def store_outcome(store: ResultsStore, campaign_id: int, out: JobOutcome) -> int:
    job = out.job
    return store.add_episode(
        campaign_id,
        scenario=job.scenario_label,
        family=job.family_label,
        controller=job.controller,
        params=job.store_params,
        effective_params=out.effective_params,
        seed=job.seed,
        status=out.status,
        metrics=out.metrics,
        error=out.error,
        wall_time=out.wall_time,
        trajectory=out.trajectory,
    )


def _value(v: Any) -> Any:
    """A stored value as plain Python (missing -> None, numpy scalars -> Python)."""
    import numpy as np
    import pandas as pd

    if v is None or (not isinstance(v, str) and pd.isna(v)):
        return None
    return v.item() if isinstance(v, np.generic) else v


def outcome_record(out: JobOutcome) -> dict[str, Any]:
    """An outcome as :func:`stored_records` reads it back once stored (``params_hash`` left out).

    Raises:
        RuntimeError: the job failed (its error message).
    """
    if out.error is not None:
        raise RuntimeError(f"{out.job.scenario_label} {out.job.controller}: {out.error}")
    job = out.job
    return {
        "scenario": job.scenario_label,
        "controller": job.controller,
        "seed": int(job.seed),
        "status": out.status,
        "params": job.store_params,
        "effective_params": out.effective_params,
        "wall_time": out.wall_time,
        **(out.metrics or {}),
    }


def stored_records(store: ResultsStore, campaign: str) -> list[dict[str, Any]]:
    """A campaign's episodes as plain dicts, in store order: ``scenario``, ``controller``,
    ``seed``, ``status``, ``params`` and ``effective_params`` (dicts), ``params_hash``,
    ``wall_time`` [s] and every
    metric of :data:`~uvnav.sim.metrics.METRIC_NAMES` (``None`` where missing); ``[]`` for a
    campaign not in the store."""
    import json

    from uvnav.sim.metrics import METRIC_NAMES

    if store.campaign_id(campaign) is None:
        return []
    return [
        {
            "scenario": rec["scenario"],
            "controller": rec["controller"],
            "seed": int(rec["seed"]),
            "status": rec["status"],
            "params": json.loads(rec["params"]),
            "params_hash": rec["params_hash"],
            "effective_params": json.loads(rec["effective_params"] or "{}"),
            "wall_time": _value(rec["wall_time"]),
            **{m: _value(rec[m]) for m in METRIC_NAMES},
        }
        for rec in store.episodes_frame(campaign).to_dict("records")
    ]


#: what the fork server imports before it forks a worker (the last one runs :func:`warm_up`)
FORKSERVER_PRELOAD = (
    "uvnav.bench.campaign",
    "uvnav.scenarios",
    "uvnav.controllers",
    "uvnav.bench.forkserver_warm",
)


def default_mp_context() -> mp.context.BaseContext:
    """``forkserver`` (uvnav preloaded and warmed up, :data:`FORKSERVER_PRELOAD`) on POSIX,
    ``spawn`` elsewhere; see the module docstring."""
    if sys.platform != "win32" and "forkserver" in mp.get_all_start_methods():
        ctx = mp.get_context("forkserver")
        ctx.set_forkserver_preload(list(FORKSERVER_PRELOAD))
        return ctx
    return mp.get_context("spawn")


def warm_up() -> None:
    """Run one short episode (``straight-v1`` on the default generator's scene 0) and drop it:
    the lazy imports and the compiled kernels' loading that a process's first episode pays are
    paid here, once (the fork server does, :mod:`uvnav.bench.forkserver_warm`; the workers it forks
    inherit them).  Never raises: a failure only leaves the workers to warm up themselves."""
    with suppress(Exception):  # warming up is an optimisation, never a failure
        run_job(Job(controller="straight-v1", seed=0, generator_seed=0))


def run_campaign(
    store: ResultsStore,
    name: str,
    jobs: Sequence[Job],
    *,
    config: Mapping[str, Any] | None = None,
    workers: int = 1,
    progress: bool = False,
    retry_errors: bool = False,
    mp_context: mp.context.BaseContext | None = None,
    on_outcome: Callable[[JobOutcome, int], None] | None = None,
    engine: str = "local",
    address: str | None = None,
    probe_factory: Callable[[Job], Sequence[Any]] | None = None,
) -> CampaignRun:
    """Run ``jobs`` under campaign ``name``, storing each episode as it finishes; resume-safe.

    Args:
        store: the results store (written only from this process).
        name: campaign name; an existing campaign of that name is resumed.
        jobs: job descriptions; duplicates (same resume key) run once.
        config: JSON-able description stored with a new campaign.
        workers: worker processes (``engine="local"``; ``1`` runs in-process) or Ray CPUs
            (``engine="ray"``).
        progress: show a rich progress bar on stderr.
        retry_errors: run again the jobs stored with status ``error`` (replacing those rows).
        mp_context: multiprocessing context for the pool (default :func:`default_mp_context`).
        on_outcome: called in this process with each outcome and its episode id, after storing.
        engine: ``"local"`` (process pool) or ``"ray"`` (Ray tasks, see
            :func:`uvnav.bench.ray_engine.run_ray`); the stored metrics are the same.
        address: Ray cluster address (``engine="ray"`` only; default: a local Ray instance).
        probe_factory: set as each job's :attr:`~uvnav.bench.jobs.Job.probe_factory` (probes
            that watch the episodes this call runs; they only observe).

    Returns:
        What was skipped, run and stored.

    Raises:
        KeyboardInterrupt: re-raised after cancelling queued jobs; stored episodes stay stored.
            SIGTERM raises :class:`Terminated`, a :class:`KeyboardInterrupt`, the same way.
        uvnav.bench.store.StoreInUseError: another process runs a campaign into this database
            (:meth:`ResultsStore.writer_lease`); nothing was run.
        concurrent.futures.process.BrokenProcessPool: a worker died (not a Python exception).
        ValueError: unknown ``engine``.
        uvnav.bench.ray_engine.EngineUnavailableError: ``engine="ray"`` without Ray installed.
    """
    if engine not in ENGINES:
        raise ValueError(f"unknown engine {engine!r}; known: {', '.join(ENGINES)}")
    if engine == "ray":
        import_ray()  # fail before touching the store when Ray is missing
    if probe_factory is not None:
        jobs = [dataclasses.replace(job, probe_factory=probe_factory) for job in jobs]
    # one campaign writer per database (a second refuses at once); SIGTERM is handled as Ctrl-C
    with store.writer_lease(), sigterm_as_interrupt():
        return _run_campaign(
            store,
            name,
            jobs,
            config=config,
            workers=workers,
            progress=progress,
            retry_errors=retry_errors,
            mp_context=mp_context,
            on_outcome=on_outcome,
            engine=engine,
            address=address,
        )


def _run_campaign(
    store: ResultsStore,
    name: str,
    jobs: Sequence[Job],
    *,
    config: Mapping[str, Any] | None,
    workers: int,
    progress: bool,
    retry_errors: bool,
    mp_context: mp.context.BaseContext | None,
    on_outcome: Callable[[JobOutcome, int], None] | None,
    engine: str,
    address: str | None,
) -> CampaignRun:
    """:func:`run_campaign` once the writer lease is held."""
    tic = time.perf_counter()
    cfg = dict(config) if config is not None else {"n_jobs": len(jobs)}
    campaign_id = store.campaign(name, cfg)
    done = store.done_keys(campaign_id, include_errors=not retry_errors)
    todo: list[Job] = []
    seen: set[EpisodeKey] = set()
    for job in jobs:
        k = job.key
        if k in seen:
            continue
        seen.add(k)
        if k not in done:
            todo.append(job)
    run = CampaignRun(campaign_id=campaign_id, total=len(seen), skipped=len(seen) - len(todo))

    bar = _ProgressBar(name, len(todo), run.skipped) if progress and todo else None

    def handle(out: JobOutcome) -> None:
        episode_id = store_outcome(store, campaign_id, out)
        run.ran += 1
        run.errors += out.status == STATUS_ERROR
        run.statuses[out.status] = run.statuses.get(out.status, 0) + 1
        run.episode_ids[out.job.key] = episode_id
        if bar is not None:
            bar.advance(run.statuses)
        if on_outcome is not None:
            on_outcome(out, episode_id)

    def handle_group(outs: list[JobOutcome]) -> None:
        with store.batch():  # the group's episodes in one transaction
            for out in outs:
                handle(out)

    try:
        if bar is not None:
            bar.start()
        if engine == "ray":
            if todo:
                run_ray(
                    scene_groups(todo),
                    handle_group,
                    run_batch=run_group_batch,
                    workers=workers,
                    address=address,
                )
        elif workers <= 1:
            for job in todo:
                handle(run_job(job))
        elif todo:
            sizer = TaskSizer()

            def handle_batch(outs: list[list[JobOutcome]]) -> None:
                for group in outs:
                    sizer.add(group)
                    handle_group(group)

            ctx = mp_context or default_mp_context()
            batches = sized_batches(deque(scene_groups(todo)), sizer)
            _run_pool(batches, run_group_batch, handle_batch, workers, ctx)
    finally:
        if bar is not None:
            bar.stop()
        run.wall_time = time.perf_counter() - tic
    return run


class Terminated(KeyboardInterrupt):
    """SIGTERM reached the campaign's main process: handled as Ctrl-C is (workers stopped, the
    episodes already stored kept; ``--resume`` continues)."""


@contextmanager
def sigterm_as_interrupt() -> Iterator[None]:
    """Within the block, SIGTERM raises :class:`Terminated` (a :class:`KeyboardInterrupt`) in the
    main thread instead of killing the process outright; the previous handler is restored after.
    Elsewhere than in the main thread (where Python allows no handler) nothing changes."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def _raise(signum: int, frame: object) -> None:
        raise Terminated(f"signal {signal.Signals(signum).name}")

    previous = signal.signal(signal.SIGTERM, _raise)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous if previous is not None else signal.SIG_DFL)


#: how often a worker checks that the campaign's main process is still there [s]
WATCHDOG_PERIOD = 0.5
#: how long an interrupted campaign waits for each killed worker to be gone [s]
WORKER_EXIT_TIMEOUT = 5.0


def _process_alive(pid: int) -> bool:
    """Whether process ``pid`` exists and has not exited (a zombie counts as exited on Linux)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            return fh.read().rsplit(b")", 1)[1].split()[0] != b"Z"
    except (OSError, IndexError):
        return True  # no /proc: os.kill said it exists


def _watch_main(main_pid: int, parent_pid: int) -> None:
    """Worker thread: end this worker when the campaign's main process is gone or this worker was
    orphaned (its parent, the fork server, changed), e.g. after a SIGKILL of the main process."""
    while _process_alive(main_pid) and os.getppid() == parent_pid:
        time.sleep(WATCHDOG_PERIOD)
    os._exit(1)  # nothing to clean up: results only ever go to the (gone) main process


def _worker_init(main_pid: int) -> None:
    """Worker initializer: Ctrl-C is handled by the main process alone (see :func:`_run_pool`),
    and a watchdog thread ends the worker with the main process (:func:`_watch_main`)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(
        target=_watch_main, args=(main_pid, os.getppid()), name="uvnav-watchdog", daemon=True
    ).start()


def _stop_workers(executor: ProcessPoolExecutor) -> None:
    """Cancel queued jobs and end the workers now: their episodes are lost anyway on interrupt.

    A worker killed while it writes a result leaves part of a message in the result pipe, and the
    executor's manager thread blocked in ``Connection.recv`` waiting for the rest: Python joins
    that thread at exit, so the process hung after Ctrl-C.  Once the workers are dead, this
    process holds the pipe's last write end; closing it turns the blocked read into an EOF, the
    manager thread sees a broken pool and ends.
    """
    # the executor keeps its processes and queues in private attributes (Python >= 3.14 also has
    # ``terminate_workers``); they are read before ``shutdown`` forgets them
    procs = list((getattr(executor, "_processes", None) or {}).values())
    writer = getattr(getattr(executor, "_result_queue", None), "_writer", None)
    terminate = getattr(executor, "terminate_workers", None)
    if not procs and callable(terminate):
        terminate()  # no private mapping to read (a future Python)
        return
    executor.shutdown(wait=False, cancel_futures=True)
    for proc in procs:
        if proc.is_alive():
            proc.kill()  # SIGKILL: a worker's own code cannot delay it
    for proc in procs:
        proc.join(timeout=WORKER_EXIT_TIMEOUT)
    if writer is not None and all(not proc.is_alive() for proc in procs):
        writer.close()


def run_in_workers(
    items: Sequence[T],
    compute: Callable[[T], R],
    handle: Callable[[R], None],
    *,
    workers: int = 1,
    mp_context: mp.context.BaseContext | None = None,
) -> None:
    """``handle(compute(item))`` for every item: ``compute`` in worker processes, ``handle`` here.

    The loop of every resumable campaign (this module's and the experiments' own stores): workers
    only compute, this process writes each result as it finishes (one store transaction each),
    so an interrupted run keeps all it finished.  ``workers <= 1`` or a single item runs
    in-process, in order; otherwise results come in the order they finish.  ``compute`` must be
    picklable (a module-level function).

    Raises:
        KeyboardInterrupt: re-raised after stopping the workers (see :func:`_run_pool`); SIGTERM
            raises :class:`Terminated`, a :class:`KeyboardInterrupt`, the same way.
    """
    with sigterm_as_interrupt():
        if workers <= 1 or len(items) < 2:
            for item in items:
                handle(compute(item))
            return
        _run_pool(items, compute, handle, workers, mp_context or default_mp_context())


def _run_pool(
    todo: Iterable[T],
    compute: Callable[[T], R],
    handle: Callable[[R], None],
    workers: int,
    ctx: mp.context.BaseContext,
) -> None:
    """Run ``compute`` over ``todo`` on a process pool, handing each result to ``handle`` as it
    finishes.  ``todo`` is drawn from only as a worker needs more (a generator may size the next
    item on the results handled so far).

    Workers ignore SIGINT, so a Ctrl-C (sent by the terminal to the whole process group) reaches
    only this process: it stops the workers at once — without waiting for the episodes in flight,
    whose results would be discarded — and re-raises :class:`KeyboardInterrupt`.  SIGTERM does the
    same where the caller handles it (:func:`sigterm_as_interrupt`).  Should this process die
    without cleaning up (SIGKILL, a crash), each worker's watchdog ends it within
    :data:`WATCHDOG_PERIOD`, and the fork server follows its last worker.
    """
    executor = ProcessPoolExecutor(
        max_workers=workers, mp_context=ctx, initializer=_worker_init, initargs=(os.getpid(),)
    )
    queue = iter(todo)
    pending: set[Future[R]] = set()
    window = 2 * workers
    try:
        while True:
            while len(pending) < window:
                try:
                    item = next(queue)
                except StopIteration:
                    break
                pending.add(executor.submit(compute, item))
            if not pending:
                break
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for fut in finished:
                handle(fut.result())
    except BaseException:
        _stop_workers(executor)
        raise
    executor.shutdown(wait=True)


class _ProgressBar:
    """A rich progress bar on stderr showing done/total, rate, ETA and status counts."""

    def __init__(self, name: str, total: int, skipped: int) -> None:
        from rich.console import Console
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )

        self._progress = Progress(
            TextColumn("[bold]{task.description}"),
            BarColumn(),
            MofNCompleteColumn(),
            TimeElapsedColumn(),
            TimeRemainingColumn(),
            TextColumn("{task.fields[counts]}"),
            console=Console(stderr=True),
        )
        note = f" ({skipped} already done)" if skipped else ""
        self._task = self._progress.add_task(f"{name}{note}", total=total, counts="")

    def start(self) -> None:
        self._progress.start()

    def stop(self) -> None:
        self._progress.stop()

    def advance(self, statuses: Mapping[str, int]) -> None:
        counts = " ".join(f"{k}={v}" for k, v in sorted(statuses.items()))
        self._progress.update(self._task, advance=1, counts=counts)


def grid_jobs(
    controllers: Sequence[str | tuple[str, Mapping[str, Any]]],
    seeds: Iterable[int],
    *,
    scenarios: Sequence[str] = (),
    generator_seeds: Iterable[int] | None = None,
    generator: str = DEFAULT_GENERATOR,
    record: bool = False,
) -> list[Job]:
    """The cartesian product scenarios × controllers × seeds as jobs.

    Args:
        controllers: names, or ``(name, params)`` pairs.
        seeds: episode seeds.
        scenarios: built-in names or YAML paths.
        generator_seeds: if given, also one generated scenario per generator seed, run with
            episode seed equal to the generator seed (``seeds`` is not crossed with these).
        generator: generator label (key of :data:`GENERATORS`).
        record: record trajectories.
    """
    ctrls = [(c, {}) if isinstance(c, str) else (c[0], dict(c[1])) for c in controllers]
    seed_list = [int(s) for s in seeds]
    jobs = [
        Job(controller=c, params=p, seed=s, scenario=sc, record=record)
        for sc in scenarios
        for c, p in ctrls
        for s in seed_list
    ]
    if generator_seeds is not None:
        jobs += [
            Job(
                controller=c,
                params=p,
                seed=int(g),
                generator_seed=int(g),
                generator=generator,
                record=record,
            )
            for g in generator_seeds
            for c, p in ctrls
        ]
    return jobs
