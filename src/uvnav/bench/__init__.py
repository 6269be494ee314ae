"""Layer 6: the campaign engine — scenarios × controllers × seeds → a SQLite results store.

* :mod:`uvnav.bench.store` — the results database (DESIGN §5).
* :mod:`uvnav.bench.jobs` — picklable job descriptions, their outcomes and task sizes.
* :mod:`uvnav.bench.campaign` — the jobs run on a local process pool (or Ray), resumable.
* :mod:`uvnav.bench.fingerprint` — the results database's name, the code fingerprint and the
  staleness check of stored campaigns.
* :mod:`uvnav.bench.spec` — campaign YAML files (scenarios × controllers × seeds) → jobs.
* :mod:`uvnav.bench.ray_engine` — the jobs as Ray tasks (extra ``uvnav[bench]``; Ray is imported
  only when the engine runs).
* :mod:`uvnav.bench.summary` — the per-controller table ``uvnav bench`` prints.

The experiments that run campaigns on this engine (``uvnav reproduce NAME``, ``uvnav run``) are
:mod:`uvnav.experiments`, a layer above; nothing here imports them.
"""

from uvnav.bench.campaign import CampaignRun, Job, JobOutcome, grid_jobs, run_campaign, run_job
from uvnav.bench.spec import (
    CampaignError,
    CampaignSpec,
    campaign_from_dict,
    load_campaign,
    run_campaign_spec,
)
from uvnav.bench.store import ResultsStore, params_hash
from uvnav.bench.summary import controller_summary

__all__ = [
    "CampaignError",
    "CampaignRun",
    "CampaignSpec",
    "Job",
    "JobOutcome",
    "ResultsStore",
    "campaign_from_dict",
    "controller_summary",
    "grid_jobs",
    "load_campaign",
    "params_hash",
    "run_campaign",
    "run_campaign_spec",
    "run_job",
]
