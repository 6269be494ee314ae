"""Ray's overhead: the CPU a campaign on the Ray engine adds per episode to the local engine's
(issue 20, item 4: at most 10 % of the episode's own CPU), and on a two-node cluster beside the
local pool.

Run: ``PYTHONPATH=src .venv/bin/python benchmarks/bench_ray.py`` (``--seeds N``: random-ch2
scenes, 2 episodes each, default 5000: the issue's 10,000-episode campaign, whose line the
target is part of; ``--quick``: 100 seeds; ``--workers``: default 2; ``--out DIR`` writes
``DIR/ray.json``).  Needs Ray (extra ``uvnav[bench]``) and Linux (``/proc``); without either it
writes the record with ``pass: null`` and says why.  About 9 minutes on 2 idle cores (the
in-process run alone takes a third of it).

The campaign's size matters: a Ray worker pays its imports and its first episode's warm-up
(numba's import, loading the cached kernels, which imports scipy.linalg: over a CPU-second)
once, where the pool's fork server pays them once for all its workers.  Over 10,000 episodes
of about 20 CPU-ms that is about 1 % an episode; over 2,000 (this script's former default) five
times as much.

The same jobs (random-ch2 seeds x zhang2019-v1 and savkin-wang2013-v1, as ``bench_campaign.py``)
run three times through :func:`uvnav.bench.campaign.run_campaign`, each into a fresh store:

1. the local engine in this process (``workers=1``);
2. the local engine's process pool (``--workers`` processes);
3. the Ray engine on a local Ray instance of ``--workers`` CPUs, started here
   (:func:`uvnav.bench.ray_engine.start_local_ray`, as ``uvnav bench --engine ray`` starts it);
4. (unless ``--no-cluster``) the Ray engine on a two-node cluster started here as a user starts
   one (:func:`two_node_cluster`: ``ray start --head`` and ``ray start --address`` for a second
   raylet, 1 CPU each, token authentication), connected to as ``uvnav bench --address`` connects
   (``ray.init``, every node's code check), beside the local pool of 2 processes: both run the
   same jobs on 2 CPUs, the pool's workers forked from a warm fork server, the cluster's two
   Ray workers (one per node) started and warmed up by the campaign; the driver stores every
   episode in both; the cluster run counts connecting (``ray.init``, the nodes' code check,
   which starts a worker on each node), as the pool's run counts starting its fork server.
   Reported: episodes per second of each, and Ray's overhead per episode,
   held = (the cluster run's wall x 2 CPUs - the pool's CPU) / episodes (beside the pool's own
   (wall x 2 - CPU) / episodes, what a loaded machine costs any run) and spent = (CPU of the
   cluster run's process tree - the pool's) / episodes.  The cluster's start is reported apart.

Counted, for each run: user + system CPU time, read from ``/proc/PID/stat``, of this process and
every process below it — the fork server and pool workers; Ray's GCS server, raylet, dashboard
and runtime-env agents, log monitor and workers — including what their exited children used
(``cutime`` and ``cstime``: a pool worker that has exited is counted through the fork server that
reaped it), split by process (driver, pool; Ray workers, Ray daemons).  From it is taken the
jobs' own CPU, the sum of the outcomes' ``cpu_time`` (the worker thread's CPU time in
:func:`~uvnav.bench.campaign.run_job`: scene, episode, metrics): what is left is the engine's
overhead (storing, messages, scheduling, process start-up and imports, daemons).  Two processes
busy on two cores (or on one core's two hyperthreads) each run slower than one alone, and a
loaded machine more so, so total CPU times of runs with different parallelism are not
comparable with each other; runs with the same parallelism are, and the overheads are.

Ray's added CPU per episode = (CPU of Ray's run - CPU of the pool's run) / episodes, judged as a
share of the episode's own CPU (the in-process run's jobs' CPU per episode).  The pool and Ray
each run the campaign twice, in the order pool, Ray, Ray, pool, and are judged on the sums
(:func:`pooled`): a difference of two CPU totals of 10,000 episodes each moved by several per
cent of an episode from one run to the next.  It is reported in
two parts: the overheads' difference, and the jobs' (Ray's workers pay the first episode's
warm-up, about 0.65 CPU-s each, themselves; the pool's fork server pays it once before it forks;
and whatever Ray's threads beside a task cost it).  Ray's start-up (``ray.init`` until it returns:
GCS, raylet, agents, idle workers) is a cost per campaign, reported apart (and per episode of this
run with it); the run after it (its daemons' CPU during the run, its workers' imports and warm-up
included) is what the target judges.  Prints target, measured, ratio and PASS/FAIL.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).parent))

from run_benchmarks import machine_info, write_json

from uvnav.bench.campaign import Job, JobOutcome, run_campaign
from uvnav.bench.store import ResultsStore

LAWS = ("zhang2019-v1", "savkin-wang2013-v1")
#: Ray's added CPU per episode, at most this share of the episode's own CPU
TARGET_SHARE = 0.10
#: how long to leave the fork server to reap an exited worker before its CPU is read [s]
REAP_WAIT_S = 0.3


def _proc_table() -> dict[int, tuple[int, str, float]] | None:
    """Every process's ``(parent pid, name, CPU seconds)`` from ``/proc`` (user + system, its own
    and its reaped children's), or ``None`` without ``/proc``."""
    if not os.path.isdir("/proc/self"):
        return None
    tick = os.sysconf("SC_CLK_TCK")
    table: dict[int, tuple[int, str, float]] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat", "rb") as fh:
                stat = fh.read()
        except OSError:  # gone meanwhile
            continue
        head, tail = stat.rsplit(b")", 1)
        name = head.split(b"(", 1)[1].decode(errors="replace")
        fields = tail.split()  # state ppid ... utime stime cutime cstime at 11..14
        utime, stime, cutime, cstime = (int(x) for x in fields[11:15])
        table[int(entry)] = (int(fields[1]), name, (utime + stime + cutime + cstime) / tick)
    return table


