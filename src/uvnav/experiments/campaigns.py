"""Running an experiment's campaigns into the results store, and summing up their rows: the one
place every experiment that runs jobs goes through.

* :func:`fingerprint` — the code fingerprint of an experiment's campaigns: the packages that
  decide an episode (:func:`uvnav.bench.fingerprint.code_fingerprint`) and the experiment's own
  files (its runner, its network).
* :func:`run_checked` — campaigns of plain scene jobs (Ch. 2, crowds, the regime map): every
  stored campaign's fingerprint checked, then each run with the engine's progress bar.
* :func:`run_jobs` — the jobs a campaign lacks, each stored in its own transaction as it
  finishes (an interrupt loses only the episodes in flight); returns the stored records of the
  jobs asked for, in job order.
* :func:`run_rows` — :func:`run_jobs` with each record made an experiment's row.
* :func:`run_recorded` — every job run again with its trajectory recorded (the figures'
  trajectories); an episode the campaign lacks is stored, a stored one is kept.
* :func:`group_stats` / :func:`non_successes` — per-group outcome statistics and the episodes
  that did not succeed, from rows (dicts).

A failed episode (status ``error``) raises :class:`RuntimeError` in :func:`run_jobs` and
:func:`run_recorded`: a reproduction never tabulates a broken run.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Iterable, Mapping, Sequence
from typing import Any

from uvnav.bench.campaign import (
    outcome_record,
    run_campaign,
    run_in_workers,
    run_job,
    store_outcome,
    stored_records,
)
from uvnav.bench.fingerprint import code_fingerprint
from uvnav.bench.jobs import Job, JobOutcome
from uvnav.bench.store import EpisodeKey, ResultsStore, StaleCampaignError, extend_fingerprint
from uvnav.bench.summary import outcome_stats

#: ``progress(done, total)`` after each episode run (``total``: the episodes the call runs)
Progress = Callable[[int, int], None]


def fingerprint(*parts: str) -> str:
    """The code fingerprint of an experiment's campaigns: the packages that decide an episode
    and the files or folders ``parts`` (relative to the ``uvnav`` package, e.g.
    ``"experiments/ch4.py"``)."""
    return extend_fingerprint(code_fingerprint(), *parts)


def run_jobs(
    store: ResultsStore,
    campaign: str,
    jobs: Iterable[Job],
    *,
    config: Mapping[str, Any],
    workers: int = 1,
    progress: Progress | None = None,
) -> list[dict[str, Any]]:
    """Run the jobs of ``campaign`` not yet in the store, each stored as it finishes; stored
    episodes of other jobs are kept.

    Returns:
        The :func:`~uvnav.bench.campaign.stored_records` of the jobs (stored and new), in job
        order.

    Raises:
        RuntimeError: an episode failed (stored with status ``error``; a later run retries it).
    """
    jobs = list(jobs)
    total = len({j.key for j in jobs} - store.done_keys(store.campaign(campaign, dict(config))))
    errors: list[str] = []
    done = 0

    def seen(out: JobOutcome, _episode: int) -> None:
        nonlocal done
        done += 1
        if out.error is not None:
            errors.append(f"{out.job.scenario_label} {out.job.controller}: {out.error}")
        if progress is not None:
            progress(done, total)

    run_campaign(
        store, campaign, jobs, config=config, workers=workers, retry_errors=True, on_outcome=seen
    )
    if errors:
        raise RuntimeError(f"{campaign}: {len(errors)} episode(s) failed, first {errors[0]}")
    return job_records(store, campaign, jobs)


def job_records(store: ResultsStore, campaign: str, jobs: Iterable[Job]) -> list[dict[str, Any]]:
    """The stored records of ``jobs`` in ``campaign``, in job order (jobs not stored left out)."""
    by_key = {
        (r["scenario"], r["controller"], r["params_hash"], r["seed"]): r
        for r in stored_records(store, campaign)
    }
    return [by_key[j.key] for j in jobs if j.key in by_key]


def run_rows(
    jobs: Iterable[Job],
    store: ResultsStore,
    campaign: str,
    *,
    row: Callable[[dict[str, Any]], dict[str, Any]],
    config: Mapping[str, Any],
    workers: int = 1,
    progress: Progress | None = None,
) -> list[dict[str, Any]]:
    """:func:`run_jobs`, each stored record made an experiment's row by ``row``."""
    recs = run_jobs(store, campaign, jobs, config=config, workers=workers, progress=progress)
    return [row(r) for r in recs]


