"""Campaigns: resume without duplicates, interruption, errors as data, pool == in-process."""

from __future__ import annotations

from collections import deque
from pathlib import Path

import pytest

from uvnav.bench.campaign import (
    FORKSERVER_PRELOAD,
    Job,
    JobOutcome,
    TaskSizer,
    grid_jobs,
    run_campaign,
    run_group_batch,
    run_job,
    scene_groups,
    sized_batches,
    warm_up,
)
from uvnav.bench.store import ResultsStore
from uvnav.sim import METRIC_NAMES

# metrics that do not depend on timing (decision_us_* are wall-clock measurements)
DETERMINISTIC = [m for m in METRIC_NAMES if not m.startswith("decision_us")]


SCENES = Path(__file__).parents[1] / "scenes"
#: a scene file that does not exist: its jobs fail to build (an ``error`` outcome)
BROKEN = str(SCENES / "no-such-scene.yaml")


def tiny_scene(seed: int) -> str:
    """Robot (0, 0) -> (2, 0) past one disc; the disc blocks the path for seed % 3 == 0."""
    return str(SCENES / ("tiny-blocked.yaml" if seed % 3 == 0 else "tiny-clear.yaml"))


def tiny_jobs(seeds: range) -> list[Job]:
    params = [{}, {"slow_radius": 0.5}]
    return [
        Job(controller="straight-v1", seed=s, scenario=tiny_scene(s), params=p)
        for s in seeds
        for p in params
    ]


def test_job_validation_and_key() -> None:
    with pytest.raises(ValueError, match="exactly one"):
        Job(controller="straight-v1", seed=0)
    with pytest.raises(ValueError, match="exactly one"):
        Job(controller="straight-v1", seed=0, scenario="a", generator_seed=1)
    with pytest.raises(ValueError, match="scene_params need a scenario"):
        Job(controller="straight-v1", seed=0, generator_seed=1, scene_params={"sensing.range": 2})
    told = Job(controller="c", seed=0, scenario="s", scene_params={"sensing.range": 2})
    assert told.scenario_label == "s[sensing.range=2]"
    a = Job(controller="c", seed=3, scenario="s", params={"b": 1, "a": 2})
    b = Job(controller="c", seed=3, scenario="s", params={"a": 2, "b": 1})
    assert a == b and a.key == b.key and hash(a) == hash(b)
    g = Job(controller="c", seed=7, generator_seed=7)
    assert g.scenario_label == "random-ch2/0007" and g.family_label == "random-ch2"


def test_grid_jobs() -> None:
    jobs = grid_jobs(
        ["a", ("b", {"x": 1})], range(3), scenarios=["s1", "s2"], generator_seeds=range(4)
    )
    assert len(jobs) == 2 * 2 * 3 + 4 * 2
    assert len({j.key for j in jobs}) == len(jobs)


def test_run_job_error_is_an_outcome() -> None:
    out = run_job(Job(controller="straight-v1", seed=1, scenario=BROKEN))
    assert out.status == "error" and out.metrics is None
    assert out.error is not None and "ScenarioError" in out.error and "no such file" in out.error
    unknown = run_job(Job(controller="no-such-law-v9", seed=1, scenario=tiny_scene(1)))
    assert unknown.status == "error" and "no-such-law-v9" in (unknown.error or "")


def test_resume_after_partial_run_has_no_duplicates(tmp_path: Path) -> None:
    jobs = tiny_jobs(range(6))
    with ResultsStore(tmp_path / "r.sqlite") as store:
        first = run_campaign(store, "tiny", jobs[:5])  # "interrupted" after 5 of 12
        assert (first.ran, first.skipped) == (5, 0)
        second = run_campaign(store, "tiny", jobs)
        assert (second.total, second.ran, second.skipped) == (12, 7, 5)
        third = run_campaign(store, "tiny", jobs + jobs)  # duplicates in the list run once
        assert (third.total, third.ran, third.skipped) == (12, 0, 12)
        df = store.episodes_frame("tiny")
    assert len(df) == 12
    keys = set(zip(df["scenario"], df["controller"], df["params_hash"], df["seed"], strict=True))
    assert keys == {j.key for j in jobs}
    assert set(df["status"]) == {"success", "collision"}
    # resumed results equal an uninterrupted run, bit for bit
    with ResultsStore(tmp_path / "straight.sqlite") as other:
        run_campaign(other, "tiny", jobs)
        ref = other.episodes_frame("tiny")
    a = df.sort_values(["seed", "params_hash"]).reset_index(drop=True)
    b = ref.sort_values(["seed", "params_hash"]).reset_index(drop=True)
    assert a[DETERMINISTIC].equals(b[DETERMINISTIC])