def tree_snapshot(root: int | None = None) -> dict[int, tuple[str, float]] | None:
    """Name and CPU seconds (its reaped children's included) of process ``root`` (default: this
    one) and each of its living descendants; ``None`` where ``/proc`` is missing."""
    table = _proc_table()
    if table is None:
        return None
    root = os.getpid() if root is None else root
    children: dict[int, list[int]] = {}
    for pid, (ppid, _, _) in table.items():
        children.setdefault(ppid, []).append(pid)
    out: dict[int, tuple[str, float]] = {}
    todo = [root]
    while todo:
        pid = todo.pop()
        if pid in table:
            out[pid] = table[pid][1:]
            todo.extend(children.get(pid, ()))
    return out


def tree_cpu(root: int | None = None) -> float | None:
    """CPU seconds of :func:`tree_snapshot`, summed."""
    snap = tree_snapshot(root)
    return None if snap is None else sum(cpu for _, cpu in snap.values())


def _role(pid: int, name: str, engine: str) -> str:
    """Who a process of the tree is: this process (the driver, which stores), or for the local
    engine its pool (the fork server, with the workers it reaped), for Ray a worker (named
    ``ray::<task>`` or ``ray::IDLE``) or one of Ray's daemons (GCS server, raylet, agents,
    monitors)."""
    if pid == os.getpid():
        return "driver"
    if engine != "ray":
        return "pool"
    if name.startswith("ray::") and not name.startswith(("ray::Dashboard", "ray::RuntimeEnv")):
        return "ray workers"
    return "ray daemons"


def by_role(
    before: dict[int, tuple[str, float]] | None,
    after: dict[int, tuple[str, float]] | None,
    engine: str,
) -> dict[str, float] | None:
    """CPU seconds spent between two snapshots, by :func:`_role`."""
    if before is None or after is None:
        return None
    roles: dict[str, float] = {}
    for pid, (name, cpu) in after.items():
        role = _role(pid, name, engine)
        roles[role] = roles.get(role, 0.0) + cpu - before.get(pid, (name, 0.0))[1]
    return dict(sorted(roles.items()))


def campaign_jobs(seeds: int) -> list[Job]:
    """random-ch2 seeds ``0..seeds-1`` x :data:`LAWS` (``bench_campaign.py``'s jobs)."""
    return [Job(controller=c, seed=g, generator_seed=g) for g in range(seeds) for c in LAWS]


