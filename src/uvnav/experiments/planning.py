"""What an experiment would run, without running it (``uvnav reproduce NAME --plan``).

:func:`plan_experiment` returns the experiment's planned campaigns (its ``plan`` at the context's
size, with the same context preparation as a run); :func:`plan_summary` adds, per campaign, its
laws, its scene families and how many of its jobs the results database already holds.  The
database is only read, and only when it exists: planning creates no file.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from uvnav.bench.fingerprint import DB_NAME
from uvnav.bench.jobs import Job
from uvnav.bench.store import FINGERPRINT_KEY, ResultsStore
from uvnav.experiments.protocol import ExperimentContext, PlannedCampaign
from uvnav.experiments.registry import check_options, get_experiment


def plan_experiment(name: str, ctx: ExperimentContext) -> list[PlannedCampaign] | None:
    """The campaigns ``uvnav reproduce NAME`` would run with ``ctx``, in order (``None``: the
    experiment declares no plan).  Nothing runs and nothing is written.

    Raises:
        ExperimentError: unknown experiment, or ``seeds``/``start_seed`` it does not take.
    """
    experiment = get_experiment(name)
    check_options(experiment, ctx.seeds, ctx.start_seed)
    if experiment.plan is None:
        return None
    return list(experiment.plan(experiment.prepare(ctx)))


def scene_family(job: Job) -> str:
    """The job's scene family: its ``family``, else its generator (without parameters) or its
    scenario."""
    if job.family is not None:
        return job.family
    if job.generator_seed is not None:
        return job.generator
    return str(job.scenario)


def _stored(db_path: Path, plans: Sequence[PlannedCampaign]) -> dict[str, tuple[int, bool]]:
    """Per planned campaign stored in ``db_path``: how many of its jobs are stored, and whether
    the stored campaign was made by other code (its fingerprint differs)."""
    out: dict[str, tuple[int, bool]] = {}
    if not db_path.is_file():
        return out
    with ResultsStore(db_path, readonly=True) as store:
        configs = {c["name"]: c["config"] for c in store.campaigns()}
        for p in plans:
            cid = store.campaign_id(p.name)
            if cid is None:
                continue
            done = store.done_keys(cid)
            stale = configs[p.name].get(FINGERPRINT_KEY) != p.config.get(FINGERPRINT_KEY)
            out[p.name] = (sum(j.key in done for j in p.jobs), stale)
    return out


def plan_summary(name: str, ctx: ExperimentContext) -> dict[str, Any]:
    """``--plan --json``: the experiment, its size, the database and whether it exists, per
    campaign its name, jobs, stored jobs, whether it is stale (stored by other code: a run
    refuses it), laws and scene families (in first-job order), and the experiment's stages.

    Raises:
        ExperimentError: as :func:`plan_experiment`.
        NotAStoreError: the database is not a uvnav results database.
    """
    experiment = get_experiment(name)
    plans = plan_experiment(name, ctx)
    db_path = Path(ctx.results_dir) / DB_NAME
    stored = _stored(db_path, plans or [])
    size = experiment.prepare(ctx).size
    return {
        "experiment": experiment.name,
        "size": "full" if ctx.full else "quick",
        "runs": size.runs if size is not None else "",
        "database": str(db_path),
        "database_exists": db_path.is_file(),
        "planned": plans is not None,
        "campaigns": [
            {
                "name": p.name,
                "jobs": len(p.jobs),
                "stored": stored.get(p.name, (0, False))[0],
                "stale": stored.get(p.name, (0, False))[1],
                "laws": list(dict.fromkeys(j.controller for j in p.jobs)),
                "families": list(dict.fromkeys(scene_family(j) for j in p.jobs)),
            }
            for p in plans or []
        ],
        "stages": list(experiment.stages),
    }