def test_ctrl_c_keeps_finished_episodes_and_resume_completes(tmp_path: Path) -> None:
    jobs = tiny_jobs(range(4))
    seen: list[int] = []

    def interrupt_after_three(out: JobOutcome, episode_id: int) -> None:
        seen.append(episode_id)
        if len(seen) == 3:
            raise KeyboardInterrupt

    with ResultsStore(tmp_path / "r.sqlite") as store:
        with pytest.raises(KeyboardInterrupt):
            run_campaign(store, "tiny", jobs, on_outcome=interrupt_after_three)
        assert store.count("tiny") == 3
        rest = run_campaign(store, "tiny", jobs)
        assert (rest.ran, rest.skipped) == (5, 3)
        assert store.count("tiny") == 8


def test_failing_job_is_stored_and_campaign_continues(tmp_path: Path) -> None:
    jobs = [
        *tiny_jobs(range(2)),
        Job(controller="straight-v1", seed=5, scenario=BROKEN),
    ]
    with ResultsStore(tmp_path / "r.sqlite") as store:
        run = run_campaign(store, "mixed", jobs)
        assert (run.ran, run.errors) == (5, 1)
        df = store.episodes_frame("mixed")
        err = df[df["status"] == "error"].iloc[0]
        assert "no such file" in err["error"]
        assert err[DETERMINISTIC].isna().all()
        # errors count as done unless retried
        assert run_campaign(store, "mixed", jobs).ran == 0
        assert run_campaign(store, "mixed", jobs, retry_errors=True).ran == 1
        assert store.count("mixed") == 5


def test_process_pool_matches_in_process(tmp_path: Path) -> None:
    jobs = tiny_jobs(range(3))
    with ResultsStore(tmp_path / "pool.sqlite") as store:
        run = run_campaign(store, "tiny", jobs, workers=2, progress=True)
        assert run.ran == 6
        pooled = store.episodes_frame("tiny").sort_values(["seed", "params_hash"])
    with ResultsStore(tmp_path / "one.sqlite") as store:
        run_campaign(store, "tiny", jobs, workers=1)
        serial = store.episodes_frame("tiny").sort_values(["seed", "params_hash"])
    assert (
        pooled[DETERMINISTIC]
        .reset_index(drop=True)
        .equals(serial[DETERMINISTIC].reset_index(drop=True))
    )


def test_recorded_job_stores_trajectory(tmp_path: Path) -> None:
    job = Job(controller="straight-v1", seed=1, scenario=tiny_scene(1), record=True)
    with ResultsStore(tmp_path / "r.sqlite") as store:
        run = run_campaign(store, "rec", [job])
        traj = store.load_trajectory(run.episode_ids[job.key])
    assert traj is not None and len(traj.times) > 10


def test_scenario_and_generator_jobs() -> None:
    scenarios = pytest.importorskip("uvnav.scenarios")
    name = next(n for n in scenarios.list_builtin() if n.startswith("thesis-ch2-"))
    out = run_job(Job(controller="straight-v1", seed=0, scenario=name))
    assert out.status in {"success", "collision", "timeout"}, out.error
    gen = run_job(Job(controller="straight-v1", seed=3, generator_seed=3))
    assert gen.status in {"success", "collision", "timeout"}, gen.error
    again = run_job(Job(controller="straight-v1", seed=3, generator_seed=3))
    assert gen.metrics is not None and again.metrics is not None
    assert {k: gen.metrics[k] for k in DETERMINISTIC} == {
        k: again.metrics[k] for k in DETERMINISTIC
    }


def test_run_in_workers_hands_every_result_to_this_process() -> None:
    import math

    from uvnav.bench.campaign import run_in_workers

    items = [float(k) for k in range(7)]
    for workers in (1, 2):
        got: list[float] = []
        run_in_workers(items, math.sqrt, got.append, workers=workers)
        # the pool hands results over as they finish; the set of results is the same
        assert sorted(got) == [math.sqrt(x) for x in items]
    in_order: list[float] = []
    run_in_workers(items, math.sqrt, in_order.append, workers=1)
    assert in_order == [math.sqrt(x) for x in items]  # in-process keeps the order