def timed_campaign(
    jobs: Sequence[Job],
    workers: int,
    engine: str,
    before_read: Callable[[], None] | None = None,
    session: Callable[[], contextlib.AbstractContextManager[None]] | None = None,
) -> dict[str, Any]:
    """One campaign of ``jobs`` into a fresh store (inside ``session()``, e.g. connected to a
    Ray cluster, counted with the campaign): wall time, episodes per second, CPU of the process
    tree, the jobs' own CPU (their outcomes' ``cpu_time``) and what the rest costs (the
    engine's overhead)."""
    jobs_cpu = [0.0]

    def count(out: JobOutcome, episode_id: int) -> None:
        jobs_cpu[0] += out.cpu_time

    with tempfile.TemporaryDirectory() as tmp, ResultsStore(Path(tmp) / "r.sqlite") as store:
        snap0, tic = tree_snapshot(), time.perf_counter()
        with session() if session is not None else contextlib.nullcontext():
            connect = time.perf_counter() - tic
            run = run_campaign(
                store, f"bench-{engine}", jobs, workers=workers, engine=engine, on_outcome=count
            )
            wall = time.perf_counter() - tic
            if before_read is not None:
                before_read()
            snap1 = tree_snapshot()  # before the session ends (a cluster ends its workers)
    roles = by_role(snap0, snap1, engine)
    cpu = None if roles is None else sum(roles.values())
    n = max(run.ran, 1)
    return {
        "engine": engine,
        "workers": workers,
        "episodes": run.ran,
        "statuses": dict(sorted(run.statuses.items())),
        "wall_s": wall,
        "session_wall_s": connect,
        "episodes_per_s": run.ran / wall if wall > 0 else None,
        "cpu_s": cpu,
        "jobs_cpu_s": jobs_cpu[0],
        "overhead_cpu_s": None if cpu is None else cpu - jobs_cpu[0],
        "cpu_ms_per_episode": None if cpu is None else 1e3 * cpu / n,
        "jobs_cpu_ms_per_episode": 1e3 * jobs_cpu[0] / n,
        "overhead_ms_per_episode": None if cpu is None else 1e3 * (cpu - jobs_cpu[0]) / n,
        "cpu_s_by_process": roles,
    }


def pooled(*runs: dict[str, Any]) -> dict[str, Any]:
    """Runs of one campaign (:func:`timed_campaign`'s, or :func:`measure_ray`'s, whose first
    start-up is kept) as one: episodes, times, CPU and statuses summed, the rates and the
    per-episode figures of the sums."""
    first = runs[0]
    out = {**first}
    n = sum(int(r["episodes"]) for r in runs)
    wall = sum(r["wall_s"] for r in runs)
    cpus = [r["cpu_s"] for r in runs]
    cpu = None if None in cpus else sum(cpus)
    jobs_cpu = sum(r["jobs_cpu_s"] for r in runs)
    statuses: dict[str, int] = {}
    by_process: dict[str, float] | None = {}
    for r in runs:
        for k, v in r["statuses"].items():
            statuses[k] = statuses.get(k, 0) + v
        if r["cpu_s_by_process"] is None or by_process is None:
            by_process = None
            continue
        for k, v in r["cpu_s_by_process"].items():
            by_process[k] = by_process.get(k, 0.0) + v
    out.update(
        runs=len(runs), episodes=n, statuses=dict(sorted(statuses.items())), wall_s=wall,
        session_wall_s=sum(r["session_wall_s"] for r in runs),
        episodes_per_s=n / wall if wall > 0 else None, cpu_s=cpu, jobs_cpu_s=jobs_cpu,
        overhead_cpu_s=None if cpu is None else cpu - jobs_cpu,
        cpu_ms_per_episode=None if cpu is None else 1e3 * cpu / max(n, 1),
        jobs_cpu_ms_per_episode=1e3 * jobs_cpu / max(n, 1),
        overhead_ms_per_episode=None if cpu is None else 1e3 * (cpu - jobs_cpu) / max(n, 1),
        cpu_s_by_process=by_process,
    )  # fmt: skip
    return out


def measure_ray(jobs: Sequence[Job], workers: int) -> dict[str, Any]:
    """The Ray engine on a local instance started here: start-up apart, then the campaign."""
    import ray

    from uvnav.bench.ray_engine import start_local_ray

    snap0, tic = tree_snapshot(), time.perf_counter()
    start_local_ray(ray, workers)
    wall = time.perf_counter() - tic
    roles = by_role(snap0, tree_snapshot(), "ray")
    startup = {
        "wall_s": wall,
        "cpu_s": None if roles is None else sum(roles.values()),
        "cpu_s_by_process": roles,
    }
    try:
        res = timed_campaign(jobs, workers, "ray")  # read before the shutdown: all alive
    finally:
        ray.shutdown()
    return {**res, "startup": startup, "ray": ray.__version__}


