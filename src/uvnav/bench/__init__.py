"""Layer 6: benchmark campaigns — scenarios × controllers × seeds → a SQLite results store.

* :mod:`uvnav.bench.store` — the results database (DESIGN §5).
* :mod:`uvnav.bench.campaign` — picklable jobs run on a local process pool, resumable.
* :mod:`uvnav.bench.reproduce` — the thesis Chapter 2 reproduction behind ``uvnav run``
  (``from uvnav.bench.reproduce import reproduce``; the function is not re-exported here so that it
  does not shadow its module).
"""

from uvnav.bench.campaign import CampaignRun, Job, JobOutcome, grid_jobs, run_campaign, run_job
from uvnav.bench.store import ResultsStore, params_hash

__all__ = [
    "CampaignRun",
    "Job",
    "JobOutcome",
    "ResultsStore",
    "grid_jobs",
    "params_hash",
    "run_campaign",
    "run_job",
]