def test_scene_groups_keep_one_scene_and_seed_together() -> None:
    laws = ("straight-v1", "zhang2019-v1")
    jobs = [Job(controller=c, seed=g, generator_seed=g) for g in (3, 1) for c in laws]
    jobs += [Job(controller=c, seed=s, scenario="thesis-ch2-one-obstacle") for s in (0, 1)
             for c in laws]  # fmt: skip
    jobs.append(Job(controller="straight-v1", seed=3, generator_seed=3,
                    generator_params={"n_obstacles": 2}))  # fmt: skip
    groups = scene_groups(jobs)
    assert [[j.controller for j in g] for g in groups] == [list(laws)] * 4 + [["straight-v1"]]
    assert [(g[0].scenario_label, g[0].seed) for g in groups] == [
        ("random-ch2/0003", 3), ("random-ch2/0001", 1), ("thesis-ch2-one-obstacle", 0),
        ("thesis-ch2-one-obstacle", 1), ("random-ch2[n_obstacles=2]/0003", 3),
    ]  # fmt: skip
    assert sorted(j.key for g in groups for j in g) == sorted(j.key for j in jobs)


def test_a_batch_stores_all_or_nothing(tmp_path: Path) -> None:
    ok = {m: 0.0 for m in ("min_clearance", "path_length", "control_effort")}
    with ResultsStore(tmp_path / "r.sqlite") as store:
        cid = store.campaign("c")
        with store.batch():
            for s in range(3):
                store.add_episode(cid, scenario="s", controller="x", seed=s, status="timeout",
                                  metrics=ok)  # fmt: skip
        assert store.count("c") == 3
        with pytest.raises(KeyboardInterrupt), store.batch():
            store.add_episode(cid, scenario="s", controller="x", seed=7, status="timeout",
                              metrics=ok)  # fmt: skip
            raise KeyboardInterrupt
        assert store.count("c") == 3
        store.add_episode(cid, scenario="s", controller="x", seed=8, status="timeout", metrics=ok)
        assert store.count("c") == 4  # outside a batch: a write is its own transaction again


def test_run_job_times_its_cpu() -> None:
    out = run_job(Job(controller="straight-v1", seed=1, generator_seed=1))
    assert out.error is None and out.cpu_time > 0.0


def _outcome(job: Job, wall_time: float) -> JobOutcome:
    return JobOutcome(job, "success", {}, None, wall_time)


def test_task_sizer_batches_short_groups_up_to_a_limit() -> None:
    job = Job(controller="straight-v1", seed=0, generator_seed=0)
    sizer = TaskSizer(seconds=0.25, limit=16)
    assert sizer.size() == 1  # nothing measured yet: one group per task
    sizer.add([_outcome(job, 0.02), _outcome(job, 0.03)])  # a group of 0.05 s
    assert sizer.size() == 5
    sizer.add([_outcome(job, 0.15)])  # mean 0.1 s per group
    assert sizer.size() == 2
    sizer.add([_outcome(job, 2.0)])  # slow groups: still one per task
    assert sizer.size() == 1
    fast = TaskSizer(seconds=0.25, limit=16)
    fast.add([_outcome(job, 0.0001)])
    assert fast.size() == 16


def test_sized_batches_are_cut_when_asked_for() -> None:
    """A task is sized when the pool asks for it, on the groups handled so far."""
    groups = [[Job(controller="straight-v1", seed=g, generator_seed=g)] for g in range(10)]
    sizer = TaskSizer(seconds=0.25, limit=16)
    batches = sized_batches(deque(groups), sizer)
    assert len(next(batches)) == 1  # nothing back yet
    sizer.add([_outcome(groups[0][0], 0.08)])  # 0.08 s a group: 3 to a task
    assert [len(b) for b in batches] == [3, 3, 3]
    assert list(batches) == []


def test_group_batch_runs_every_group_and_times_each_job() -> None:
    laws = ("straight-v1", "zhang2019-v1")
    groups = scene_groups([Job(controller=c, seed=g, generator_seed=g) for g in (1, 2)
                           for c in laws])  # fmt: skip
    outs = run_group_batch(groups)
    assert [[o.job for o in g] for g in outs] == groups
    assert all(o.error is None and o.cpu_time > 0.0 for g in outs for o in g)


def test_fork_server_warms_up_once() -> None:
    """The pool's fork server imports the module that runs one episode before it forks."""
    assert FORKSERVER_PRELOAD[-1] == "uvnav.bench.forkserver_warm"
    import uvnav.bench.forkserver_warm  # noqa: F401 - runs warm_up(): must not raise

    warm_up()