def _start_node(tmp: Path, env: dict[str, str], *args: str) -> subprocess.Popen[bytes]:
    """``ray start --block --num-cpus 1 ARGS`` in a new session, once it says it started."""
    log = tmp / f"node-{len(list(tmp.glob('node-*.log')))}.log"
    ray_cli = str(Path(sys.executable).with_name("ray"))
    with open(log, "wb") as out:
        proc = subprocess.Popen(
            [ray_cli, "start", "--block", "--num-cpus=1", "--node-ip-address=127.0.0.1", *args],
            stdout=out, stderr=subprocess.STDOUT, start_new_session=True, env=env,
        )  # fmt: skip
    deadline = time.monotonic() + 90
    while b"Ray runtime started" not in log.read_bytes():
        if proc.poll() is not None or time.monotonic() > deadline:
            _stop_node(proc)
            raise RuntimeError(f"ray start failed: {log.read_text()[-300:]}")
        time.sleep(0.3)
    return proc


def _stop_node(node: subprocess.Popen[bytes]) -> None:
    """SIGTERM ``ray start --block`` (it stops its node), then SIGKILL what is left of its
    session (``ray stop`` would stop every Ray of this user on the machine)."""
    if node.poll() is None:
        node.send_signal(signal.SIGTERM)
        with contextlib.suppress(subprocess.TimeoutExpired):
            node.wait(timeout=20)
    for entry in os.listdir("/proc"):
        with contextlib.suppress(OSError):
            if entry.isdigit() and os.getsid(int(entry)) == node.pid:
                os.kill(int(entry), signal.SIGKILL)
    with contextlib.suppress(subprocess.TimeoutExpired):
        node.wait(timeout=10)


@contextlib.contextmanager
def two_node_cluster() -> Iterator[str]:
    """A Ray cluster on this machine as a user starts one (``ray start --head`` and ``ray
    start --address`` for a second raylet, 1 CPU each, token authentication with a fresh token,
    this checkout's uvnav on the nodes' ``PYTHONPATH``, their own ``RAY_TMPDIR``); yields the
    head's ``127.0.0.1:PORT`` with this process set to send the token; stopped at the end."""
    import uvnav

    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = int(sock.getsockname()[1])
    token = secrets.token_hex(24)
    tmp = Path(tempfile.mkdtemp(prefix="uvr-", dir="/tmp"))  # Ray's socket paths: 107 bytes
    env = {k: v for k, v in os.environ.items() if not k.startswith("RAY_")}
    env.update(RAY_TMPDIR=str(tmp), RAY_AUTH_MODE="token", RAY_AUTH_TOKEN=token,
               PYTHONPATH=str(Path(uvnav.__file__).resolve().parents[1]))  # fmt: skip
    nodes: list[subprocess.Popen[bytes]] = []
    saved = os.environ.get("RAY_AUTH_TOKEN")
    try:
        nodes.append(_start_node(tmp, env, "--head", f"--port={port}",
                                 "--include-dashboard=false"))  # fmt: skip
        nodes.append(_start_node(tmp, env, f"--address=127.0.0.1:{port}"))
        os.environ["RAY_AUTH_TOKEN"] = token
        yield f"127.0.0.1:{port}"
    finally:
        if saved is None:
            os.environ.pop("RAY_AUTH_TOKEN", None)
        else:
            os.environ["RAY_AUTH_TOKEN"] = saved
        for node in reversed(nodes):
            _stop_node(node)
        shutil.rmtree(tmp, ignore_errors=True)


def measure_cluster(jobs: Sequence[Job]) -> dict[str, Any]:
    """The Ray engine on :func:`two_node_cluster` (2 CPUs in all) as ``uvnav bench --address``
    runs it: connecting (:func:`uvnav.bench.ray_engine.cluster_session`: ``ray.init``, every
    node's code check, which starts and warms up a worker on each node) and the campaign, both
    counted, as the pool's run counts starting its fork server; the cluster's start is reported
    apart (a cluster serves many campaigns).  CPU: this process and every cluster process (the
    nodes are its descendants), read while connected (the cluster ends the job's workers when
    the driver leaves)."""
    from uvnav.bench.ray_engine import cluster_session

    tic = time.perf_counter()
    with two_node_cluster() as address:
        started = time.perf_counter() - tic
        res = timed_campaign(jobs, 2, "ray", session=lambda: cluster_session(address))
    return {**res, "cluster_start_wall_s": started, "nodes": 2, "cpus": 2}