def run_recorded(
    store: ResultsStore,
    campaign: str,
    jobs: Sequence[Job],
    *,
    config: Mapping[str, Any],
    workers: int = 1,
    on_episode: Callable[[JobOutcome], None] | None = None,
) -> dict[EpisodeKey, Any]:
    """Run every job again with its trajectory recorded (``workers <= 1``: in this process, in
    order, so a job may carry an object that does not pickle); an episode the campaign lacks is
    stored in its own transaction as it finishes, a stored one is kept.  ``on_episode(outcome)``
    after each.

    Returns:
        Each job's recorded result (its outcome's ``result``, or its trajectory) by resume key.

    Raises:
        RuntimeError: an episode failed (the one stored before is kept).
    """
    kept: dict[EpisodeKey, Any] = {}
    with store.writer_lease():
        cid = store.campaign(campaign, dict(config))
        done = store.done_keys(cid, include_errors=False)

        def keep(out: JobOutcome) -> None:
            outcome_record(out)  # raises for a failed episode
            if out.job.key not in done:
                store_outcome(store, cid, out)
            kept[out.job.key] = out.result
            if on_episode is not None:
                on_episode(out)

        recorded = [dataclasses.replace(j, record=True) for j in jobs]
        run_in_workers(recorded, run_job, keep, workers=workers)
    return kept


def group_stats(
    rows: Iterable[dict[str, Any]],
    keys: Callable[[dict[str, Any]], tuple[Any, ...]],
    names: Sequence[str],
    counts: Mapping[str, Callable[[dict[str, Any]], int]] | None = None,
) -> list[dict[str, Any]]:
    """Per group of rows (``keys(row)``, groups sorted): the key fields ``names``, the outcome
    statistics (:func:`~uvnav.bench.summary.outcome_stats`) and each of ``counts`` summed over
    the group's rows."""
    groups: dict[tuple[Any, ...], list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault(keys(r), []).append(r)
    return [
        {
            **dict(zip(names, key, strict=True)),
            **outcome_stats(rs),
            **{name: sum(count(r) for r in rs) for name, count in (counts or {}).items()},
        }
        for key, rs in sorted(groups.items())
    ]


def non_successes(rows: Iterable[dict[str, Any]], keep: Sequence[str]) -> list[dict[str, Any]]:
    """The rows that did not succeed, each cut to the fields ``keep``."""
    return [{k: r.get(k) for k in keep} for r in rows if r["status"] != "success"]


def family(row: Mapping[str, Any]) -> str:
    """A row's scene family: its ``scene`` before ``:`` (``random-ch4:3`` -> ``random-ch4``)."""
    return str(row["scene"]).split(":", 1)[0]


def check_campaigns(store: ResultsStore, configs: dict[str, dict[str, Any]]) -> None:
    """Check that every stored campaign of ``configs`` (name -> config) was made by the same code
    (fingerprint); never deletes one.

    Raises:
        StaleCampaignError: naming every stored campaign whose fingerprint differs (its episodes
            cannot be resumed and would be mixed with new ones; the user removes them).
    """
    stale = []
    for c in store.campaigns():
        cfg = configs.get(c["name"])
        if cfg is not None and c["config"].get("fingerprint") != cfg["fingerprint"]:
            stale.append(c["name"])
    if stale:
        raise StaleCampaignError(
            store.path, stale, f"{'was' if len(stale) == 1 else 'were'} stored by other code"
        )


def run_checked(
    store: ResultsStore,
    plans: Sequence[tuple[str, dict[str, Any], list[Job]]],
    *,
    workers: int,
    progress: bool,
    statuses: bool = False,
) -> dict[str, dict[str, Any]]:
    """Check the stored campaigns of ``plans`` ((name, config, jobs); :func:`check_campaigns`),
    then run each; returns name -> its counts: jobs, ran, skipped, errors, the status counts (with
    ``statuses``) and the wall time [s]."""
    check_campaigns(store, {name: cfg for name, cfg, _ in plans})
    out: dict[str, dict[str, Any]] = {}
    for name, cfg, jobs in plans:
        run = run_campaign(store, name, jobs, config=cfg, workers=workers, progress=progress)
        counts: dict[str, Any] = {"jobs": run.total, "ran": run.ran, "skipped": run.skipped}
        counts["errors"] = run.errors
        if statuses:
            counts["statuses"] = dict(run.statuses)
        out[name] = {**counts, "wall_time": round(run.wall_time, 2)}
    return out