def cluster_overhead(pool: dict[str, Any], cluster: dict[str, Any]) -> dict[str, Any]:
    """Ray's overhead per episode on the cluster against the local pool (both 2 CPUs, the same
    jobs, per episode): ``held_ms`` = (cluster wall x 2 CPUs - the pool's CPU), the CPU time
    the cluster held beyond what the pool spent on the same work, beside ``pool_held_ms`` =
    (the pool's wall x 2 - its CPU), what the pool itself held idle or lost to other load;
    ``cpu_ms`` = (CPU of the cluster run's process tree - the pool run's), the CPU Ray spent
    beyond the pool's."""
    n = max(int(cluster["episodes"]), 1)
    out: dict[str, Any] = {
        "throughput_ratio": cluster["episodes_per_s"] / pool["episodes_per_s"],
        "held_ms": None,
        "pool_held_ms": None,
        "cpu_ms": None,
    }
    if pool["cpu_s"] is not None and cluster["cpu_s"] is not None:  # /proc read
        out["held_ms"] = 1e3 * (cluster["wall_s"] * cluster["cpus"] - pool["cpu_s"]) / n
        out["pool_held_ms"] = 1e3 * (pool["wall_s"] * 2 - pool["cpu_s"]) / n
        out["cpu_ms"] = 1e3 * (cluster["cpu_s"] - pool["cpu_s"]) / n
    return out


def judge(inproc: dict[str, Any], pool: dict[str, Any], ray_run: dict[str, Any]) -> dict[str, Any]:
    """Ray's added CPU per episode (the CPU of Ray's runs less the local pool's, both process
    trees, per episode; one start-up per run with it) and its share of the episode's own CPU
    (the in-process jobs'), with its parts: the overheads' difference, and the jobs' (Ray's
    workers pay their first episode's warm-up themselves, the pool's fork server pays it once
    for all its workers)."""
    if None in (inproc["cpu_s"], pool["cpu_s"], ray_run["cpu_s"]):
        return {"measured": None, "limit": TARGET_SHARE, "pass": None, "note": "no /proc"}
    n = max(int(ray_run["episodes"]), 1)
    episode_ms = inproc["jobs_cpu_ms_per_episode"]
    added_ms = 1e3 * (ray_run["cpu_s"] - pool["cpu_s"]) / n
    share = added_ms / episode_ms
    startup = ray_run["startup"]["cpu_s"] or 0.0
    return {
        "episode_cpu_ms": episode_ms,
        "ray_added_cpu_ms": added_ms,
        "of_which_overhead_ms": (
            ray_run["overhead_ms_per_episode"] - pool["overhead_ms_per_episode"]
        ),
        "of_which_jobs_ms": ray_run["jobs_cpu_ms_per_episode"] - pool["jobs_cpu_ms_per_episode"],
        "ray_added_with_startup_ms": added_ms + 1e3 * startup * ray_run.get("runs", 1) / n,
        "measured": share,
        "limit": TARGET_SHARE,
        "ratio": share / TARGET_SHARE,
        "pass": share <= TARGET_SHARE,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument(
        "--seeds",
        type=int,
        default=5000,
        help="random-ch2 scenes (2 episodes each; 5000: the issue's campaign)",
    )
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--quick", action="store_true", help="100 seeds: a smoke run")
    ap.add_argument("--out", type=Path, help="write ray.json here")
    ap.add_argument(
        "--no-cluster", action="store_true", help="skip the run on a two-node Ray cluster"
    )
    args = ap.parse_args()
    seeds = 100 if args.quick else args.seeds
    record: dict[str, Any] = {"machine": machine_info(), "quick": args.quick, "seeds": seeds}
    try:
        import ray  # noqa: F401
    except ImportError as exc:
        print(f"ray: not installed ({exc}); nothing measured")
        record["target"] = {"measured": None, "limit": TARGET_SHARE, "pass": None,
                            "note": "ray not installed"}  # fmt: skip
        if args.out is not None:
            write_json(args.out, "ray", record)
        return
    jobs = campaign_jobs(seeds)
    load0 = os.getloadavg()[0]
    inproc = timed_campaign(jobs, 1, "local")
    # pool, Ray, Ray, pool: a drift of the machine's speed over the four cancels, and one
    # noisy run weighs half (one sitting's single pair gave 14.5 %, a rerun alone 3.3 %)
    pool_a = timed_campaign(jobs, args.workers, "local", lambda: time.sleep(REAP_WAIT_S))
    ray_run = pooled(measure_ray(jobs, args.workers), measure_ray(jobs, args.workers))
    pool = pooled(pool_a, timed_campaign(jobs, args.workers, "local",
                                         lambda: time.sleep(REAP_WAIT_S)))  # fmt: skip
    runs = [("in-process", inproc), (f"pool x{args.workers}", pool),
            (f"ray x{args.workers}", ray_run)]  # fmt: skip
    cluster: dict[str, Any] | None = None
    if not args.no_cluster:
        pool2 = pool_a if args.workers == 2 else timed_campaign(
            jobs, 2, "local", lambda: time.sleep(REAP_WAIT_S))  # fmt: skip
        try:
            cluster = measure_cluster(jobs)
        except RuntimeError as exc:
            print(f"two-node cluster: not measured ({exc})")
            record["cluster"] = {"note": str(exc)}
        else:
            record["cluster"] = {**cluster, "pool_x2": pool2,
                                 "overhead": cluster_overhead(pool2, cluster)}  # fmt: skip
            if pool2 is not pool_a:
                runs.append(("pool x2", pool2))
            runs.append(("ray 2 nodes", cluster))
    record.update(in_process=inproc, pool=pool, ray_engine=ray_run, load_before=load0,
                  load_after=os.getloadavg()[0])  # fmt: skip
    target = record["target"] = judge(inproc, pool, ray_run)
    for name, res in runs:
        cpu = res["cpu_s"]
        print(f"{name:<12} {res['episodes']} episodes: {res['wall_s']:6.1f} s wall, "
              f"{res['episodes_per_s']:6.1f} episodes/s, "
              + ("CPU not measured" if cpu is None else
                 f"{cpu:6.1f} CPU-s; per episode: job {res['jobs_cpu_ms_per_episode']:.2f} ms, "
                 f"the rest {res['overhead_ms_per_episode']:.2f} ms"))  # fmt: skip
        if res["cpu_s_by_process"]:
            print("             CPU-s by process: " + ", ".join(
                f"{k} {v:.2f}" for k, v in res["cpu_s_by_process"].items()))  # fmt: skip
    if cluster is not None:
        ov = record["cluster"]["overhead"]
        print(f"ray 2 nodes: cluster start {cluster['cluster_start_wall_s']:.1f} s (apart), "
              f"connect and code check {cluster['session_wall_s']:.1f} s (counted); "
              f"{ov['throughput_ratio']:.2f} x the pool's episodes/s")  # fmt: skip
        if ov["cpu_ms"] is not None:
            print(f"Ray's overhead per episode on 2 nodes: held {ov['held_ms']:.2f} ms "
                  "((wall x 2 CPUs - the pool's CPU) / episodes; the pool's own "
                  f"(wall x 2 - CPU) / episodes: {ov['pool_held_ms']:.2f} ms), spent "
                  f"{ov['cpu_ms']:.2f} CPU-ms ((run's CPU - the pool's) / episodes)")  # fmt: skip
    su = ray_run["startup"]
    print(f"ray start-up: {su['wall_s']:.1f} s wall, {su['cpu_s'] or float('nan'):.1f} CPU-s; "
          f"load {load0:.1f} -> {record['load_after']:.1f}")  # fmt: skip
    if target["pass"] is None:
        print(f"target: Ray's added CPU <= {TARGET_SHARE:.0%} of the episode's: not measured")
    else:
        print(
            f"ray adds {target['ray_added_cpu_ms']:.2f} CPU-ms per episode to the pool "
            f"(overhead {target['of_which_overhead_ms']:.2f}, jobs "
            f"{target['of_which_jobs_ms']:.2f}; {target['ray_added_with_startup_ms']:.2f} with "
            f"its start-up); episode {target['episode_cpu_ms']:.2f} CPU-ms"
        )
        print(
            f"target: Ray's added CPU per episode <= {TARGET_SHARE:.0%} of the episode's: "
            f"measured {target['measured']:.1%} (ratio {target['ratio']:.2f}) "
            f"{'PASS' if target['pass'] else 'FAIL'}"
        )
    if args.out is not None:
        write_json(args.out, "ray", record)


if __name__ == "__main__":
    main()
